#!/usr/bin/env bash
# End-to-end test of the Slurm executor on a real one-node cluster on 127.0.0.1.
#
#   tests/slurm/run.sh               the test (installs Slurm with apt-get when missing)
#   tests/slurm/run.sh --overhead N  also measure the driver's own CPU time for N trivial tasks
#
# It runs `impactcal batch` through the Slurm executor with examples/batch/slurm.toml:
#   1. a batch with a run whose solver fails: reported with its exit status and resubmitted
#      once, the others read back;
#   2. a cancel: SIGINT to the driver scancels its array (checked with squeue);
#   3. SIGKILL of the driver mid-array, then a rerun that re-attaches to the tasks still
#      queued or running and ends with the same histories as step 1;
#   4. a small study (examples/study/slurm.toml) killed with SIGKILL mid-ensemble and
#      resumed: it re-attaches to the ensemble's array and ends with the same study.json as
#      the same study run uninterrupted on the local process pool;
#   5. a small closed loop (examples/loop/slurm.toml, the drop tower): every stage of the
#      loop a job array of `impactcal point` tasks, the holdout's runs at their
#      condition; the same loop.json as the same loop in process;
#   6. the closed loop on an external solver (examples/loop/external/processes.toml: the
#      deck template drop.k, each run `impactcal simulate` as a program in a job array):
#      the same loop.json as the same deck run in process as a built-in model (deck.toml),
#      apart from the line naming the model.
set -euo pipefail
cd "$(dirname "$0")/../.."
REPO=$(pwd)
OVERHEAD=0
if [ "${1:-}" = "--overhead" ]; then OVERHEAD=${2:?--overhead N}; fi

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  echo "== installing slurm"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq slurmctld slurmd slurm-client munge >/dev/null
fi

ROOT=$(mktemp -d /tmp/impactcal-slurm.XXXXXX)
cleanup() {
  if [ -n "${SLURM_CONF:-}" ]; then scancel --user="$(id -un)" 2>/dev/null || true; fi
  "$REPO/tests/slurm/stop.sh" "$ROOT"
  rm -rf "$ROOT"
}
trap cleanup EXIT
echo "== starting slurm in $ROOT"
"$REPO/tests/slurm/start.sh" "$ROOT"
export SLURM_CONF="$ROOT/slurm.conf"

echo "== building impactcal"
# The binary `cargo test --workspace` builds for the integration tests: after it (as in CI)
# this is a no-op; `cargo build -p impactcal-cli` would unify features differently and
# build the workspace again.
cargo test --workspace --no-run --quiet
IMPACTCAL="${CARGO_TARGET_DIR:-$REPO/target}/debug/impactcal"
W="$ROOT/work"
mkdir -p "$W"
cp examples/batch/strip.k "$W/"
fail() { echo "FAILED: $*" >&2; exit 1; }
# kill_after_results JOURNAL N PID: SIGKILL of PID once JOURNAL records N results (or 60 s).
kill_after_results() {
  for _ in $(seq 1 600); do
    n=$(grep -c '"event":"result"' "$1" 2>/dev/null || true)
    [ "${n:-0}" -ge "$2" ] && break
    sleep 0.1
  done
  kill -KILL "$3"
  wait "$3" 2>/dev/null || true
}

# The shipped configuration, with a faster poll for the test.
sed 's/^poll = .*/poll = 0.5/' examples/batch/slurm.toml > "$W/slurm.toml"
# A slow solver for the cancel and kill steps: a pause, then the built-in solver.
slow_config() {
  sed "s|^\[solver\]$|[solver]\ncommand = [\"sh\", \"-c\", \"sleep $1; exec \\\\\"\$0\\\\\" simulate --deck strip.k --out out.csv\", \"$IMPACTCAL\"]|" \
    "$W/slurm.toml" > "$W/slow.toml"
}
GOOD="t,vz
0.002,-5
0.0025,-4
0.0015,-6
0.0022,-4.5
0.0018,-5.5
0.0021,-5.2"
printf '%s\n' "$GOOD" > "$W/good.csv"
printf '%s\n%s\n' "$GOOD" "-0.001,-5" > "$W/with_bad.csv"

echo "== 1. a batch with a failing run"
set +e
"$IMPACTCAL" batch --config "$W/slurm.toml" --points "$W/with_bad.csv" --out "$W/one" 2> "$W/one.err"
code=$?
set -e
cat "$W/one.err"
[ $code = 1 ] || fail "exit code $code, expected 1"
grep -q 'run 6: the solver exited with status 2' "$W/one.err" || fail "the failed run is not named"
python3 - "$W/one/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
assert s["succeeded"] == 6 and s["failed"] == 1, s
assert s["results"][6]["attempts"] == 2, s["results"][6]
assert all(r["attempts"] == 1 for r in s["results"][:6]), s
PY
subs=$(grep -c '"event":"slurm_job"' "$W/one/runs/strip/journal.jsonl")
[ "$subs" = 2 ] || fail "expected 2 arrays (the batch, the resubmission), found $subs"
grep -q 'thickness: must be finite and positive' "$W/one/runs/strip/6/stderr.txt" || fail "stderr of run 6"

