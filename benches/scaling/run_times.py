#!/usr/bin/env python3
"""Where the wall time of a study or closed loop went: in its model runs or in its own work.

    run_times.py OUT_DIR WALL_SECONDS

Reads every run's params.json under OUT_DIR/runs (prepared_at, finished_at: the run's
interval, from writing its inputs to reading its result back) and prints, as one JSON line:
the runs made, the sum of the runs' own times, the time at least one run was going (the
union of the intervals), and the rest of the wall time: what the study or loop spent on its
own statistics (nuisance terms, Jacobians, attribution, M1, reports) between runs; each also
per run. Standard library only.
"""
import json
import os
import sys


def main():
    out, wall = sys.argv[1], float(sys.argv[2])
    intervals = []
    for root, _, files in os.walk(os.path.join(out, "runs")):
        if "params.json" in files:
            with open(os.path.join(root, "params.json")) as f:
                r = json.load(f)
            if r.get("finished_at") is not None:
                intervals.append((r["prepared_at"], r["finished_at"]))
    intervals.sort()
    union, end = 0.0, None
    start = None
    for a, b in intervals:
        if end is None or a > end:
            if end is not None:
                union += end - start
            start, end = a, b
        else:
            end = max(end, b)
    if end is not None:
        union += end - start
    runs = len(intervals)
    own = sum(b - a for a, b in intervals)
    rest = max(wall - union, 0.0)
    print(json.dumps({
        "runs": runs,
        "wall_s": round(wall, 1),
        "runs_sum_s": round(own, 1),
        "runs_union_s": round(union, 1),
        "own_work_s": round(rest, 1),
        "run_s_per_run": round(own / runs, 3) if runs else None,
        "own_work_s_per_run": round(rest / runs, 3) if runs else None,
    }))


if __name__ == "__main__":
    main()
