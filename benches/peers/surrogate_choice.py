"""Tables of benches/peers/surrogate_choice.sh: held-out error of `impactcal surrogate fit`
under its two selection rules against the better of a linear regression and a
cross-validated smoothed cubic RBF (scipy). Arguments: the impactcal binary, a scratch
directory, and the car pole data directory (empty: synthetic families only)."""

import ast
import os
import subprocess
import sys

import numpy as np
import scipy
from scipy.interpolate import RBFInterpolator

BIN, WORK, DATA = sys.argv[1], sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else ""
SPLITS = int(os.environ.get("SPLITS", 5))
SEEDS = int(os.environ.get("SEEDS", 5))
METHODS = {"auto": ["--kind", "auto"], "cubic": ["--kind", "cubic", "--auto"],
           "erbf": ["--kind", "erbf", "--auto"]}
METHODS = {k: METHODS[k] for k in os.environ.get("METHODS", "auto cubic erbf").split()}
RULES = os.environ.get("RULES", "min-loo one-se").split()
OLD, NEW = RULES[0], RULES[-1]  # today's rule and the rule under test
SMOOTHINGS = [0.0] + [10.0**k for k in range(-3, 4)]


def write(path, header, rows):
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def ours(names, bounds, xf, yf, xq, args):
    """Fits with the CLI and predicts at xq (raw inputs); returns the predictions."""
    with open(f"{WORK}/bounds.csv", "w") as f:
        f.write("name,lower,upper,nominal\n")
        for n, (lo, hi) in zip(names, bounds):
            f.write(f"{n},{float(lo)!r},{float(hi)!r},{float(0.5 * (lo + hi))!r}\n")
    outs = [f"y{j}" for j in range(yf.shape[1])]
    write(f"{WORK}/params.csv", names, xf)
    write(f"{WORK}/outputs.csv", outs, yf)
    write(f"{WORK}/query.csv", names, xq)
    r = subprocess.run([BIN, "surrogate", "fit", "--bounds", f"{WORK}/bounds.csv", "--params",
                        f"{WORK}/params.csv", "--outputs", f"{WORK}/outputs.csv", "--out",
                        f"{WORK}/model.json"] + args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{args}: {r.stderr}")
    p = subprocess.run([BIN, "surrogate", "predict", "--model", f"{WORK}/model.json",
                        "--params", f"{WORK}/query.csv", "--out", f"{WORK}/pred.csv"],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{args} predict: {p.stderr}")
    return np.loadtxt(f"{WORK}/pred.csv", delimiter=",", skiprows=1).reshape(len(xq), -1)


def yardsticks(uf, yf, uq):
    """Linear regression and the cubic RBF (linear tail) whose smoothing 10-fold
    cross-validation chooses per output, fitted in unit-scaled inputs; predictions at uq."""
    design = lambda u: np.column_stack([np.ones(len(u)), u])
    beta, *_ = np.linalg.lstsq(design(uf), yf, rcond=None)
    linear = design(uq) @ beta
    folds = np.array_split(np.random.default_rng(0).permutation(len(uf)), 10)
    cubic = np.empty((len(uq), yf.shape[1]))
    for j in range(yf.shape[1]):
        cv = []
        for s in SMOOTHINGS:
            err = 0.0
            for k in range(10):
                test = folds[k]
                train = np.setdiff1d(np.arange(len(uf)), test)
                m = RBFInterpolator(uf[train], yf[train, j], kernel="cubic", degree=1, smoothing=s)
                err += np.sum((m(uf[test]) - yf[test, j]) ** 2)
            cv.append(err)
        s = SMOOTHINGS[int(np.argmin(cv))]
        cubic[:, j] = RBFInterpolator(uf, yf[:, j], kernel="cubic", degree=1, smoothing=s)(uq)
    return linear, cubic


def rel(pred, truth, scale):
    return np.sqrt(np.mean((pred - truth) ** 2, axis=0)) / scale


def lhs(n, d, rng):
    u = (np.argsort(rng.random((n, d)), axis=0) + rng.random((n, d))) / n
    return u


# Synthetic families (unit-cube inputs mapped onto each box).
def sine(x):
    m = x.shape[1]
    return sum((1 + 0.3 * j) * np.sin(2 * x[:, j]) for j in range(m)) + x[:, 0] * x[:, m - 1]


def branin(x):
    b, c, t = 5.1 / (4 * np.pi**2), 5 / np.pi, 1 / (8 * np.pi)
    return (x[:, 1] - b * x[:, 0] ** 2 + c * x[:, 0] - 6) ** 2 + 10 * (1 - t) * np.cos(x[:, 0]) + 10


from hartmann_constants import A3, A6, ALPHA, P3, P6  # noqa: E402


def hartmann(a, p):
    return lambda x: -np.sum(ALPHA * np.exp(-np.sum(a * (x[:, None, :] - p) ** 2, axis=2)), axis=1)


FAMILIES = {
    "sine-3": (sine, [[0, 1]] * 3),
    "sine-9": (sine, [[0, 1]] * 9),
    "branin": (branin, [[-5, 10], [0, 15]]),
    "hartmann3": (hartmann(A3, P3), [[0, 1]] * 3),
    "hartmann6": (hartmann(A6, P6), [[0, 1]] * 6),
}
NOISE = [0.0, 0.05, 0.5]

rows = []  # (set, case, yardstick error, {(method, rule): error})


def evaluate(label, case, names, bounds, xf, yf, xq, truth, scale):
    lo, hi = bounds[:, 0], bounds[:, 1]
    uf, uq = (xf - lo) / (hi - lo), (xq - lo) / (hi - lo)
    linear, cubic = yardsticks(uf, yf, uq)
    best = np.minimum(rel(linear, truth, scale), rel(cubic, truth, scale))
    errs = {}
    for m, args in METHODS.items():
        for rule in RULES:
            errs[(m, rule)] = rel(ours(names, bounds, xf, yf, xq, args + ["--select", rule]),
                                  truth, scale)
    for j in range(yf.shape[1]):
        rows.append((label, f"{case[j]}", best[j], {k: v[j] for k, v in errs.items()}))
        ratios = " ".join(f"{m}/{r}={errs[(m, r)][j] / best[j]:.3f}" for m, r in errs)
        print(f"# {label} | {case[j]} | {best[j]:.3g} | {ratios}", file=sys.stderr, flush=True)


if DATA:
    problem = ast.literal_eval(open(os.path.join(DATA, "p9_problem.txt")).read())
    names, bounds = problem["names"], np.array(problem["bounds"], dtype=float)
    x = np.loadtxt(os.path.join(DATA, "p9_X.csv"), delimiter=",")
    outputs = ["IE", "dmax", "fmax", "vfin"]
    y = np.column_stack([np.loadtxt(os.path.join(DATA, f"p9_Y_{o}.csv")) for o in outputs])
    for split in range(SPLITS):
        order = np.random.default_rng(split).permutation(len(x))
        fit, held = order[:250], order[250:]
        evaluate("car pole", [f"split {split} {o}" for o in outputs], names, bounds, x[fit],
                 y[fit], x[held], y[held], np.std(y[held], axis=0))

for name, (f, box) in FAMILIES.items():
    box = np.array(box, float)
    d = len(box)
    n = 10 * d + 20
    lo, hi = box[:, 0], box[:, 1]
    ref = f(lo + (hi - lo) * np.random.default_rng(99).random((10000, d)))
    sd = np.std(ref)
    names = [f"p{j}" for j in range(d)]
    for level in NOISE:
        for seed in range(SEEDS):
            rng = np.random.default_rng(1000 + seed)
            xf = lo + (hi - lo) * lhs(n, d, rng)
            yf = (f(xf) + level * sd * rng.standard_normal(n))[:, None]
            xq = lo + (hi - lo) * rng.random((1000, d))
            evaluate("synthetic", [f"{name} noise {level:g} seed {seed}"], names, box, xf, yf,
                     xq, f(xq)[:, None], sd)

print(f"scipy {scipy.__version__}, numpy {np.__version__}; error / yardstick, yardstick = "
      f"min(linear regression, cubic RBF smoothing by 10-fold CV over {SMOOTHINGS})")
print()
head = "| set | case | yardstick |" + "".join(f" {m} {r} |" for m in METHODS for r in RULES)
print(head)
print("|" + "---|" * (3 + len(METHODS) * len(RULES)))
for label, case, best, errs in rows:
    cells = "".join(f" {errs[(m, r)] / best:.3f} |" for m in METHODS for r in RULES)
    print(f"| {label} | {case} | {best:.3g} |{cells}")
print()
print(f"| set | method | cases | within 5 % ({OLD}) | within 5 % ({NEW}) | worst ratio ({OLD}) "
      f"| worst ratio ({NEW}) | {NEW} worse than {OLD} | by more than 5 % | better |")
print("|---|---|---|---|---|---|---|---|---|---|")
for label in ["car pole", "synthetic"]:
    sel = [r for r in rows if r[0] == label]
    if not sel:
        continue
    for m in METHODS:
        old = np.array([r[3][(m, OLD)] / r[2] for r in sel])
        new = np.array([r[3][(m, NEW)] / r[2] for r in sel])
        print(f"| {label} | {m} | {len(sel)} | {np.sum(old <= 1.05)} | {np.sum(new <= 1.05)} | "
              f"{old.max():.3f} | {new.max():.3f} | {np.sum(new > old * (1 + 1e-9))} | "
              f"{np.sum(new > 1.05 * old)} | {np.sum(new < old * (1 - 1e-9))} |")
for label in ["synthetic"]:
    sel = [r for r in rows if r[0] == label]
    print()
    print(f"| family | noise | method | median ratio ({OLD}) | median ratio ({NEW}) | "
          f"within 5 % ({OLD}) | within 5 % ({NEW}) |")
    print("|---|---|---|---|---|---|---|")
    for name in FAMILIES:
        for level in NOISE:
            cases = [r for r in sel if r[1].startswith(f"{name} noise {level:g} ")]
            if not cases:
                continue
            for m in METHODS:
                old = np.array([r[3][(m, OLD)] / r[2] for r in cases])
                new = np.array([r[3][(m, NEW)] / r[2] for r in cases])
                print(f"| {name} | {level:g} | {m} | {np.median(old):.3f} | {np.median(new):.3f} | "
                      f"{np.sum(old <= 1.05)}/{len(cases)} | {np.sum(new <= 1.05)}/{len(cases)} |")
