#!/usr/bin/env python3
"""Sobol' indices of the car pole study's four outputs, LS-DYNA's and ours.

Helper of benches/peers/car_pole_sobol.sh, which runs it in benches/peers/.venv (SALib,
numpy). Every index comes from the same pipeline of impactcal commands: an ERBF surrogate
fitted to runs (`surrogate fit --kind erbf --auto`, leave-one-out choice of r_c and
smoothing), a Saltelli design on the study's box (`sample --method saltelli`, scrambled
Sobol' base, SALib's row order), the surrogate's predictions there (`surrogate predict`),
and `impactcal sobol` (first order Saltelli 2010, total Jansen 1999, bootstrap intervals).
SALib 1.6 (`SALib.analyze.sobol`, the same two estimators) analyses the same predictions as
a peer of the estimator. Subcommands:

  lsdyna                 indices from LS-DYNA's 330 runs (p9_X.csv, p9_Y_*.csv): ours,
                         SALib's on the same surrogate samples, and the PCE indices the
                         study's repository publishes (PCE_S1, PCE_ST below)
  stability              the first-order indices from LS-DYNA's runs restricted to the
                         first n designs of the greedy maximin order that
                         car_pole_crosscode.py runs (and to random subsets of n), against
                         all 330: how many designs give stable leading indices
  ours RESULTS           indices of our solver from the designs in RESULTS (the
                         results.csv of car_pole_crosscode.sh), against LS-DYNA's on the
                         same designs and on all 330: rank correlation and top three
  selftest               checks of the ranking code against hand-computed values

Environment: CAR_POLE_DATA (default /work/shared/data/car_pole), IMPACTCAL (the binary,
default target/release/impactcal), SOBOL_N (Saltelli base rows, default 4096).
"""
import csv
import json
import os
import random
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from car_pole_crosscode import (  # noqa: E402  (the study's names, bounds and design order)
    BASE_REPEATS, BOUNDS, NAMES, OUTPUTS, maximin, read_x, read_y, spearman, unit)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("IMPACTCAL", os.path.join(ROOT, "target", "release", "impactcal"))
N_BASE = int(os.environ.get("SOBOL_N", "4096"))
SEED = 1

# The PCE Sobol' indices published in the study's repository (dbrizard/GSA-car-crash at
# 477fb05, GSA/car_v223_right-impact_v30/Eric/EricPCEsobol/SI-Y-<output>.txt and
# SI-tot-Y-<output>.txt, commit 656eca5 of 2024-04-08, read by PCEsobol.EricPCESobol): ten
# rows per file (ten PCE fits), one column per parameter in NAMES order; here the mean of
# the ten rows, as EricPCESobol takes it. Dated before the 330 runs were added (0250fa2,
# 2024-05-06), so they come from an earlier design of the same v223 model.
PCE_S1 = {
    "dmax": [0.2504, 0.1794, 0.4710, 0.0000, 0.0028, 0.0325, 0.0580, 0.0059, 0.0000],
    "fmax": [0.0000, 0.0000, 0.8436, 0.0000, 0.0000, 0.0000, 0.1564, 0.0000, 0.0000],
    "vfin": [0.2503, 0.2041, 0.4168, 0.0000, 0.0383, 0.0000, 0.0647, 0.0000, 0.0000],
    "IE": [0.1734, 0.6612, 0.0053, 0.0049, 0.0979, 0.0000, 0.0000, 0.0000, 0.0000],
}
PCE_ST = {
    "dmax": [0.2504, 0.1794, 0.4710, 0.0000, 0.0028, 0.0325, 0.0580, 0.0059, 0.0000],
    "fmax": [0.0000, 0.0000, 0.8436, 0.0000, 0.0000, 0.0000, 0.1564, 0.0000, 0.0000],
    "vfin": [0.2669, 0.2134, 0.4426, 0.0000, 0.0383, 0.0000, 0.0647, 0.0000, 0.0000],
    "IE": [0.2260, 0.6659, 0.0614, 0.0049, 0.0991, 0.0000, 0.0000, 0.0000, 0.0000],
}


