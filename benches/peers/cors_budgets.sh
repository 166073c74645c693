#!/usr/bin/env bash
# CORS-RBF against pySOT's DYCORS and SRBF at the budgets of a calibration (60, 150) and of
# the earlier record (300), on the seven Dixon-Szego functions, 30 seeds: our side told its
# budget (the default of the harness) and not told it (`--unknown-budget`, the horizon of
# 300), pySOT rerun at every budget (DYCORS's schedule depends on it). Prints the table of
# docs/validation.md ("CORS at a calibration's budgets").
#
#   benches/peers/cors_budgets.sh [SEEDS=30] [BUDGETS="60 150 300"]
#
# Resumable: a result file (benches/peers/out/cors_b<B>*.jsonl, pysot_b<B>_<strategy>_<function>.jsonl)
# that is complete is kept; delete it to rerun. Counts do not depend on the machine's load.
set -euo pipefail
cd "$(dirname "$0")/../.."
SEEDS="${1:-30}"
BUDGETS="${2:-60 150 300}"
VENV=benches/peers/.venv
OUT=benches/peers/out
mkdir -p "$OUT"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q pySOT==0.3.3 six
cargo build --release -p impactcal-cors --example cors_dixon_szego
ours="${CARGO_TARGET_DIR:-target}/release/examples/cors_dixon_szego"
functions="branin goldstein-price hartmann3 hartmann6 shekel5 shekel7 shekel10"
complete() { [ -s "$1" ] && [ "$(grep -c '^{' "$1")" = "$2" ]; }
for b in $BUDGETS; do
    for variant in known unknown; do
        out="$OUT/cors_b$b.jsonl"
        flag=()
        if [ "$variant" = unknown ]; then
            out="$OUT/cors_b${b}_unknown.jsonl"
            flag=(--unknown-budget)
        fi
        complete "$out" $((7 * SEEDS)) && continue
        echo "== impactcal-cors, budget $b ($variant)"
        "$ours" --seeds "$SEEDS" --budget "$b" "${flag[@]}" > "$out.tmp" && mv "$out.tmp" "$out"
    done
    for s in dycors srbf; do
        for f in $functions; do
            out="$OUT/pysot_b${b}_${s}_$f.jsonl"
            complete "$out" "$SEEDS" && continue
            echo "== pySOT $s $f, budget $b"
            "$VENV/bin/python" benches/peers/cors_pysot.py --seeds "$SEEDS" --budget "$b" \
                --strategies "$s" --functions "$f" > "$out.tmp" 2> /dev/null && mv "$out.tmp" "$out"
        done
    done
done
# shellcheck disable=SC2086
"$VENV/bin/python" benches/peers/cors_budgets.py "$OUT" $BUDGETS