echo "== 2. cancel: SIGINT scancels the array"
slow_config 30
"$IMPACTCAL" batch --config "$W/slow.toml" --points "$W/good.csv" --out "$W/two" 2> "$W/two.err" &
DRIVER=$!
for _ in $(seq 1 100); do
  [ -n "$(squeue -h -o %i)" ] && break
  sleep 0.2
done
[ -n "$(squeue -h -o %i)" ] || fail "nothing was queued"
kill -INT $DRIVER
set +e; wait $DRIVER; code=$?; set -e
cat "$W/two.err"
[ $code = 1 ] || fail "exit code $code after SIGINT, expected 1"
grep -q 'interrupted; scancel' "$W/two.err" || fail "no scancel reported"
for _ in $(seq 1 50); do
  [ -z "$(squeue -h -o %i)" ] && break
  sleep 0.2
done
[ -z "$(squeue -h -o %i)" ] || { squeue; fail "tasks still queued after the cancel"; }

echo "== 3. SIGKILL of the driver mid-array, then resume"
slow_config 2
"$IMPACTCAL" batch --config "$W/slow.toml" --points "$W/good.csv" --out "$W/three" 2> /dev/null &
DRIVER=$!
J="$W/three/runs/strip/journal.jsonl"
kill_after_results "$J" 2 $DRIVER
left=$(squeue -h -r -o %i | wc -l)
echo "driver killed with $(grep -c '"event":"result"' "$J") results in the journal and $left tasks in the queue"
[ "$left" -gt 0 ] || fail "the array finished before the kill"
"$IMPACTCAL" batch --config "$W/slow.toml" --points "$W/good.csv" --out "$W/three"
grep -c '"event":"slurm_job"' "$J" | grep -qx 1 || fail "tasks were resubmitted instead of re-attached"
for i in 0 1 2 3 4 5; do
  cmp "$W/one/runs/strip/$i/result.csv" "$W/three/runs/strip/$i/result.csv" || fail "run $i differs"
done

echo "== 4. a study on Slurm: SIGKILL mid-ensemble, resume, the same study.json"
S="$W/study"
mkdir -p "$S"
cp examples/study/bounds.csv examples/study/test.csv "$S/"
# Our solver after a pause of 1 s, so that the kill finds tasks queued or running.
SLOW="command = [\"sh\", \"-c\", 'sleep 1; exec \"\$0\" simulate --deck strip.k --out out.csv', \"$IMPACTCAL\"]"
sed -e 's/^poll = .*/poll = 0.5/' -e "s|^template = .*|template = \"$W/strip.k\"\n$SLOW|" \
  examples/study/slurm.toml > "$S/slurm.toml"
# The same study on the local process pool: the reference.
sed -e '/^\[executor\]/,$d' "$S/slurm.toml" > "$S/local.toml"
printf '[executor]\nkind = "processes"\njobs = 2\n' >> "$S/local.toml"
"$IMPACTCAL" study --config "$S/local.toml" --out "$S/reference" 2> "$S/reference.err" \
  || { cat "$S/reference.err"; fail "the reference study"; }
"$IMPACTCAL" study --config "$S/slurm.toml" --out "$S/slurm" 2> /dev/null &
DRIVER=$!
J="$S/slurm/runs/ensemble/journal.jsonl"
kill_after_results "$J" 2 $DRIVER
left=$(squeue -h -r -o %i | wc -l)
echo "study killed with $(grep -c '"event":"result"' "$J") of 12 ensemble results in the journal and $left tasks in the queue"
[ "$left" -gt 0 ] || fail "the ensemble finished before the kill"
[ ! -e "$S/slurm/study.json" ] || fail "the study finished before the kill"
"$IMPACTCAL" study --config "$S/slurm.toml" --out "$S/slurm" 2> "$S/resume.err" \
  || { cat "$S/resume.err"; fail "the resumed study"; }
grep -E 'ensemble over the parameter space: 0/12 runs \([0-9]+ from the journal\)' "$S/resume.err" \
  || { cat "$S/resume.err"; fail "the resumed ensemble's line (12 runs, some from the journal)"; }
grep -c '"event":"slurm_job"' "$J" | grep -qx 1 || fail "the ensemble was resubmitted instead of re-attached"
cmp "$S/reference/study.json" "$S/slurm/study.json" || fail "the resumed study differs from the reference"

echo "== 5. a closed loop on Slurm: the same loop.json as in process"
L="$W/loop"
mkdir -p "$L"
cp examples/loop/test.csv examples/loop/holdout.csv "$L/"
# A shorter Gauss-Newton polish keeps the number of arrays (one per stage) small.
sed -e 's/^poll = .*/poll = 0.5/' -e 's/^\[loop\]$/[loop]\npolish = 2/' examples/loop/slurm.toml \
  > "$L/slurm.toml"
