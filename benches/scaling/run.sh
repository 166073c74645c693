#!/usr/bin/env bash
# The scaling record of the closed loop and the study on the coarse airframe
# (docs/performance.md, "Closed loop and study at the size of a whole test"): for 24, 240
# and 1,215 channels over 0.025 and 0.05 s, the test data of
# benches/harness/loop_scaling_data.rs (hidden damping, trigger offset, 40 dB noise, one
# wrong gain; a holdout at another sink speed), then `impactcal close-loop` (Table 2
# declared, CFC 60, the holdout, [loop] jitter_runs 30, reconcile_runs 30, recalibrate_runs 30) and
# `impactcal study` (ensemble 30, 12 sensors, reconciliation 30), each under a hard cap on
# its address space (CAP_GB, default 8) so that a regression fails instead of taking the
# machine. Prints one Markdown row per case: values compared, runs, wall time, peak
# resident memory (/usr/bin/time) beside the memory plan the guard checked, the runs' own
# time per run and the rest of the wall time
# per run (the loop's or study's own work, benches/scaling/run_times.py), the verdict. The
# runs' result files are deleted once a case is measured (a loop at 1,215 channels x 501
# samples writes 4 GB of them).
#
#   benches/scaling/run.sh [OUT_DIR] [CASES...]      CASES like 1215:0.05 (default: all six)
#   WHAT=study benches/scaling/run.sh ...            only the studies (or WHAT=loop)
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:-/tmp/impactcal-scaling}
shift || true
CASES=${*:-24:0.025 24:0.05 240:0.025 240:0.05 1215:0.025 1215:0.05}
CAP=$(( ${CAP_GB:-8} * 1024 * 1024 * 1024 ))
cargo build --release -p impactcal-cli >/dev/null 2>&1
cargo build --release --example loop_scaling_data >/dev/null 2>&1
BIN=$PWD/target/release/impactcal
GEN=$PWD/target/release/examples/loop_scaling_data
HERE=$PWD/benches/scaling
mkdir -p "$OUT"
seconds() { grep "Elapsed (wall" "$1" | awk '{n = split($8, p, ":"); s = 0;
  for (i = 1; i <= n; i++) s = s * 60 + p[i]; print s}'; }
peak() { grep "Maximum resident" "$1" | awk '{printf "%.0f", $6 / 1000}'; }
plan() { python3 -c "import re, sys
m = re.search(r'plans about ([0-9.]+) (kB|MB|GB)', open(sys.argv[1]).read())
print(round(float(m.group(1)) * {'kB': 1e-3, 'MB': 1, 'GB': 1e3}[m.group(2)]) if m else '-')" "$1"; }
echo "| what | channels x samples | values | runs | wall (s) | peak RSS (MB) | plan (MB) | run s/run | own work s/run | verdict |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for c in $CASES; do
  S=${c%%:*}
  E=${c##*:}
  D=$OUT/s$S-e$E
  mkdir -p "$D"
  [ -f "$D/test.csv" ] || "$GEN" "$D" "$S" "$E" 2> "$D/data.log"
  T=$(( $(wc -l < "$D/test.csv") - 1 ))
  for what in ${WHAT:-loop study}; do
    rm -rf "$D/$what-out"
    if [ $what = loop ]; then
      cmd=(close-loop --config "$D/loop.toml" --out "$D/$what-out")
    else
      cmd=(study --config "$D/study.toml" --out "$D/$what-out")
    fi
    status=0
    /usr/bin/time -v prlimit --as=$CAP -- "$BIN" "${cmd[@]}" > "$D/$what.out" \
        2> "$D/$what.log" || status=$?
    W=$(seconds "$D/$what.log")
    times=$(python3 "$HERE/run_times.py" "$D/$what-out" "$W")
    field() { python3 -c "import json,sys; print(json.loads(sys.argv[1])[sys.argv[2]])" "$times" "$1"; }
    if [ $what = loop ]; then
      verdict=$(grep -o "^verdict: [a-z-]*" "$D/$what.log" | head -1 | cut -d' ' -f2)
    else
      verdict=$(python3 -c "import json; r = json.load(open('$D/$what-out/study.json')); \
print(r['m1']['verdict'], 'reduction', round(r['errors']['reduction'], 3))" 2>/dev/null || true)
    fi
    [ $status -eq 0 ] || verdict="exit $status: $(grep -m1 error "$D/$what.log" | cut -c1-120)"
    # The runs' histories are not kept (4 GB for a loop at 1,215 channels x 501 samples);
    # params.json of each run stays for run_times.py.
    find "$D/$what-out/runs" -name result.csv -delete 2>/dev/null || true
    echo "| $what | $S x $T | $((S * T)) | $(field runs) | $W | $(peak "$D/$what.log") | $(plan "$D/$what.log") | $(field run_s_per_run) | $(field own_work_s_per_run) | $verdict |"
  done
done
