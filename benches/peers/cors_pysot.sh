#!/usr/bin/env bash
# CORS-RBF (impactcal-cors) against pySOT's DYCORS and SRBF (cubic RBF, linear tail) on the
# seven Dixon-Szego functions: same initial design size 2(d+1) (symmetric Latin hypercube),
# same budget, same seed numbers. Prints the table recorded in docs/validation.md and
# docs/performance.md.
#
#   benches/peers/cors_pysot.sh [SEEDS=30] [BUDGET=300]
#
# REUSE_PYSOT=1 keeps an existing benches/peers/out/pysot.jsonl (pySOT's counts are
# deterministic for a seed; its timings are those of the run that wrote the file) and says so.
# NOISE_LEVELS="0.01 0.05" (with NOISE_BUDGET, default 150) also runs both tools on the noisy
# functions f + level * range * z with the shared noise table out/noise.txt (written by
# cors_pysot.py --write-noise when absent) and prints the table of answers; REUSE_PYSOT=1
# keeps existing out/pysot_noise_<level>.jsonl files too.
# Our side is benches/harness/cors_dixon_szego.rs, the `cors_dixon_szego` example of
# impactcal-cors.
set -euo pipefail
cd "$(dirname "$0")/../.."
SEEDS="${1:-30}"
BUDGET="${2:-300}"
NOISE_BUDGET="${NOISE_BUDGET:-150}"
VENV=benches/peers/.venv
OUT=benches/peers/out
mkdir -p "$OUT"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q pySOT==0.3.3 six
cargo build --release -p impactcal-cors --example cors_dixon_szego
target_dir="${CARGO_TARGET_DIR:-target}"
ours="$target_dir/release/examples/cors_dixon_szego"
# Runs pySOT into $1 (remaining arguments for cors_pysot.py) unless reusing an existing file.
pysot() {
    local out="$1"
    shift
    if [ "${REUSE_PYSOT:-0}" = 1 ] && [ -s "$out" ]; then
        echo "== pySOT: reusing $out (REUSE_PYSOT=1; not rerun)"
    else
        echo "== pySOT DYCORS and SRBF -> $out"
        "$VENV/bin/python" benches/peers/cors_pysot.py "$@" > "$out" 2> "${out%.jsonl}.stderr"
    fi
}
echo "== impactcal-cors ($SEEDS seeds, budget $BUDGET)"
"$ours" --seeds "$SEEDS" --budget "$BUDGET" > "$OUT/cors.jsonl"
pysot "$OUT/pysot.jsonl" --seeds "$SEEDS" --budget "$BUDGET"
"$VENV/bin/python" benches/peers/cors_summary.py "$OUT/cors.jsonl" "$OUT/pysot.jsonl"
if [ -n "${NOISE_LEVELS:-}" ]; then
    if [ ! -s "$OUT/noise.txt" ]; then
        "$VENV/bin/python" benches/peers/cors_pysot.py --write-noise "$OUT/noise.txt" \
            --seeds "$SEEDS" --budget "$NOISE_BUDGET"
    fi
    files=()
    for level in $NOISE_LEVELS; do
        echo "== noise $level of the range (budget $NOISE_BUDGET)"
        "$ours" --seeds "$SEEDS" --budget "$NOISE_BUDGET" --noise "$level" \
            --noise-file "$OUT/noise.txt" > "$OUT/cors_noise_$level.jsonl"
        pysot "$OUT/pysot_noise_$level.jsonl" --seeds "$SEEDS" --budget "$NOISE_BUDGET" \
            --noise "$level" --noise-file "$OUT/noise.txt"
        files+=("$OUT/cors_noise_$level.jsonl" "$OUT/pysot_noise_$level.jsonl")
    done
    "$VENV/bin/python" benches/peers/cors_summary.py "${files[@]}"
fi
