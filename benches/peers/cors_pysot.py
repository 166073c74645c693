"""pySOT (DYCORS and SRBF, cubic RBF with a linear tail) on the seven Dixon-Szego functions.

Prints one JSON line per (strategy, function, seed), in the format of our
`benches/harness/cors_dixon_szego.rs`: evaluations until the relative error drops below 1% (null
if not within the budget) and the mean time per adaptive iteration spent outside the
objective (the optimiser's overhead). Run through cors_pysot.sh; `--seeds S --first-seed F`
runs seeds F..F+S-1.

Noisy objectives: `--write-noise FILE` writes the shared noise table (the range of each
function over its box, and per seed the standard normal draws added to evaluation 1, 2, ...);
`--noise LEVEL --noise-file FILE` then runs the whole budget on `f(x) + LEVEL * range * z_k`
and reports pySOT's answer (the point of the lowest noisy value) with the true value there.
The range is `max f - f*` with the maximum over 100,000 uniform points of the box (numpy
seed 0) and `f*` the published minimum.
"""

import json
import sys
import time

import numpy as np
from poap.controller import SerialController
from pySOT.experimental_design import SymmetricLatinHypercube
from pySOT.optimization_problems import OptimizationProblem
from pySOT.strategy import DYCORSStrategy, SRBFStrategy
from pySOT.surrogate import CubicKernel, LinearTail, RBFInterpolant


def branin(x):
    b = 5.1 / (4 * np.pi**2)
    c = 5 / np.pi
    t = 1 / (8 * np.pi)
    return (x[1] - b * x[0] ** 2 + c * x[0] - 6) ** 2 + 10 * (1 - t) * np.cos(x[0]) + 10


def goldstein_price(x):
    x1, x2 = x
    a = 1 + (x1 + x2 + 1) ** 2 * (19 - 14 * x1 + 3 * x1**2 - 14 * x2 + 6 * x1 * x2 + 3 * x2**2)
    b = 30 + (2 * x1 - 3 * x2) ** 2 * (18 - 32 * x1 + 12 * x1**2 + 48 * x2 - 36 * x1 * x2 + 27 * x2**2)
    return a * b


from hartmann_constants import A3, A6, ALPHA, P3, P6  # noqa: E402

SA = np.array([[4, 4, 4, 4], [1, 1, 1, 1], [8, 8, 8, 8], [6, 6, 6, 6], [3, 7, 3, 7],
               [2, 9, 2, 9], [5, 5, 3, 3], [8, 1, 8, 1], [6, 2, 6, 2], [7, 3.6, 7, 3.6]], float)
SC = np.array([0.1, 0.2, 0.2, 0.4, 0.4, 0.6, 0.3, 0.7, 0.5, 0.5])


def hartmann(a, p):
    return lambda x: -np.sum(ALPHA * np.exp(-np.sum(a * (x - p) ** 2, axis=1)))


def shekel(m):
    return lambda x: -np.sum(1.0 / (np.sum((x - SA[:m]) ** 2, axis=1) + SC[:m]))


FUNCTIONS = {
    "branin": (branin, [-5, 0], [10, 15], 0.397887357729738),
    "goldstein-price": (goldstein_price, [-2, -2], [2, 2], 3.0),
    "hartmann3": (hartmann(A3, P3), [0] * 3, [1] * 3, -3.862782147820756),
    "hartmann6": (hartmann(A6, P6), [0] * 6, [1] * 6, -3.322368011415511),
    "shekel5": (shekel(5), [0] * 4, [10] * 4, -10.15319967905823),
    "shekel7": (shekel(7), [0] * 4, [10] * 4, -10.402940566818664),
    "shekel10": (shekel(10), [0] * 4, [10] * 4, -10.536409816692046),
}


class Problem(OptimizationProblem):
    def __init__(self, f, lb, ub):
        self.f = f
        self.dim = len(lb)
        self.lb = np.array(lb, float)
        self.ub = np.array(ub, float)
        self.int_var = np.array([])
        self.cont_var = np.arange(self.dim)

    def eval(self, x):
        return float(self.f(np.asarray(x, float)))


class Reached(Exception):
    pass


def write_noise(path, seeds, budget):
    rng = np.random.default_rng(0)
    with open(path, "w") as out:
        for name, (f, lb, ub, fmin) in FUNCTIONS.items():
            lb, ub = np.array(lb, float), np.array(ub, float)
            x = lb + (ub - lb) * rng.random((100_000, len(lb)))
            top = max(f(p) for p in x)
            out.write(f"range {name} {float(top - fmin)!r}\n")
        for seed in range(seeds):
            z = np.random.default_rng(10_000 + seed).standard_normal(budget)
            out.write(f"z {seed} " + " ".join(repr(float(v)) for v in z) + "\n")