grep -q '^polish = 2$' "$L/slurm.toml" || fail "slurm.toml has no [loop] table to shorten the polish in"
# The same loop in process: the file without its [executor] table (the last).
sed -e '/^\[executor\]/,$d' "$L/slurm.toml" > "$L/local.toml"
grep -q '^\[executor\]' "$L/local.toml" && fail "local.toml still has an executor"
"$IMPACTCAL" close-loop --config "$L/local.toml" --out "$L/reference" 2> "$L/reference.err" \
  || { cat "$L/reference.err"; fail "the reference loop"; }
start=$(date +%s)
"$IMPACTCAL" close-loop --config "$L/slurm.toml" --out "$L/slurm" 2> "$L/slurm.err" \
  || { cat "$L/slurm.err"; fail "the loop on Slurm"; }
arrays=$(cat "$L"/slurm/runs/*/journal.jsonl | grep -c '"event":"slurm_job"')
echo "loop on Slurm: $arrays job arrays in $(( $(date +%s) - start )) s"
grep -q '"v0": 5' "$L/slurm/runs/holdout-enriched/0/params.json" || fail "the holdout's condition"
grep -q 'contact_damping' "$L/slurm/runs/holdout-enriched/0/params.json" || fail "the added candidate"
cmp "$L/reference/loop.json" "$L/slurm/loop.json" || fail "the loop on Slurm differs from the loop in process"

echo "== 6. a closed loop on an external solver on Slurm: the same loop.json as the deck in process"
X="$W/external"
mkdir -p "$X"
cp examples/loop/external/drop.k examples/loop/external/bounds.csv examples/loop/external/test.csv \
  examples/loop/external/holdout.csv examples/loop/external/deck.toml "$X/"
# The shipped file with a Slurm executor (its [executor] table is the last) and the solver
# named as a program: `impactcal simulate` on the rendered deck.
sed -e '/^\[executor\]/,$d' \
  -e "s|^template = .*|template = \"drop.k\"\ncommand = [\"$IMPACTCAL\", \"simulate\", \"--deck\", \"drop.k\", \"--out\", \"out.csv\"]|" \
  examples/loop/external/processes.toml > "$X/slurm.toml"
printf '[executor]\nkind = "slurm"\npoll = 0.5\nretries = 1\n' >> "$X/slurm.toml"
"$IMPACTCAL" close-loop --config "$X/deck.toml" --out "$X/reference" 2> "$X/reference.err" \
  || { cat "$X/reference.err"; fail "the deck's loop in process"; }
start=$(date +%s)
"$IMPACTCAL" close-loop --config "$X/slurm.toml" --out "$X/slurm" 2> "$X/slurm.err" \
  || { cat "$X/slurm.err"; fail "the external solver's loop on Slurm"; }
arrays=$(cat "$X"/slurm/runs/*/journal.jsonl | grep -c '"event":"slurm_job"')
echo "external solver's loop on Slurm: $arrays job arrays in $(( $(date +%s) - start )) s"
grep -q '^R vz,-4$' "$X/slurm/runs/holdout-enriched/0/drop.k" || fail "the holdout's drop speed in the deck"
python3 - "$X/reference/loop.json" "$X/slurm/loop.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert a.pop("model").startswith("deck ") and b.pop("model").startswith("solver "), "model lines"
# The configuration digests differ with the files' models.
a.pop("digest"); b.pop("digest")
assert a == b, "the external solver's loop on Slurm differs from the deck's loop in process"
assert b["verdict"] == "attributed" and b["added"][0]["name"] == "damp", (b["verdict"], b["added"])
PY

if [ "$OVERHEAD" -gt 0 ]; then
  echo "== overhead: $OVERHEAD trivial tasks"
  printf 'time,y\n0,0\n1,<<a>>\n' > "$W/trivial.csv"
  cat > "$W/trivial.toml" <<TOML
[batch]
study = "trivial"
[solver]
template = "trivial.csv"
command = ["cp", "trivial.csv", "out.csv"]
[executor]
kind = "slurm"
poll = 2.0
max_array = 1000
TOML
  python3 -c "
print('a')
for i in range($OVERHEAD): print(i)" > "$W/trivial_points.csv"
  start=$(date +%s.%N)
  bash -c "'$IMPACTCAL' batch --config '$W/trivial.toml' --points '$W/trivial_points.csv' --out '$W/trivial' && times" > "$W/times.txt"
  end=$(date +%s.%N)
  python3 - "$W/times.txt" "$OVERHEAD" "$start" "$end" <<'PY'
import re, sys
text = open(sys.argv[1]).read().split("\n")
n = int(sys.argv[2]); wall = float(sys.argv[4]) - float(sys.argv[3])
def secs(s):
    m = re.match(r"(\d+)m([\d.]+)s", s); return int(m.group(1)) * 60 + float(m.group(2))
# `times`: the shell's own user/sys, then its children's (the driver and what it ran).
user, sys_ = (secs(x) for x in text[1].split())
print(f"{n} tasks in {wall:.1f} s wall; driver CPU (user+sys, with the sbatch/squeue it ran) "
      f"{user + sys_:.2f} s = {1000 * (user + sys_) / n:.1f} ms per task")
PY
fi
echo "== slurm test passed"
