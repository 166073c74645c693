#!/usr/bin/env bash
# Peer comparison of test data, CFC filters and curve metrics, timed in the same run:
#   - ISO/TS 18571 R and its four scores against objective-rating-metrics on 33 curve pairs;
#   - CFC 60/180/600/1000 against pyisomme's ISO-6487 filter;
#   - ISO-MME data sets written by pyisomme (ASCII, UTF-8, ISO-8859-1, Windows-1252; folder
#     and zip) read back by both;
#   - the speed of ISO/TS 18571 on 1,215 pairs of 801 samples, ours against
#     objective-rating-metrics.
# Builds its own venv (the peers pin numpy 1.x) and prints every comparison.
#
# Usage: benches/peers/testdata_metrics.sh [OUR_REPEATS] [PEER_REPEATS] [--write-fixtures]
#   --write-fixtures also copies the inputs and the peers' answers into the crates' tests/data
#   (the files `cargo test` checks without Python).
set -euo pipefail
cd "$(dirname "$0")/../.."
OURS="${1:-5}"
PEER="${2:-1}"
VENV=benches/peers/.venv-metrics
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install --quiet objective-rating-metrics==1.3 pyisomme==1.1.0
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$VENV/bin/python" benches/peers/testdata_metrics.py generate "$WORK" 2>/dev/null
cargo run --quiet --release --example testdata_peer -- "$WORK" "$OURS" > "$WORK/ours.json"
"$VENV/bin/python" benches/peers/testdata_metrics.py report "$WORK" "$PEER"
if [ "${3:-}" = "--write-fixtures" ]; then
    "$VENV/bin/python" benches/peers/testdata_metrics.py fixtures "$WORK" "$PWD"
    echo "fixtures written to crates/impactcal-core/tests/data and crates/impactcal-calibrate/tests/data"
fi
