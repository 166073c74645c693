#!/usr/bin/env bash
# Refactoring changes no number: runs the example study and loop files (the strip deck, the
# template solver, the drop tower) with the `impactcal` of a base commit and of this tree, and compares
# study.json / loop.json byte for byte after mapping the option keys the experiment schema
# renamed (and leaving out `fingerprint`, a hash over the option names).
#   benches/harness/refactor_identity.sh <base-impactcal> <new-impactcal> [work-dir]
# <base-impactcal>: the release binary built from the base commit (e.g. `git archive <base>
# | tar -x -C /tmp/base && cargo build --release -p impactcal-cli` there).
set -euo pipefail
BASE=$1
NEW=$2
W=${3:-$(mktemp -d)}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$W"
cp -r "$ROOT/examples" "$W/new-examples"
git -C "$ROOT" archive "$(git -C "$ROOT" merge-base HEAD main)" examples | tar -x -C "$W" \
  && mv "$W/examples" "$W/base-examples"

# A loop file on the local executor: its [executor] (and old [batch]) table dropped.
local_copy() { # file -> same file without [executor]/[batch] tables
  awk '/^\[(executor|batch)\]/{skip=1; next} /^\[/{skip=0} !skip' "$1" > "$2"
}

normalise() { # json -> normalised json on stdout
  python3 - "$1" <<'PY'
import json, sys
RENAMED = {"ensemble": "halton_runs", "noise_runs": "jitter_runs", "noise_eps": "jitter_eps",
           "reconcile_batch": "cors_batch"}
LOOP = {"ensemble": "jitter_runs", "jitter": "jitter_eps", "reconcile": "reconcile_runs",
        "recalibrate": "recalibrate_runs", "batch": "cors_batch"}
d = json.load(open(sys.argv[1]))
d.pop("fingerprint", None)
opts = d.get("options")
if isinstance(opts, dict):
    table = LOOP if "recalibrate" in opts or "recalibrate_runs" in opts else RENAMED
    d["options"] = {table.get(k, k): v for k, v in opts.items()}
# The two trees are copied to two folders; a deck's path enters the model's description.
print(json.dumps(d, sort_keys=True, indent=1).replace("/base-examples/", "/examples/")
      .replace("/new-examples/", "/examples/"))
PY
}

status=0
compare() { # name base-json new-json
  if cmp -s <(normalise "$2") <(normalise "$3"); then
    echo "identical: $1"
  else
    echo "DIFFERENT: $1"; diff <(normalise "$2") <(normalise "$3") | head -20 || true; status=1
  fi
}

run_pair() { # name kind(study|close-loop) base-config new-config
  local name=$1 kind=$2 json
  [ "$kind" = study ] && json=study.json || json=loop.json
  "$BASE" "$kind" --config "$3" --out "$W/out-base-$name" 2>"$W/base-$name.err" \
    || { echo "base failed: $name"; tail -3 "$W/base-$name.err"; status=1; return; }
  "$NEW" "$kind" --config "$4" --out "$W/out-new-$name" 2>"$W/new-$name.err" \
    || { echo "new failed: $name"; tail -3 "$W/new-$name.err"; status=1; return; }
  compare "$name" "$W/out-base-$name/$json" "$W/out-new-$name/$json"
}

for f in deck-processes processes; do
  run_pair "study-$f" study "$W/base-examples/study/$f.toml" "$W/new-examples/study/$f.toml"
done
for f in processes; do
  local_copy "$W/base-examples/loop/$f.toml" "$W/base-examples/loop/$f-local.toml"
  local_copy "$W/new-examples/loop/$f.toml" "$W/new-examples/loop/$f-local.toml"
  run_pair "loop-$f-local" close-loop "$W/base-examples/loop/$f-local.toml" "$W/new-examples/loop/$f-local.toml"
  run_pair "loop-$f" close-loop "$W/base-examples/loop/$f.toml" "$W/new-examples/loop/$f.toml"
done
echo "work dir: $W"
exit $status
