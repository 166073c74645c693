#!/usr/bin/env bash
# CORS-RBF (impactcal-cors) against pySOT's DYCORS and SRBF (cubic RBF, linear tail) on the
# seven Dixon-Szego functions: same initial design size 2(d+1) (symmetric Latin hypercube),
# same budget, same seed numbers. Prints the table recorded in docs/validation.md and
# docs/performance.md.
#
#   benches/peers/cors_pysot.sh [SEEDS=30] [BUDGET=300]
# Our side is benches/harness/cors_dixon_szego.rs, built as the `cors_dixon_szego` example target.
set -euo pipefail
cd "$(dirname "$0")/../.."
SEEDS="${1:-30}"
BUDGET="${2:-300}"
VENV=benches/peers/.venv
OUT=benches/peers/out
mkdir -p "$OUT"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install -q pySOT==0.3.3 six
cargo build --release --example cors_dixon_szego
echo "== impactcal-cors ($SEEDS seeds, budget $BUDGET)"
target_dir="${CARGO_TARGET_DIR:-target}"
"$target_dir/release/examples/cors_dixon_szego" --seeds "$SEEDS" --budget "$BUDGET" > "$OUT/cors.jsonl"
echo "== pySOT DYCORS and SRBF"
"$VENV/bin/python" benches/peers/cors_pysot.py --seeds "$SEEDS" --budget "$BUDGET" \
    > "$OUT/pysot.jsonl" 2> "$OUT/pysot.stderr"
"$VENV/bin/python" benches/peers/cors_summary.py "$OUT/cors.jsonl" "$OUT/pysot.jsonl"
