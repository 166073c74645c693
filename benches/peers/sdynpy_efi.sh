#!/usr/bin/env bash
# Peer comparison: SDynPy's effective independence (sandialabs/sdynpy,
# sdynpy.fem.sdynpy_dof.by_effective_independence) against impactcal-sensors on the SAME
# candidate shape matrices, timed in the same run. Checks that both keep the same DOFs and
# prints the median times and the ratio.
#
# Usage: benches/peers/sdynpy_efi.sh [REPEATS]   (from the repository root)
# Our side is benches/harness/place_timing.rs, built as the `place_timing` example target.
set -euo pipefail
cd "$(dirname "$0")/../.."
REPEATS="${1:-5}"
VENV=benches/peers/.venv
# SDynPy imports Qt and matplotlib; run them headless.
export QT_QPA_PLATFORM=offscreen MPLBACKEND=Agg
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet --upgrade pip
fi
"$VENV/bin/pip" install --quiet sdynpy

cargo build --release --quiet --example place_timing
OURS="${CARGO_TARGET_DIR:-target}/release/examples/place_timing"

# Sizes: (candidates, shapes, target). The 12150 x 30 case is for our side only unless
# SDYNPY_LARGE=1, because SDynPy's full recompute takes very long there.
CASES="1215 20 41"
if [ "${SDYNPY_LARGE:-0}" = "1" ]; then CASES="$CASES
12150 30 100"; fi

echo "$CASES" | while read -r S K N; do
    M="$WORK/phi_${S}x${K}.csv"
    # The same matrix for both sides: orthonormal columns (like impact shapes U_k) of a
    # seeded Gaussian matrix, written with full precision.
    "$VENV/bin/python" - "$S" "$K" "$M" <<'PY'
import sys, numpy as np
s, k, path = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
rng = np.random.default_rng(20240601 + s + k)
q, _ = np.linalg.qr(rng.standard_normal((s, k)))
with open(path, "w") as f:
    f.write("label," + ",".join(f"shape{j+1}" for j in range(k)) + "\n")
    for i in range(s):
        f.write(f"{i // 3 + 1}.{'xyz'[i % 3]}," + ",".join(repr(float(v)) for v in q[i]) + "\n")
PY
    "$OURS" "$M" "$N" "$REPEATS" "$WORK/ours.txt" | tee "$WORK/ours.log"
    "$VENV/bin/python" - "$M" "$N" "$REPEATS" "$WORK/ours.txt" "$WORK/ours.log" <<'PY'
import sys, time, re, numpy as np
import warnings
warnings.filterwarnings("ignore")
from sdynpy.fem.sdynpy_dof import by_effective_independence
path, n, repeats = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
phi = np.loadtxt(path, delimiter=",", skiprows=1, usecols=None, dtype=str)
phi = phi[:, 1:].astype(float)
times, keep = [], None
for _ in range(max(1, min(repeats, 3))):
    t0 = time.perf_counter()
    keep = by_effective_independence(n, phi)
    times.append(time.perf_counter() - t0)
theirs = float(np.median(times))
ours_sel = sorted(int(l) for l in open(sys.argv[4]) if l.strip())
same = sorted(int(i) for i in keep) == ours_sel
ours = float(re.search(r"median ([0-9.eE+-]+) s", open(sys.argv[5]).read()).group(1))
print(f"sdynpy:    {phi.shape[0]} x {phi.shape[1]} -> {n}: median {theirs:.6f} s over {len(times)} runs")
print(f"same selection: {same}")
print(f"speed-up (sdynpy / impactcal): {theirs / ours:.1f}x")
if not same:
    sys.exit(1)
PY
done
