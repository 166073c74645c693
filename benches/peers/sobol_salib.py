"""Sobol' indices of a many-column output: impactcal against SALib 1.6 looped over columns.

Both sides use the same input: the plain (unscrambled) Sobol' Saltelli design of d
parameters on the unit cube (SALib's `sample.sobol(..., scramble=False)`; impactcal makes
identical rows, checked by crates/impactcal-sobol/tests/salib_agreement.rs) and the output
y(x, t) = G(x) (1 + s) + x1 s + x2 x3 (1 - s), s = t / T, with G the Sobol' G-function
(a = 0, 0.5, 3, 9, 99, ...). Both compute first and total indices (and second order with
--second-order) with the same number of bootstrap resamples.

SALib has no vector outputs: users loop `sobol.analyze` over the columns. Looping over all
T columns would take tens of minutes, so the script times SALib on the first
--salib-columns columns and extrapolates the median per-column time to T columns (SALib's
cost per column does not depend on the others). impactcal analyses all T columns in one call
(benches/harness/sobol_peer.rs, median of --repeats runs), and the script checks that both give the
same point estimates on the columns SALib ran.

Usage (from the repository root):
    python3 benches/peers/sobol_salib.py --n 16384 --d 6 --t 1000 --resamples 100
    python3 benches/peers/sobol_salib.py --n 16384 --d 20 --t 100 --resamples 100 --second-order
"""

import argparse
import json
import pathlib
import resource
import statistics
import subprocess
import sys
import time
import venv

ROOT = pathlib.Path(__file__).resolve().parents[2]
VENV = ROOT / "benches" / "peers" / ".venv"


def ensure_venv() -> None:
    """Re-runs this script inside benches/peers/.venv with SALib installed."""
    python = VENV / "bin" / "python"
    if pathlib.Path(sys.prefix).resolve() == VENV.resolve():
        return
    if not python.exists():
        venv.create(VENV, with_pip=True)
    # The venv is shared by all peer scripts: install SALib even when it already exists.
    subprocess.run([str(python), "-m", "pip", "install", "-q", "SALib==1.6.0", "scipy", "numpy"], check=True)
    sys.exit(subprocess.run([str(python), __file__, *sys.argv[1:]]).returncode)


def outputs(x, cols, t_count):
    import numpy as np

    d = x.shape[1]
    a = np.array([0.0, 0.5, 3.0, 9.0] + [99.0] * max(0, d - 4))[:d]
    g = np.prod((np.abs(4.0 * x - 2.0) + a) / (1.0 + a), axis=1)
    s = np.arange(cols) / t_count
    return g[:, None] * (1.0 + s) + x[:, [0]] * s + (x[:, 1] * x[:, 2])[:, None] * (1.0 - s)


def main() -> None:
    ensure_venv()
    import numpy as np
    from SALib.analyze import sobol as salib_analyze
    from SALib.sample import sobol as salib_sample

    p = argparse.ArgumentParser()
    p.add_argument("--n", type=int, default=16384)
    p.add_argument("--d", type=int, default=6)
    p.add_argument("--t", type=int, default=1000)
    p.add_argument("--resamples", type=int, default=100)
    p.add_argument("--second-order", action="store_true")
    p.add_argument("--salib-columns", type=int, default=5)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    k = min(args.salib_columns, args.t, 10)

    subprocess.run(
        ["cargo", "build", "--release", "--quiet", "--example", "sobol_peer"], cwd=ROOT, check=True
    )
    import os

    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    ours_cmd = [
        str(target / "release" / "examples" / "sobol_peer"),
        str(args.n), str(args.d), str(args.t), str(args.resamples),
        "1" if args.second_order else "0", str(args.repeats),
    ]
    ours = json.loads(subprocess.run(ours_cmd, check=True, capture_output=True, text=True).stdout)

    problem = {"num_vars": args.d, "names": [f"x{i + 1}" for i in range(args.d)], "bounds": [[0.0, 1.0]] * args.d}
    x = salib_sample.sample(problem, args.n, calc_second_order=args.second_order, scramble=False)
    y = outputs(x, k, args.t)
    times, max_diff = [], 0.0
    for t in range(k):
        start = time.perf_counter()
        s = salib_analyze.analyze(
            problem, y[:, t], calc_second_order=args.second_order, num_resamples=args.resamples, seed=1
        )
        times.append(time.perf_counter() - start)
        max_diff = max(
            max_diff,
            float(np.max(np.abs(s["S1"] - np.array(ours["first_order"][t])))),
            float(np.max(np.abs(s["ST"] - np.array(ours["total"][t])))),
        )
        if args.second_order:
            ours_s2 = np.array(ours["second_order"][t], dtype=float)
            upper = np.triu_indices(args.d, 1)
            max_diff = max(max_diff, float(np.max(np.abs(s["S2"][upper] - ours_s2[upper]))))
    per_column = statistics.median(times)
    salib_total = per_column * args.t
    rows = x.shape[0]
    print(f"case: N={args.n} d={args.d} T={args.t} rows={rows} resamples={args.resamples} "
          f"second_order={args.second_order}")
    print(f"impactcal: median {ours['median_s']:.3f} s over {args.repeats} runs "
          f"({ours['threads']} threads), all {args.t} columns; runs {ours['times_s']}")
    print(f"SALib 1.6: median {per_column:.3f} s per column over {k} columns -> "
          f"{salib_total:.1f} s for {args.t} columns (extrapolated)")
    print(f"ratio SALib / impactcal: {salib_total / ours['median_s']:.1f}x")
    out_mb = ours["output_bytes"] / 1e6
    peak_mb = (ours["peak_rss_bytes"] or 0) / 1e6
    print(f"impactcal peak RSS {peak_mb:.0f} MB for an output matrix of {out_mb:.0f} MB "
          f"(ratio {peak_mb / out_mb:.2f}; includes generating the design and outputs)")
    print(f"SALib process peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3:.0f} MB "
          f"(holding {k} columns only)")
    print(f"max |impactcal - SALib| over S1, ST{', S2' if args.second_order else ''} "
          f"of {k} columns: {max_diff:.2e}")


if __name__ == "__main__":
    main()
