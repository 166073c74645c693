#!/usr/bin/env python3
"""Compares two loop.json files (a closed loop's result) number by number.

    compare_loop_json.py BEFORE.json AFTER.json [--tol 1e-9] [--runs BEFORE_DIR AFTER_DIR]

Walks both documents together and prints, for every key path whose numbers differ (list
indices and channel labels folded into `[]` and `<label>`), the largest difference over
the largest magnitude on that path, max |a - b| / max(|a|, |b|), and every structural
difference (a key or list entry on one side only, text that differs), counted.
The M1 exceedances come from a Monte Carlo ensemble of predictive draws: they are listed
apart, with the binomial standard error of an exceedance fraction over the samples.
Exit status 0 when every other number agrees within --tol and nothing structural
differs, 1 otherwise. With --runs, the points of every stage of runs the two loops made
(OUT/runs/<stage>/<i>/params.json), in the order the first loop made them, up to the first
stage where they differ and the one after: on a model whose response changes by its own
noise under a change in the last bits of a parameter (a crash model), two loops whose
arithmetic differs only in round-off agree up to the first step that depends on it, and
then follow different trajectories of the same noise. Standard library only.
"""
import json
import math
import os
import sys
from collections import defaultdict


LABELLED = ("sensor_pattern", "u1", "gains", "biases", "sensors")


def walk(a, b, path, diffs, structure):
    if isinstance(a, dict) and isinstance(b, dict):
        labelled = path.rsplit(".", 1)[-1] in LABELLED
        for k in sorted(set(a) | set(b)):
            key = "<label>" if labelled else k
            if k not in a or k not in b:
                structure.append(f"{path}.{key}: only in {'after' if k not in a else 'before'}")
            else:
                walk(a[k], b[k], f"{path}.{key}", diffs, structure)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            structure.append(f"{path}: {len(a)} entries before, {len(b)} after")
        for x, y in zip(a, b):
            walk(x, y, f"{path}[]", diffs, structure)
    elif isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or isinstance(b, str):
        if a != b:
            structure.append(f"{path}: {a!r} before, {b!r} after")
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        d, m = diffs.get(path, (0.0, 0.0))
        delta = abs(a - b)
        if math.isnan(delta):
            delta = 0.0 if (math.isnan(a) and math.isnan(b)) else math.inf
        diffs[path] = (max(d, delta), max(m, abs(a), abs(b)))
    elif a is None and b is None:
        pass
    else:
        structure.append(f"{path}: {a!r} before, {b!r} after")


def stage_points(out):
    """{stage: (start time, [point per run])} of a loop's output folder."""
    stages = {}
    root = os.path.join(out, "runs")
    for stage in os.listdir(root):
        d = os.path.join(root, stage)
        if not os.path.isdir(d):
            continue
        runs = sorted((int(i) for i in os.listdir(d) if i.isdigit()))
        points, start = [], math.inf
        for i in runs:
            with open(os.path.join(d, str(i), "params.json")) as f:
                r = json.load(f)
            points.append(r["values"])
            start = min(start, r["prepared_at"])
        stages[stage] = (start, points)
    return stages


def compare_runs(before, after):
    a, b = stage_points(before), stage_points(after)
    differing = 0
    for stage in sorted(a, key=lambda k: a[k][0]):
        if stage not in b:
            print(f"  runs {stage}: only before")
            differing += 1
        else:
            pa, pb = a[stage][1], b[stage][1]
            worst = 0.0
            for x, y in zip(pa, pb):
                for u, v in zip(x, y):
                    scale = max(abs(u), abs(v))
                    if scale > 0:
                        worst = max(worst, abs(u - v) / scale)
            same = "identical" if worst == 0.0 and len(pa) == len(pb) else \
                f"largest relative difference {worst:.3e} ({len(pa)} and {len(pb)} runs)"
            print(f"  runs {stage}: {same}")
            if same != "identical":
                differing += 1
        if differing >= 2:
            print("  (later stages follow from these)")
            break


def main():
    args = sys.argv[1:]
    runs = None
    if "--runs" in args:
        i = args.index("--runs")
        runs = args[i + 1 : i + 3]
        del args[i : i + 3]
    tol = 1e-9
    if "--tol" in args:
        i = args.index("--tol")
        tol = float(args[i + 1])
        del args[i : i + 2]
    before, after = (json.load(open(p)) for p in args)
    raw, structure = {}, []
    walk(before, after, "", raw, structure)
    diffs = {p: (d / m if m > 0 else (0.0 if d == 0 else math.inf)) for p, (d, m) in raw.items()}
    m1 = {p: d for p, d in diffs.items() if p.endswith("m1_exceedance")}
    rest = {p: d for p, d in diffs.items() if p not in m1}
    worst = max(rest.values(), default=0.0)
    print(f"{len(rest)} numeric paths compared; largest relative difference {worst:.3e}")
    for p, d in sorted(rest.items(), key=lambda x: -x[1]):
        if d > tol:
            print(f"  {d:.3e}  {p}  (largest difference {raw[p][0]:.3e}, largest value {raw[p][1]:.3e})")
    samples = None
    try:
        det = before["detection"]
        samples = len(det["v1"])
    except (KeyError, TypeError):
        pass
    for side, doc in (("before", before), ("after", after)):
        for test in ("metrics_calibration", "metrics_holdout"):
            stages = doc.get(test) or {}
            vals = {k: v.get("m1_exceedance") for k, v in stages.items() if isinstance(v, dict)}
            if vals:
                print(f"  M1 exceedance {side:6s} {test}: {vals}")
    if samples:
        print(f"  (Monte Carlo: an exceedance f over {samples} samples has standard error "
              f"sqrt(f (1 - f) / {samples}), e.g. {math.sqrt(0.05 * 0.95 / samples):.4f} at 0.05)")
    counted = defaultdict(int)
    for s in structure:
        counted[s] += 1
    for s, c in counted.items():
        print(f"  structure ({c}x): {s}")
    if runs:
        compare_runs(*runs)
    ok = worst <= tol and not structure
    print("same numbers" if ok else "DIFFERENT")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
