#!/usr/bin/env bash
# How `impactcal surrogate fit` chooses among its candidates (--auto, --kind auto), on data
# the rule was not designed on: the one-standard-error rule (`--select one-se`) against
# the lowest leave-one-out error (`--select min-loo`, the default),
# both against the better of two yardsticks fitted on the same runs: a linear regression
# and scipy's smoothed cubic RBF with its smoothing chosen by 10-fold cross-validation.
#
# 1. The public car pole-crash study (330 LS-DYNA runs, 9 parameters, 4 outputs; layout as
#    in surrogate_noise.sh), split five ways at random (numpy seeds 0..4): fit 250, hold
#    out 80. Error: held-out RMSE / std of the held-out values.
# 2. Synthetic families with noise of 0, 5 % and 50 % of the function's standard deviation
#    over its box: the smooth sine family of crates/impactcal-erbf/tests/tuning.rs in 3 and
#    9 dimensions, Branin (2), Hartmann-3 and Hartmann-6, on Latin hypercubes of 10 d + 20
#    points (numpy seeds 0..4), 1000 uniform test points. Error: RMSE against the
#    noiseless function / its standard deviation.
#
# Printed: per case the ratio of each method's error to the yardstick, whether it is within
# 5 %, and how often the new rule is worse than the old one (at all, and by more than 5 %).
# RULES="min-loo one-se" (the default) compares those two; the first listed is the old rule,
# the last the new (RULES="min-loo nested" for nested cross-validation).
#
# Usage: benches/peers/surrogate_choice.sh [car-pole-dir] (or IMPACTCAL_CAR_POLE; without
# it only the synthetic families run). SPLITS=5 SEEDS=5 METHODS="auto cubic erbf"
# RULES="min-loo one-se".
set -euo pipefail
cd "$(dirname "$0")/../.."
DATA="${1:-${IMPACTCAL_CAR_POLE:-}}"
VENV=benches/peers/.venv
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
"$VENV/bin/pip" install --quiet numpy==2.4.6 scipy==1.17.1
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}"
if [ -z "${IMPACTCAL_BIN:-}" ]; then
    cargo build --quiet --release -p impactcal-cli
fi
BIN="${IMPACTCAL_BIN:-$CARGO_TARGET_DIR/release/impactcal}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$VENV/bin/python" benches/peers/surrogate_choice.py "$BIN" "$WORK" "$DATA"
