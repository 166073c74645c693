"""Summarises the JSON lines of cors_pysot.sh: per function and tool, the median and
quartiles of evaluations to 1% relative error (failures count as beyond the budget), the
success rate within the budget, and the median overhead per adaptive iteration, with the
ratio of ours to the faster pySOT strategy (both timed in the same run).

Lines of noisy runs (with a "noise" key) are summarised apart: per function, noise level,
tool and answer (the luckiest sample; ours also the smoothed surrogate's answer), the median
and quartiles of the TRUE relative error (f(x) - f*) / |f*| at the answer, and the seeds
whose answer lies within 1%."""

import json
import sys
from collections import defaultdict

import numpy as np

rows = [json.loads(line) for path in sys.argv[1:] for line in open(path) if line.startswith("{")]
noisy = [r for r in rows if "noise" in r]
rows = [r for r in rows if "noise" not in r]
groups = defaultdict(list)
for r in rows:
    groups[(r["function"], r["tool"])].append(r)
functions = ["branin", "goldstein-price", "hartmann3", "hartmann6", "shekel5", "shekel7", "shekel10"]
tools = ["impactcal-cors", "pysot-dycors", "pysot-srbf"]
if rows:
    print("| function | tool | seeds | median evals to 1% | quartiles | success within budget | median overhead per iteration (ms) |")
    print("|---|---|---|---|---|---|---|")
    for f in functions:
        for t in tools:
            g = groups.get((f, t))
            if not g:
                continue
            e = np.array([r["evals_to_1pct"] if r["evals_to_1pct"] is not None else np.inf for r in g])
            q1, med, q3 = np.percentile(e, [25, 50, 75], method="lower") if np.isfinite(e).all() else np.quantile(e, [0.25, 0.5, 0.75], method="lower")
            fmt = lambda v: "fail" if not np.isfinite(v) else f"{v:.0f}"
            ok = np.isfinite(e).sum()
            over = np.median([r["overhead_s"] for r in g]) * 1e3
            print(f"| {f} | {t} | {len(g)} | {fmt(med)} | {fmt(q1)}-{fmt(q3)} | {ok}/{len(g)} | {over:.2f} |")
    # Overheads of both sides from the same run: the ratio of ours to the faster pySOT strategy.
    over = {k: np.median([r["overhead_s"] for r in g]) * 1e3 for k, g in groups.items()}
    if any(t == "impactcal-cors" for _, t in over) and any(t != "impactcal-cors" for _, t in over):
        print()
        print("| function | impactcal-cors (ms) | pySOT DYCORS (ms) | pySOT SRBF (ms) | ratio to the faster pySOT |")
        print("|---|---|---|---|---|")
        for f in functions:
            if (f, tools[0]) not in over:
                continue
            peers = [over[(f, t)] for t in tools[1:] if (f, t) in over]
            cells = " | ".join(f"{over[(f, t)]:.2f}" if (f, t) in over else "-" for t in tools)
            ratio = f"{over[(f, tools[0])] / min(peers):.2f}" if peers else "-"
            print(f"| {f} | {cells} | {ratio} |")

if noisy:
    answers = defaultdict(list)
    for r in noisy:
        answers[(r["function"], r["noise"], r["tool"], "best sample")].append(r["sample_error"])
        if "answer_error" in r:
            answers[(r["function"], r["noise"], r["tool"], "surrogate")].append(r["answer_error"])
    levels = sorted({r["noise"] for r in noisy})
    # The range of each function (out/noise.txt, next to the first file), for the gap in
    # units of the range: the relative error divides by |f*|, which is small for Branin.
    import os
    ranges = {}
    table = os.path.join(os.path.dirname(sys.argv[1]), "noise.txt")
    if os.path.exists(table):
        for line in open(table):
            p = line.split()
            if p and p[0] == "range":
                ranges[p[1]] = float(p[2])
    fstar = {"branin": 0.397887357729738, "goldstein-price": 3.0, "hartmann3": 3.862782147820756,
             "hartmann6": 3.322368011415511, "shekel5": 10.15319967905823,
             "shekel7": 10.402940566818664, "shekel10": 10.536409816692046}
    print()
    print("| function | noise (of range) | tool | answer | seeds | median true rel. error | quartiles | within 1% | median true gap (% of range) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for f in functions:
        for level in levels:
            for t in tools:
                for a in ["best sample", "surrogate"]:
                    e = answers.get((f, level, t, a))
                    if not e:
                        continue
                    q1, med, q3 = np.percentile(e, [25, 50, 75], method="lower")
                    ok = sum(v < 0.01 for v in e)
                    gap = f"{100 * med * fstar[f] / ranges[f]:.3g}" if f in ranges else "-"
                    print(f"| {f} | {level:g} | {t} | {a} | {len(e)} | {med:.3g} | {q1:.3g}-{q3:.3g} | {ok}/{len(e)} | {gap} |")