def run(args):
    r = subprocess.run([BIN] + args, capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"impactcal {' '.join(args)}: {r.stderr.strip()}")
    return r.stderr


def write_inputs(work, x, y):
    """bounds.csv, params.csv and outputs.csv of runs x (rows of nine values) and outputs
    y (dict output -> values)."""
    with open(os.path.join(work, "bounds.csv"), "w") as f:
        f.write("name,lower,upper,nominal\n")
        for n, (lo, hi) in zip(NAMES, BOUNDS):
            f.write(f"{n},{lo},{hi},{(lo + hi) / 2}\n")
    with open(os.path.join(work, "params.csv"), "w") as f:
        f.write(",".join(NAMES) + "\n")
        for r in x:
            f.write(",".join(repr(v) for v in r) + "\n")
    outs = list(y)
    with open(os.path.join(work, "outputs.csv"), "w") as f:
        f.write(",".join(outs) + "\n")
        for r in zip(*(y[k] for k in outs)):
            f.write(",".join(repr(v) for v in r) + "\n")


def indices(x, y, bootstrap=100, peer=False):
    """Sobol' indices of the ERBF surrogate of runs (x, y). Returns dict output ->
    {"S1", "ST", "S1_conf" (half width of the bootstrap interval), "loo" (the fit's
    leave-one-out rms / std), and with peer "salib_S1", "salib_ST"}."""
    with tempfile.TemporaryDirectory() as work:
        p = lambda name: os.path.join(work, name)
        write_inputs(work, x, y)
        log = run(["surrogate", "fit", "--bounds", p("bounds.csv"), "--params",
                   p("params.csv"), "--outputs", p("outputs.csv"), "--kind", "erbf",
                   "--auto", "--out", p("model.json")])
        loo = {}
        for line in log.splitlines():
            parts = line.strip().split()
            if parts and parts[0].rstrip(":") in y and "leave-one-out" in line:
                loo[parts[0].rstrip(":")] = float(parts[5].rstrip(","))
        run(["sample", "--bounds", p("bounds.csv"), "--method", "saltelli", "--n",
             str(N_BASE), "--seed", str(SEED), "--out", p("design.csv")])
        run(["surrogate", "predict", "--model", p("model.json"), "--params",
             p("design.csv"), "--out", p("pred.csv")])
        with open(p("pred.csv")) as f:
            pred = list(csv.reader(f))
        out = {}
        # One output at a time: `impactcal sobol` calls a column of (near-)zero variance
        # relative to the file's largest null, and these four differ by 1e12 in variance.
        for j, k in enumerate(pred[0]):
            with open(p("pred_one.csv"), "w") as f:
                f.write("".join(f"{r[j]}\n" for r in pred))
            run(["sobol", "--bounds", p("bounds.csv"), "--params", p("design.csv"),
                 "--outputs", p("pred_one.csv"), "--bootstrap", str(bootstrap), "--seed",
                 str(SEED), "--out", p("sobol.json")])
            with open(p("sobol.json")) as f:
                s = json.load(f)
            out[k] = {"S1": s["first_order"][0], "ST": s["total"][0], "loo": loo.get(k)}
            if "first_order_ci" in s:
                out[k]["S1_conf"] = [(hi - lo) / 2 for lo, hi in s["first_order_ci"][0]]
        if peer:
            import numpy as np
            from SALib.analyze import sobol as salib_sobol
            problem = {"num_vars": len(NAMES), "names": NAMES,
                       "bounds": [list(b) for b in BOUNDS]}
            with open(p("pred.csv")) as f:
                rows = list(csv.reader(f))
            header = rows[0]
            for k in y:
                col = header.index(k)
                yk = np.array([float(r[col]) for r in rows[1:]])
                a = salib_sobol.analyze(problem, yk, calc_second_order=False,
                                        num_resamples=100, seed=SEED)
                out[k]["salib_S1"] = list(a["S1"])
                out[k]["salib_ST"] = list(a["ST"])
                out[k]["salib_S1_conf"] = list(a["S1_conf"])
        return out


