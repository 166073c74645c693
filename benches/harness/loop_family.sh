#!/usr/bin/env bash
# The closed loop over a family of hidden effects on the coarse airframe (docs/validation.md,
# "The closed loop over a family of hidden effects"): every kind of benches/harness/
# loop_family.rs at both amplitudes and two noise seeds, and the effect-free control at both
# seeds, one JSON record per line appended to RECORDS as each case ends. Cases already in
# RECORDS are skipped, so a killed family resumes where it stopped. Run directories are
# deleted once measured.
#
#   benches/harness/loop_family.sh RECORDS WORKDIR [extra loop_family options...]
#
# Each case is one closed loop of 300-600 airframe runs (5-10 min on two quiet cores).
set -euo pipefail
records=${1:?records file}
work=${2:?work directory}
shift 2
root=$(cd "$(dirname "$0")/../.." && pwd)
cargo build --release --example loop_family --manifest-path "$root/Cargo.toml" >&2
bin="$root/target/release/examples/loop_family"
mkdir -p "$work"
touch "$records"
# One case of each kind first (amplitude 1, seed 1) and the control, so that a family stopped
# early has seen every kind; then the rest.
kinds="mass damping friction rate material"
cases=()
for kind in $kinds none; do cases+=("$kind 1 1"); done
for seed in 1 2; do
  for kind in $kinds; do
    for level in 1 2; do
      [[ "$seed $level" == "1 1" ]] || cases+=("$kind $level $seed")
    done
  done
  [[ $seed == 1 ]] || cases+=("none 1 $seed")
done
for c in "${cases[@]}"; do
  read -r kind level seed <<<"$c"
  if python3 -c "
import json,sys
for l in open('$records'):
    r=json.loads(l)
    if (r['kind'],r['level'],r['seed'])==('$kind',$level,$seed): sys.exit(0)
sys.exit(1)"; then
    continue
  fi
  echo "== $kind $level $seed" >&2
  if line=$("$bin" "$work" "$kind" "$level" "$seed" "$@"); then
    echo "$line" >>"$records"
  else
    echo "{\"kind\":\"$kind\",\"level\":$level,\"seed\":$seed,\"failed\":true}" >>"$records"
  fi
done
