#!/bin/bash
# Runs the LS-OPT car pole crash deck (GPL-3; read where it is kept, never copied) with the
# built-in shell solver to its end (0.2 s) on each thread count given, and prints what the
# solver reports (cycles, energy ratio, hourglass share, contact energy, wall time) with the
# wall-clock and user CPU time of the process (`/usr/bin/time -v`) and the load average
# before and after, so that a run on a busy machine can be told from a quiet one. The
# histories (global, part and contact energies, contact and wall forces) are left in OUT.
#
#   benches/harness/car_pole.sh [DECK_DIR] [OUT] [THREADS...]
#
# Defaults: /work/shared/data/car_pole/decks, a temporary directory, threads 1 2. Build the
# binary first: cargo build --release -p impactcal-cli.
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
decks=${1:-/work/shared/data/car_pole/decks}
out=${2:-$(mktemp -d)}
shift $(($# < 2 ? $# : 2))
threads=${*:-1 2}
bin=$here/target/release/impactcal
if [ ! -f "$decks/main_v223.k" ]; then
    echo "note: $decks/main_v223.k is absent: the car pole deck is not run"
    exit 0
fi
mkdir -p "$out"
echo "$(nproc) CPUs: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
for deck in main_v223.k main_v223_param.k; do
    for n in $threads; do
        tag=${deck%.k}_t$n
        echo "== $deck on $n thread(s)"
        echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
        /usr/bin/time -v "$bin" simulate --deck "$decks/$deck" --threads "$n" \
            --energies "$out/$tag.energies.csv" \
            --part-energies "$out/$tag.parts.csv" \
            --contact-energies "$out/$tag.contact_energies.csv" \
            --contact-forces "$out/$tag.contact_forces.csv" \
            --wall-forces "$out/$tag.walls.csv" \
            2> "$out/$tag.log" < /dev/null || { cat "$out/$tag.log"; exit 1; }
        echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
        grep -E '^impactcal' "$out/$tag.log"
        grep -E 'Elapsed \(wall clock\)|User time|System time|Maximum resident' "$out/$tag.log"
    done
done
echo "histories in $out"