def top(v, n=3):
    return [NAMES[i] for i in sorted(range(len(v)), key=lambda i: -v[i])[:n]]


def fmt(v):
    return " ".join(f"{x:6.3f}" for x in v)


def lsdyna():
    x, y = read_x(), read_y()
    r = indices(x, y, peer=True)
    print(f"LS-DYNA's {len(x)} runs; ERBF surrogate (--auto), Saltelli base {N_BASE} "
          f"(seed {SEED}); SALib 1.6 on the same predictions; PCE: the study's published "
          f"indices (mean of its ten fits)")
    print()
    print("| output | index | source | " + " | ".join(NAMES) + " | top three |")
    print("|---|---|---|" + "---|" * len(NAMES) + "---|")
    worst = 0.0
    for k in OUTPUTS:
        s = r[k]
        for idx, mine, peer, pce in (("S1", s["S1"], s["salib_S1"], PCE_S1[k]),
                                     ("ST", s["ST"], s["salib_ST"], PCE_ST[k])):
            for src, v in (("impactcal", mine), ("SALib", peer), ("PCE", pce)):
                print(f"| {k} | {idx} | {src} | " + " | ".join(f"{a:.3f}" for a in v)
                      + f" | {', '.join(top(v))} |")
            worst = max(worst, max(abs(a - b) for a, b in zip(mine, peer)))
    print()
    print(f"largest |impactcal - SALib| over all indices: {worst:.2e}")
    print()
    print("| output | LOO rms/std | S1 CI half width (max) | Spearman S1 impactcal vs PCE | "
          "top three alike | sum S1 impactcal | sum S1 PCE |")
    print("|---|---|---|---|---|---|---|")
    for k in OUTPUTS:
        s = r[k]
        ci = max(s.get("S1_conf", [float("nan")]))
        same = set(top(s["S1"])) == set(top(PCE_S1[k]))
        print(f"| {k} | {s['loo']:.3f} | {ci:.3f} | {spearman(s['S1'], PCE_S1[k]):.3f} | "
              f"{'yes' if same else 'no'} | {sum(s['S1']):.3f} | {sum(PCE_S1[k]):.3f} |")


def stability(sizes=(20, 30, 40, 50, 60, 80, 120, 200), seeds=4):
    x, y = read_x(), read_y()
    order = maximin([unit(r) for r in x], max(sizes))
    full = indices(x, y, bootstrap=0)
    print("First-order indices from LS-DYNA's first n maximin designs (the order "
          "car_pole_crosscode.py runs) and from random subsets of n, against all 330")
    print()
    print("| n | subset | " + " | ".join(f"{k} S1 of {', '.join(top(full[k]['S1']))}"
                                        for k in OUTPUTS) + " |")
    print("|---|---|" + "---|" * len(OUTPUTS))
    row = lambda n, name, r: print(
        f"| {n} | {name} | " + " | ".join(
            " ".join(f"{r[k]['S1'][NAMES.index(p)]:.2f}" for p in top(full[k]['S1']))
            + f" (max dev {max(abs(r[k]['S1'][i] - full[k]['S1'][i]) for i in range(9)):.2f}"
            + f"{'' if top(r[k]['S1']) == top(full[k]['S1']) else ', order differs'})"
            for k in OUTPUTS) + " |")
    row(len(x), "all", full)
    rng = random.Random(SEED)
    for n in sizes:
        pick = order[:n]
        r = indices([x[i] for i in pick], {k: [y[k][i] for i in pick] for k in OUTPUTS},
                    bootstrap=0)
        row(n, "maximin", r)
        for s in range(seeds):
            pick = rng.sample(range(len(x)), n)
            r = indices([x[i] for i in pick], {k: [y[k][i] for i in pick] for k in OUTPUTS},
                        bootstrap=0)
            row(n, f"random {s + 1}", r)
        sys.stdout.flush()


