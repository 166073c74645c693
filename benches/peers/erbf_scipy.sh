#!/usr/bin/env bash
# Peer comparison: our ERBF and RBF surrogates against scipy.interpolate.RBFInterpolator
# on the same data (N = 150 samples, n_p = 10 parameters, T = 10^4 outputs, 1000 queries),
# timed in the same run. Prints medians, ratios, and the agreement of the predictions of
# the two cubic (and the two Gaussian) interpolants, which are the same mathematical model.
#
# Usage: benches/peers/erbf_scipy.sh [reps]   (from the repository root)
# Our side is benches/harness/erbf_peer.rs, built as the `erbf_peer` example target.
set -euo pipefail
cd "$(dirname "$0")/../.."
REPS="${1:-5}"
VENV=benches/peers/.venv
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install --quiet numpy scipy
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}"
cargo run --quiet --release --example erbf_peer -- "$WORK" "$REPS" > "$WORK/ours.txt"
"$VENV/bin/python" - "$WORK" "$REPS" <<'PY'
import sys, time, statistics, math
import numpy as np
import scipy
from scipy.interpolate import RBFInterpolator

work, reps = sys.argv[1], int(sys.argv[2])
N, M, T, Q, CHECK = 150, 10, 10_000, 1000, 8
x = np.fromfile(f"{work}/points.bin", dtype="<f8").reshape(N, M)
f = np.fromfile(f"{work}/values.bin", dtype="<f8").reshape(N, T)
q = np.fromfile(f"{work}/queries.bin", dtype="<f8").reshape(Q, M)
ours = {}
for line in open(f"{work}/ours.txt"):
    _, name, value = line.split()
    ours[name] = float(value)

def timed(fn, warm_up=2):
    for _ in range(warm_up):
        fn()
    ts, out = [], None
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), out

eps = 1.0 / (math.sqrt(2.0) * 0.15)
fit_g, gi = timed(lambda: RBFInterpolator(x, f, kernel="gaussian", epsilon=eps, degree=-1))
pred_g, yg = timed(lambda: gi(q))
fit_c, ci = timed(lambda: RBFInterpolator(x, f, kernel="cubic", degree=1))
pred_c, yc = timed(lambda: ci(q))

def agreement(name, theirs):
    mine = np.fromfile(f"{work}/ours_{name}.bin", dtype="<f8").reshape(Q, CHECK)
    ref = theirs[:, :CHECK]
    return np.max(np.abs(mine - ref)) / np.max(np.abs(ref))

print(f"scipy {scipy.__version__}, numpy {np.__version__}; N={N}, n_p={M}, T={T}, {Q} queries, "
      f"median of {reps} after 2 warm-up calls")
print(f"{'case':<34} {'ours [s]':>10} {'scipy [s]':>10} {'scipy/ours':>10}")
rows = [
    ("ERBF fit + 1000 predict vs scipy Gaussian", ours["erbf_fit"] + ours["erbf_predict_1000"], fit_g + pred_g),
    ("Gaussian fit", ours["gaussian_fit"], fit_g),
    ("Gaussian 1000-point predict", ours["gaussian_predict_1000"], pred_g),
    ("Gaussian fit + predict", ours["gaussian_fit"] + ours["gaussian_predict_1000"], fit_g + pred_g),
    ("cubic fit", ours["cubic_fit"], fit_c),
    ("cubic 1000-point predict", ours["cubic_predict_1000"], pred_c),
    ("cubic fit + predict", ours["cubic_fit"] + ours["cubic_predict_1000"], fit_c + pred_c),
]
for name, a, b in rows:
    print(f"{name:<34} {a:>10.4f} {b:>10.4f} {b / a:>10.2f}")
print(f"ERBF fit alone {ours['erbf_fit']:.4f} s, 1000-point predict {ours['erbf_predict_1000']:.4f} s, "
      f"one-point predict {ours['erbf_predict_1'] * 1e3:.3f} ms; training residual "
      f"{ours['erbf_training_residual']:.1e}")
print(f"agreement with scipy (max |ours - scipy| / max |scipy|, first {CHECK} outputs): "
      f"cubic {agreement('cubic', yc):.1e}, gaussian {agreement('gaussian', yg):.1e}")
PY
