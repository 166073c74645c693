#!/usr/bin/env bash
# CPU time per adaptive CORS step of two builds of the cors_dixon_szego example, alternated
# seed by seed (for a loaded machine, where wall-clock overheads say nothing):
#
#   benches/peers/cors_overhead_ab.sh OLD_BINARY NEW_BINARY [SEEDS=10] [FUNCTIONS...]
#
# Each single-seed run is timed with `perf stat -e task-clock` and its CPU time divided by its
# adaptive steps (evaluations - 2(d+1)); prints the median per function and the ratio.
set -euo pipefail
old="$1"; new="$2"; seeds="${3:-10}"; shift $(( $# < 3 ? $# : 3 ))
functions=("$@")
[ ${#functions[@]} -eq 0 ] && functions=(branin goldstein-price hartmann3 hartmann6 shekel5 shekel7 shekel10)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for f in "${functions[@]}"; do
    for s in $(seq 0 $((seeds - 1))); do
        for side in old new; do
            bin="$old"; [ "$side" = new ] && bin="$new"
            line=$(perf stat -e task-clock -x, -o "$tmp/stat" "$bin" --seeds 1 --first-seed "$s" \
                --budget 300 --functions "$f")
            cpu=$(grep task-clock "$tmp/stat" | cut -d, -f1)
            echo "$f $side $cpu $line" >> "$tmp/runs"
        done
    done
done
python3 - "$tmp/runs" <<'PY'
import json, statistics, sys
from collections import defaultdict
dims = {"branin": 2, "goldstein-price": 2, "hartmann3": 3, "hartmann6": 6,
        "shekel5": 4, "shekel7": 4, "shekel10": 4}
per_step = defaultdict(list)
order = []
for line in open(sys.argv[1]):
    f, side, cpu, record = line.split(" ", 3)
    steps = json.loads(record)["evaluations"] - 2 * (dims[f] + 1)
    if steps > 0:
        per_step[(f, side)].append(float(cpu) / steps)
    if f not in order:
        order.append(f)
print("| function | old (CPU ms per step) | new | new / old |")
print("|---|---|---|---|")
for f in order:
    o, n = statistics.median(per_step[(f, "old")]), statistics.median(per_step[(f, "new")])
    print(f"| {f} | {o:.2f} | {n:.2f} | {n / o:.2f} |")
PY
