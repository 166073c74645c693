#!/bin/bash
# Compares the shell solver of two `impactcal` binaries bit for bit: the nodal velocity and
# acceleration histories and the energy histories (CSV written with shortest round-trip
# formatting, so equal text means equal bits) of
#   - the example deck examples/decks/strip_drop.k (quads, plasticity, friction),
#   - the built-in airframe (`--model airframe`, quads and triangles, invariant numbering,
#     bulk viscosity, global damping), and the same airframe written as a deck with
#     stiffness-proportional damping on every part,
#   - the strip split into triangles with stiffness damping, bulk viscosity and invariant
#     numbering (the triangle path with every term switched on),
# each on 1 and 2 threads. Exits 1 on the first difference.
#
#   benches/harness/shell_bitwise.sh BEFORE_BINARY AFTER_BINARY
#
# Build the binaries from the two commits (cargo build --release -p impactcal-cli) and copy
# them aside first.
set -eu
before=$1
after=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
here=$(cd "$(dirname "$0")/../.." && pwd)

cp "$here/examples/decks/strip_drop.k" "$work/strip.k"
# The strip as triangles (each quad split along its 1-3 diagonal), every element term on.
python3 - "$work/strip.k" "$work/strip_tri.k" <<'EOF'
import sys
lines = open(sys.argv[1]).read().splitlines()
out, section, next_id = [], None, 1000
for l in lines:
    if l.startswith('*'):
        section = l.strip()
        if section == '*END':
            out += ['*DAMPING_PART_STIFFNESS', '         1      0.05',
                    '*CONTROL_BULK_VISCOSITY', '       1.5      0.06        -2',
                    '*CONTROL_ACCURACY', '         0         2']
        out.append(l)
        continue
    if section == '*ELEMENT_SHELL' and not l.startswith('$'):
        f = [int(l[i:i + 8]) for i in range(0, 48, 8)]
        out.append(''.join(f'{v:8d}' for v in [f[0], f[1], f[2], f[3], f[4], f[4]]))
        out.append(''.join(f'{v:8d}' for v in [next_id, f[1], f[2], f[4], f[5], f[5]]))
        next_id += 1
        continue
    out.append(l)
open(sys.argv[2], 'w').write('\n'.join(out) + '\n')
EOF
"$before" airframe --end-time 0.01 --out "$work/airframe.k" 2>/dev/null
# Stiffness damping on every part of the airframe deck.
python3 - "$work/airframe.k" "$work/airframe_damped.k" <<'EOF'
import sys
lines = open(sys.argv[1]).read().splitlines()
parts, section, cards = [], None, 0
for l in lines:
    if l.startswith('*'):
        section, cards = l.strip(), 0
    elif section == '*PART' and not l.startswith('$'):
        cards += 1
        if cards % 2 == 0:
            parts.append(int(l[:10]))
end = max(i for i, l in enumerate(lines) if l.strip() == '*END')
extra = ['*DAMPING_PART_STIFFNESS'] + [f'{p:10d}      0.02' for p in parts]
open(sys.argv[2], 'w').write('\n'.join(lines[:end] + extra + lines[end:]) + '\n')
EOF

run() { # binary tag threads source-args...
  local bin=$1 tag=$2 threads=$3
  shift 3
  for q in velocity acceleration; do
    "$bin" simulate "$@" --threads "$threads" --quantity "$q" --out "$work/$tag.$threads.$q.csv" \
      --energies "$work/$tag.$threads.energies.csv" 2>/dev/null
  done
}
cases=(strip strip_tri airframe_damped airframe_model)
for side in before after; do
  bin=$before
  [ $side = after ] && bin=$after
  for t in 1 2; do
    run "$bin" "$side.strip" $t --deck "$work/strip.k"
    run "$bin" "$side.strip_tri" $t --deck "$work/strip_tri.k"
    run "$bin" "$side.airframe_damped" $t --deck "$work/airframe_damped.k"
    run "$bin" "$side.airframe_model" $t --model airframe --end-time 0.01
  done
done
status=0
for c in "${cases[@]}"; do
  for t in 1 2; do
    for f in velocity acceleration energies; do
      a="$work/before.$c.$t.$f.csv"
      b="$work/after.$c.$t.$f.csv"
      if cmp -s "$a" "$b" && cmp -s "$b" "$work/after.$c.1.$f.csv"; then
        echo "identical  $c threads=$t $f ($(wc -l < "$a") rows x $(head -1 "$a" | tr ',' '\n' | wc -l) columns)"
      else
        echo "DIFFERENT  $c threads=$t $f"
        status=1
      fi
    done
  done
done
exit $status
