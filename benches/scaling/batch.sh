#!/usr/bin/env bash
# Peak resident memory and wall time of `impactcal batch` for N small runs: the strip deck
# of examples/batch (the built-in solver, 2 ms each) on a local pool of 4 solver processes,
# then the same batch run again (every run reused from its journal). Prints one Markdown
# row per N: runs, peak RSS, wall time, journal size, and the same for the resumed batch.
# Records docs/performance.md, "Closed loop and study at the size of a whole test".
#
#   benches/scaling/batch.sh [OUT_DIR] [N ...]        (default: /tmp/impactcal-scaling-batch,
#                                                      100 1000 10000)
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:-/tmp/impactcal-scaling-batch}
shift || true
NS=${*:-100 1000 10000}
cargo build --release -p impactcal-cli >/dev/null 2>&1
BIN=$PWD/target/release/impactcal
mkdir -p "$OUT"
peak() { grep "Maximum resident" "$1" | awk '{printf "%.1f MB", $6 / 1000}'; }
wall() { grep "Elapsed (wall" "$1" | awk '{print $8}'; }
echo "| runs | peak RSS | wall | journal | resumed: peak RSS | resumed: wall |"
echo "|---|---|---|---|---|---|"
for N in $NS; do
  D=$OUT/n$N
  rm -rf "$D"
  mkdir -p "$D"
  cp examples/batch/strip.k "$D/"
  sed 's/^jobs = 2/jobs = 4/' examples/batch/batch.toml > "$D/batch.toml"
  # Thickness in [1.5, 2.5] mm and impact speed in [-6, -4] m/s on a deterministic lattice.
  awk -v n="$N" 'BEGIN { print "t,vz"; for (i = 0; i < n; i++)
      printf "%.6g,%.6g\n", 0.0015 + 0.001 * ((i * 0.618034) % 1), -6 + 2 * ((i * 0.414214) % 1) }' \
      > "$D/points.csv"
  /usr/bin/time -v "$BIN" batch --config "$D/batch.toml" --points "$D/points.csv" \
      --out "$D/out" > "$D/run.log" 2> "$D/time.txt"
  /usr/bin/time -v "$BIN" batch --config "$D/batch.toml" --points "$D/points.csv" \
      --out "$D/out" > "$D/resume.log" 2> "$D/time-resume.txt"
  J=$(stat -c %s "$D/out/runs/strip/journal.jsonl")
  echo "| $N | $(peak "$D/time.txt") | $(wall "$D/time.txt") | $((J / 1000)) kB | $(peak "$D/time-resume.txt") | $(wall "$D/time-resume.txt") |"
done
