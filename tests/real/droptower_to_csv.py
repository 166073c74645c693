#!/usr/bin/env python3
"""The AFRL drop-tower data set (one file per accelerometer, one column per test) as one
wide CSV per test, the form `impactcal check` and every other command read:

    python3 tests/real/droptower_to_csv.py SRC_DIR OUT_DIR

SRC_DIR holds accel_1.csv .. accel_6.csv (1-4: the boards, 5: fixture top, 6: fixture
bottom); each has a header line, a units line, then rows `time, test1 .. test5` in units of
1,000 g. OUT_DIR receives test1.csv .. test5.csv with the header
`time,accel_1,accel_2,accel_3,accel_4,accel_top,accel_bottom`, values unchanged (kg_n).
The source's header names seven columns where its rows hold six; the column count is taken
from the rows. Standard library only."""
import csv
import os
import sys

LABELS = ["accel_1", "accel_2", "accel_3", "accel_4", "accel_top", "accel_bottom"]


def main(src, out):
    os.makedirs(out, exist_ok=True)
    columns, time = [], None
    for k in range(1, 7):
        with open(os.path.join(src, f"accel_{k}.csv"), newline="") as f:
            rows = list(csv.reader(f))[2:]
        widths = {len(r) for r in rows}
        if widths != {6}:
            sys.exit(f"accel_{k}.csv: rows of {sorted(widths)} fields, expected 6")
        t = [r[0].strip() for r in rows]
        if time is None:
            time = t
        elif t != time:
            sys.exit(f"accel_{k}.csv: its time column differs from accel_1.csv's")
        columns.append([[r[j].strip() for r in rows] for j in range(1, 6)])
    for test in range(5):
        path = os.path.join(out, f"test{test + 1}.csv")
        with open(path, "w", newline="") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["time"] + LABELS)
            for i, t in enumerate(time):
                w.writerow([t] + [columns[s][test][i] for s in range(6)])
        print(path)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