def ours(results):
    with open(results) as f:
        rows = [r for r in csv.DictReader(f) if r["row"].isdigit() or r["row"] == "base"]
    if len(rows) < 10:
        raise SystemExit(f"{results}: {len(rows)} designs, too few for a surrogate")
    x_all, y_all = read_x(), read_y()
    # The base design (the box centre) is one of the runs; LS-DYNA's value there is the
    # mean of its five repeats.
    base_x = [(lo + hi) / 2 for lo, hi in BOUNDS]
    base_y = {k: sum(v) / len(v) for k, v in BASE_REPEATS.items()}
    x = [base_x if r["row"] == "base" else x_all[int(r["row"])] for r in rows]
    theirs = {k: [base_y[k] if r["row"] == "base" else y_all[k][int(r["row"])]
                  for r in rows] for k in OUTPUTS}
    mine = indices(x, {k: [float(r[k]) for r in rows] for k in OUTPUTS})
    same = indices(x, theirs)
    full = indices(x_all, y_all, bootstrap=0)
    print(f"{len(rows)} designs run by our solver ({results}: the box centre and rows of "
          f"p9_X.csv); the same pipeline on LS-DYNA's outputs at those designs and at all "
          f"330")
    print()
    print("| output | source | LOO rms/std | S1: " + " | ".join(NAMES) + " | top three |")
    print("|---|---|---|" + "---|" * len(NAMES) + "---|")
    srcs = (("ours", mine), (f"LS-DYNA, same {len(rows)}", same), ("LS-DYNA, 330", full))
    for k in OUTPUTS:
        for name, r in srcs:
            # A surrogate no better than the mean out of sample has learnt no trend: its
            # indices are those of noise.
            flag = " (no trend)" if r[k]["loo"] >= 1.0 else ""
            print(f"| {k} | {name} | {r[k]['loo']:.3f}{flag} | "
                  + " | ".join(f"{a:.3f}" for a in r[k]["S1"])
                  + f" | {', '.join(top(r[k]['S1']))} |")
        print(f"| {k} | PCE (published) | | " + " | ".join(f"{a:.3f}" for a in PCE_S1[k])
              + f" | {', '.join(top(PCE_S1[k]))} |")
    print()
    print("Do both codes rank the parameters alike? Spearman over the nine first-order "
          "(and total) indices; top three as sets")
    print()
    print("| output | against | Spearman S1 | Spearman ST | top three ours | top three theirs "
          "| same top three |")
    print("|---|---|---|---|---|---|---|")
    for k in OUTPUTS:
        for name, r in srcs[1:] + (("PCE (published)", {k: {"S1": PCE_S1[k],
                                                           "ST": PCE_ST[k]}}),):
            a, b = top(mine[k]["S1"]), top(r[k]["S1"])
            print(f"| {k} | {name} | {spearman(mine[k]['S1'], r[k]['S1']):.3f} | "
                  f"{spearman(mine[k]['ST'], r[k]['ST']):.3f} | {', '.join(a)} | "
                  f"{', '.join(b)} | {'yes' if set(a) == set(b) else 'no'}"
                  f"{' (same order)' if a == b else ''} |")


def selftest():
    assert top([0.1, 0.5, 0.2, 0.0, 0, 0, 0, 0, 0.3]) == ["trailb", "ybody", "trailf"]
    assert abs(spearman([1, 2, 3], [10, 30, 20]) - 0.5) < 1e-12
    assert sum(PCE_S1["fmax"]) > 0.99 and all(
        st >= s1 - 1e-12 for k in PCE_S1 for s1, st in zip(PCE_S1[k], PCE_ST[k]))
    print("selftest: ok")


def main(argv):
    if not argv:
        raise SystemExit(__doc__)
    if argv[0] == "lsdyna":
        lsdyna()
    elif argv[0] == "stability":
        stability()
    elif argv[0] == "ours":
        ours(argv[1])
    elif argv[0] == "selftest":
        selftest()
    else:
        raise SystemExit(f"unknown subcommand {argv[0]}\n{__doc__}")


if __name__ == "__main__":
    main(sys.argv[1:])
