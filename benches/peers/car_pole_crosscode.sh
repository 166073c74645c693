#!/bin/bash
# The car pole model against LS-DYNA over N designs of the study's 330 (dbrizard/
# GSA-car-crash@477fb05, LHS-330; GPL-3: the decks are read where they are kept and the
# derived decks written under WORK, never into the project). For each design chosen by
# `car_pole_crosscode.py select N` (greedy maximin over the inputs, never the outcomes) and
# for the base design (the box centre, which the study ran five times), it writes the
# design's *PARAMETER deck into WORK/<row>/ beside a link to the model, runs
# `impactcal simulate` (release build) on THREADS threads, computes the study's four outputs
# the study's way, keeps them (WORK/results.csv) and the run's log, and deletes the
# histories. A design already in results.csv is not run again, so an interrupted
# measurement resumes. Then the controlled reruns at the base design (`car_pole_crosscode.py
# controls`; CONTROLS=0 skips them, CONTROLS=a,b runs only those), each one change of the model in a copy of the include
# under WORK. At the end it prints the comparison table.
#
#   benches/peers/car_pole_crosscode.sh [N] [WORK] [THREADS]
#
# A design our solver cannot run to the end is listed in WORK/failures.txt with its error
# and left out of the statistics (the table names it). Defaults: 21 (one more than the 20
# compared, in case one fails; the greedy order keeps the first 20 whatever N), /tmp/car_pole_crosscode, 2. Build first: cargo build --release -p
# impactcal-cli. Standard-library Python 3 only. Each run is 30-100 s of CPU.
#
# VARIANT=NAME runs every design on the model with the one change NAME of the controlled
# reruns (e.g. hourglass-viscous: the runs a surrogate of that model needs), its include
# written once under WORK; no controlled reruns then. Keep a separate WORK per variant.
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
n=${1:-21}
work=${2:-/tmp/car_pole_crosscode}
threads=${3:-2}
data=${CAR_POLE_DATA:-/work/shared/data/car_pole}
export CAR_POLE_DATA=$data
bin=$here/target/release/impactcal
py="python3 $here/benches/peers/car_pole_crosscode.py"
if [ ! -f "$data/decks/car6_crash_v223.k" ]; then
    echo "note: $data/decks/car6_crash_v223.k is absent: nothing to compare"
    exit 0
fi
$py selftest
mkdir -p "$work"
results=$work/results.csv
[ -f "$results" ] || $py header > "$results"
failures=$work/failures.txt
touch "$failures"
echo "$(nproc) CPUs: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
# CONTROLS=0: no controlled reruns; CONTROLS=a,b: only those; default: all of them.
controls=
variant=${VARIANT:-}
include=$data/decks/car6_crash_v223.k
if [ -n "$variant" ]; then
    CONTROLS=0
    mkdir -p "$work/variant-$variant"
    $py control "$variant" "$work/variant-$variant"
    include=$work/variant-$variant/car6_crash_v223.k
    echo "every design runs with $variant"
fi
case "${CONTROLS:-1}" in
0) ;;
1) controls=$($py controls) ;;
*) controls=$(echo "$CONTROLS" | tr ',' ' ') ;;
esac
for row in base $($py select "$n") $controls; do
    if grep -q "^$row," "$results" || grep -q "^$row:" "$failures"; then
        continue
    fi
    dir=$work/$row
    mkdir -p "$dir"
    case " $controls " in
    *" $row "*) $py control "$row" "$dir" ;;
    *)
        ln -sf "$include" "$dir/car6_crash_v223.k"
        $py deck "$row" "$dir"
        ;;
    esac
    echo "== design $row, load before: $(cut -d' ' -f1-3 /proc/loadavg)"
    /usr/bin/time -v "$bin" simulate --deck "$dir/main.k" --threads "$threads" \
        --quantity displacement --out "$dir/nodes.csv" \
        --energies "$dir/energies.csv" \
        --wall-forces "$dir/walls.csv" \
        --part-velocities "$dir/part_velocities.csv" \
        2> "$dir/log.txt" < /dev/null || {
        # A run our solver cannot finish is recorded, not compared, and the rest go on.
        msg=$(grep -m1 '^impactcal: error' "$dir/log.txt" || tail -1 "$dir/log.txt")
        echo "$row: $msg" | tee -a "$failures"
        rm -f "$dir"/*.csv
        continue
    }
    grep -E '^impactcal: [0-9]' "$dir/log.txt"
    cycles=$(grep -oE '[0-9]+ cycles to' "$dir/log.txt" | cut -d' ' -f1)
    wall=$(grep -E 'Elapsed \(wall clock\)' "$dir/log.txt" | awk '{print $NF}')
    echo "$row,$($py outputs "$dir"),$cycles,$wall" >> "$results"
    rm -f "$dir"/*.csv
    [ -L "$dir/car6_crash_v223.k" ] || rm -f "$dir/car6_crash_v223.k"
done
echo
$py compare "$results" "$failures"
