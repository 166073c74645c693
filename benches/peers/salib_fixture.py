"""Writes the SALib reference data of crates/impactcal-sobol/tests/salib_agreement.rs.

SALib 1.6 makes a scrambled Saltelli design for Ishigami (d = 3, N = 64, second order),
the outputs of two columns are computed here, and SALib's `sobol.analyze` runs on each
column (its way of handling vector outputs). The Rust test analyses the same rows and
outputs and must agree to rounding. A plain (unscrambled) design is stored too, which
impactcal must reproduce row for row.

Usage: benches/peers/.venv/bin/python benches/peers/salib_fixture.py \
    crates/impactcal-sobol/tests/data/salib_ishigami.json
"""

import json
import sys

import numpy as np
from importlib.metadata import version
from SALib.analyze import sobol as sobol_analyze
from SALib.sample import sobol as sobol_sample


def outputs(x: np.ndarray) -> np.ndarray:
    ishigami = np.sin(x[:, 0]) * (1 + 0.1 * x[:, 2] ** 4) + 7 * np.sin(x[:, 1]) ** 2
    # A second column with a large offset and an x1 x3 interaction.
    shifted = 1000.0 + ishigami + x[:, 0] * x[:, 2]
    return np.column_stack([ishigami, shifted])


def main() -> None:
    problem = {"num_vars": 3, "names": ["x1", "x2", "x3"], "bounds": [[-np.pi, np.pi]] * 3}
    x = sobol_sample.sample(problem, 64, calc_second_order=True, scramble=True, seed=7)
    y = outputs(x)
    columns = []
    for t in range(y.shape[1]):
        s = sobol_analyze.analyze(problem, y[:, t], calc_second_order=True, num_resamples=100, seed=1)
        columns.append(
            {
                "S1": s["S1"].tolist(),
                "ST": s["ST"].tolist(),
                "S2": np.nan_to_num(s["S2"], nan=0.0).tolist(),
                "S1_conf": s["S1_conf"].tolist(),
                "ST_conf": s["ST_conf"].tolist(),
            }
        )
    unit = {"num_vars": 3, "names": ["a", "b", "c"], "bounds": [[0.0, 1.0]] * 3}
    plain = sobol_sample.sample(unit, 8, calc_second_order=True, scramble=False)
    json.dump(
        {
            "salib_version": version("SALib"),
            "n": 64,
            "x": x.tolist(),
            "y": y.tolist(),
            "columns": columns,
            "plain_design_n8_d3_second_order": plain.tolist(),
        },
        open(sys.argv[1], "w"),
    )


if __name__ == "__main__":
    main()
