#!/usr/bin/env bash
# Surrogates of noisy crash responses, as a new user would fit them: `impactcal surrogate
# fit` (every kind with its defaults, every kind with --auto, and --kind auto) against
# scipy's smoothed cubic RBFInterpolator (smoothing 1.0) and a plain linear regression,
# on the same runs, in one script.
#
# Data: a directory of scalar results of sampled runs in the layout of the public car
# pole-crash study (LS-DYNA, 9 parameters): `p9_X.csv` (runs x parameters, no header),
# `p9_problem.txt` (a Python dict with `names` and `bounds`) and one `p9_Y_<output>.csv`
# per output (one value per run, no header). The data are not part of the repository; give
# their directory as the first argument or in IMPACTCAL_CAR_POLE.
#
# The first FIT runs (default 250) fit, the rest are held out. Inputs are scaled to the
# unit cube by the bounds on both sides. Printed: held-out RMSE / std (std of the held-out
# values) per output and method, the leave-one-out estimate `surrogate fit` reports, and
# whether it warned that the fit is worse than a linear trend.
#
# Usage: benches/peers/surrogate_noise.sh [data-dir] [fit-runs]   (from the repository root)
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${1:-${IMPACTCAL_CAR_POLE:-}}"
FIT="${2:-250}"
if [ -z "$DATA" ] || [ ! -f "$DATA/p9_X.csv" ]; then
    echo "usage: $0 <data-dir with p9_X.csv> [fit-runs] (or set IMPACTCAL_CAR_POLE)" >&2
    exit 2
fi
VENV=benches/peers/.venv
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install --quiet numpy==2.4.6 scipy==1.17.1
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}"
cargo build --quiet --release -p impactcal-cli
BIN="$CARGO_TARGET_DIR/release/impactcal"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$VENV/bin/python" - "$DATA" "$FIT" "$WORK" "$BIN" <<'PY'
import ast, glob, os, re, subprocess, sys
import numpy as np
import scipy
from scipy.interpolate import RBFInterpolator

data, fit, work, binary = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
problem = ast.literal_eval(open(os.path.join(data, "p9_problem.txt")).read())
names, bounds = problem["names"], np.array(problem["bounds"], dtype=float)
x = np.loadtxt(os.path.join(data, "p9_X.csv"), delimiter=",")
outputs = sorted(re.sub(r"^p9_Y_|\.csv$", "", os.path.basename(p))
                 for p in glob.glob(os.path.join(data, "p9_Y_*.csv")))
y = np.column_stack([np.loadtxt(os.path.join(data, f"p9_Y_{o}.csv")) for o in outputs])
xf, xh, yf, yh = x[:fit], x[fit:], y[:fit], y[fit:]
lo, hi = bounds[:, 0], bounds[:, 1]
uf, uh = (xf - lo) / (hi - lo), (xh - lo) / (hi - lo)

def write(path, header, rows):
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")

with open(f"{work}/bounds.csv", "w") as f:
    f.write("name,lower,upper,nominal\n")
    for n, (l, h) in zip(names, bounds):
        f.write(f"{n},{float(l)!r},{float(h)!r},{float(0.5 * (l + h))!r}\n")
write(f"{work}/params.csv", names, xf)
write(f"{work}/outputs.csv", outputs, yf)
write(f"{work}/query.csv", names, xh)

def rel(pred):
    return np.sqrt(np.mean((pred - yh) ** 2, axis=0)) / np.std(yh, axis=0)

def ours(label, args):
    model = f"{work}/model.json"
    r = subprocess.run([binary, "surrogate", "fit", "--bounds", f"{work}/bounds.csv",
                        "--params", f"{work}/params.csv", "--outputs", f"{work}/outputs.csv",
                        "--out", model] + args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{label}: {r.stderr}")
    loo, warned = {}, set()
    for line in r.stderr.splitlines():
        m = re.match(r"\s+(\S+): leave-one-out rms / std ([0-9.eE+-]+|NaN|inf)", line)
        if m:
            loo[m.group(1)] = float(m.group(2))
        m = re.match(r"warning: (\S+): (the leave-one-out error|a linear trend reproduces)", line)
        if m:
            warned.add(m.group(1))
    p = subprocess.run([binary, "surrogate", "predict", "--model", model,
                        "--params", f"{work}/query.csv", "--out", f"{work}/pred.csv"],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{label} predict: {p.stderr}")
    pred = np.loadtxt(f"{work}/pred.csv", delimiter=",", skiprows=1)
    return rel(pred.reshape(len(yh), -1)), loo, warned

rows = []
kinds = ["erbf", "cubic", "thin-plate", "gaussian", "multiquadric"]
for k in kinds:
    rows.append((k, *ours(k, ["--kind", k])))
for k in kinds:
    rows.append((f"{k} --auto", *ours(k, ["--kind", k, "--auto"])))
rows.append(("--kind auto", *ours("auto", ["--kind", "auto"])))

design = lambda u: np.column_stack([np.ones(len(u)), u])
beta, *_ = np.linalg.lstsq(design(uf), yf, rcond=None)
linear = rel(design(uh) @ beta)
smoothed = rel(RBFInterpolator(uf, yf, kernel="cubic", degree=1, smoothing=1.0)(uh))
best = np.minimum(linear, smoothed)

print(f"scipy {scipy.__version__}, numpy {np.__version__}; {len(x)} runs, first {fit} fit, "
      f"{len(yh)} held out; held-out RMSE / std (leave-one-out estimate; W = warned worse "
      f"than a linear trend)")
head = f"{'method':<22}" + "".join(f"{o:>22}" for o in outputs)
print(head)
print(f"{'linear regression':<22}" + "".join(f"{v:>22.3f}" for v in linear))
print(f"{'scipy cubic s=1.0':<22}" + "".join(f"{v:>22.3f}" for v in smoothed))
failures = []
for label, err, loo, warned in rows:
    cells = []
    for i, o in enumerate(outputs):
        flag = "W" if o in warned else " "
        cells.append(f"{err[i]:>9.3f} ({loo.get(o, float('nan')):.3f}) {flag}".rjust(22))
        if err[i] > 1.5 * linear[i] and o not in warned:
            failures.append(f"{label} on {o}: {err[i]:.3f} > 1.5 x linear {linear[i]:.3f}, no warning")
    print(f"{label:<22}" + "".join(cells))
auto = {label: err for label, err, _, _ in rows}
for label in ["--kind auto"] + [f"{k} --auto" for k in kinds]:
    ratio = auto[label] / best
    verdict = "within 5 %" if np.all(ratio <= 1.05) else "NOT within 5 %"
    print(f"{label}: held-out error / better of (scipy smoothed cubic, linear) = "
          + ", ".join(f"{o} {r:.3f}" for o, r in zip(outputs, ratio)) + f"  [{verdict}]")
print("unwarned kernels more than 1.5x worse than the linear trend: "
      + ("none" if not failures else "; ".join(failures)))
PY