def read_noise(path):
    ranges, z = {}, {}
    for line in open(path):
        parts = line.split()
        if parts[0] == "range":
            ranges[parts[1]] = float(parts[2])
        elif parts[0] == "z":
            z[int(parts[1])] = [float(v) for v in parts[2:]]
    return ranges, z


def run_noisy(strategy_name, name, seed, budget, level, table):
    """The whole budget on the noisy function; pySOT's answer is the point of the lowest
    noisy value (what `strategy` and the controller return as the best)."""
    f, lb, ub, fmin = FUNCTIONS[name]
    ranges, z = table
    sd = level * ranges[name]
    prob = Problem(f, lb, ub)
    np.random.seed(seed)
    dim = prob.dim
    design = SymmetricLatinHypercube(dim=dim, num_pts=2 * (dim + 1))
    surrogate = RBFInterpolant(dim=dim, lb=prob.lb, ub=prob.ub, kernel=CubicKernel(), tail=LinearTail(dim))
    cls = DYCORSStrategy if strategy_name == "dycors" else SRBFStrategy
    strategy = cls(max_evals=budget, opt_prob=prob, exp_design=design, surrogate=surrogate,
                   asynchronous=True, batch_size=1)
    state = {"n": 0, "best": np.inf, "x": None}

    def objective(x):
        x = np.asarray(x, float)
        v = prob.eval(x) + sd * z[seed][state["n"]]
        state["n"] += 1
        if v < state["best"]:
            state["best"], state["x"] = v, x.copy()
        return v

    controller = SerialController(objective=objective)
    controller.strategy = strategy
    controller.run()
    true = float(f(state["x"]))
    return {"tool": f"pysot-{strategy_name}", "function": name, "seed": seed, "noise": level,
            "evaluations": state["n"], "sample_noisy": state["best"], "sample_true": true,
            "sample_error": (true - fmin) / abs(fmin), "sample_x": state["x"].tolist()}


def run(strategy_name, name, seed, budget):
    f, lb, ub, fmin = FUNCTIONS[name]
    prob = Problem(f, lb, ub)
    np.random.seed(seed)
    dim = prob.dim
    n0 = 2 * (dim + 1)
    design = SymmetricLatinHypercube(dim=dim, num_pts=n0)
    surrogate = RBFInterpolant(dim=dim, lb=prob.lb, ub=prob.ub, kernel=CubicKernel(), tail=LinearTail(dim))
    cls = DYCORSStrategy if strategy_name == "dycors" else SRBFStrategy
    strategy = cls(max_evals=budget, opt_prob=prob, exp_design=design, surrogate=surrogate,
                   asynchronous=True, batch_size=1)
    state = {"n": 0, "best": np.inf, "hit": None, "f_time": 0.0}

    def objective(x):
        t = time.perf_counter()
        v = prob.eval(x)
        state["f_time"] += time.perf_counter() - t
        state["n"] += 1
        state["best"] = min(state["best"], v)
        if state["hit"] is None and (state["best"] - fmin) / abs(fmin) < 0.01:
            state["hit"] = state["n"]
            state["t_hit"] = time.perf_counter()
            raise Reached()
        return v

    controller = SerialController(objective=objective)
    controller.strategy = strategy
    t0 = time.perf_counter()
    try:
        controller.run()
    except Reached:
        pass
    total = state.get("t_hit", time.perf_counter()) - t0
    adaptive = max(state["n"] - n0, 1)
    overhead = (total - state["f_time"]) / adaptive
    return {"tool": f"pysot-{strategy_name}", "function": name, "seed": seed,
            "evals_to_1pct": state["hit"], "best": state["best"], "evaluations": state["n"],
            "overhead_s": overhead}


def main():
    args = sys.argv[1:]
    opts = dict(zip(args[::2], args[1::2]))
    seeds = int(opts.get("--seeds", 30))
    first = int(opts.get("--first-seed", 0))
    budget = int(opts.get("--budget", 300))
    names = opts.get("--functions", ",".join(FUNCTIONS)).split(",")
    strategies = opts.get("--strategies", "dycors,srbf").split(",")
    if "--write-noise" in opts:
        write_noise(opts["--write-noise"], seeds, budget)
        return
    table = read_noise(opts["--noise-file"]) if "--noise" in opts else None
    for s in strategies:
        for name in names:
            for seed in range(first, first + seeds):
                if table is None:
                    row = run(s, name, seed, budget)
                else:
                    row = run_noisy(s, name, seed, budget, float(opts["--noise"]), table)
                print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
