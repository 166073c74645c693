#!/usr/bin/env bash
# Sobol' indices of the car pole study's outputs (dmax, fmax, vfin, IE): from LS-DYNA's 330
# runs of the public study dbrizard/GSA-car-crash@477fb05 (GPL-3: read where they are kept,
# never copied into the project) and from our solver's runs of the same designs, each by an
# ERBF surrogate of the runs and `impactcal sobol` on a Saltelli design of it; SALib 1.6 on
# the same surrogate samples and the study's published PCE indices as peers. See
# car_pole_sobol.py for what each table is.
#
#   benches/peers/car_pole_sobol.sh lsdyna             # step 1: LS-DYNA's 330 runs
#   benches/peers/car_pole_sobol.sh stability          # design size: LS-DYNA's subsets
#   benches/peers/car_pole_sobol.sh ours RESULTS.csv   # our runs (car_pole_crosscode.sh)
#
# Data: CAR_POLE_DATA (default /work/shared/data/car_pole); absent data is a note, not a
# failure. Builds the release CLI; SALib goes into benches/peers/.venv.
set -euo pipefail
cd "$(dirname "$0")/../.."
data=${CAR_POLE_DATA:-/work/shared/data/car_pole}
export CAR_POLE_DATA=$data
if [ ! -f "$data/p9_X.csv" ]; then
    echo "note: $data/p9_X.csv is absent: no car pole data to analyse"
    exit 0
fi
VENV=benches/peers/.venv
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/pip" install --quiet SALib==1.6.0 numpy==2.4.6 scipy==1.17.1
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}"
cargo build --quiet --release -p impactcal-cli
export IMPACTCAL="$CARGO_TARGET_DIR/release/impactcal"
"$VENV/bin/python" benches/peers/car_pole_sobol.py selftest
"$VENV/bin/python" benches/peers/car_pole_sobol.py "${@:-lsdyna}"
