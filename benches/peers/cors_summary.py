"""Summarises the JSON lines of cors_pysot.sh: per function and tool, the median and
quartiles of evaluations to 1% relative error (failures count as beyond the budget), the
success rate within the budget, and the median overhead per adaptive iteration."""

import json
import sys
from collections import defaultdict

import numpy as np

rows = [json.loads(line) for path in sys.argv[1:] for line in open(path) if line.startswith("{")]
groups = defaultdict(list)
for r in rows:
    groups[(r["function"], r["tool"])].append(r)
functions = ["branin", "goldstein-price", "hartmann3", "hartmann6", "shekel5", "shekel7", "shekel10"]
tools = ["impactcal-cors", "pysot-dycors", "pysot-srbf"]
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
