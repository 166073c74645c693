#!/usr/bin/env bash
# Renders a sample report with every kind of figure, a real closed-loop report (the
# drop-tower loop of examples/loop_report.rs, about 15 s) and the airframe demo's figures
# drawn on the structure (examples/airframe_report.rs: the 41 placed sensors, an impact
# shape, the reveal) in headless Chromium and checks
# that each page is not blank, shows every figure and has no two text labels of a figure
# overlapping (tests/browser/check_report.py), then that the check rejects deliberately
# broken copies of the sample page. Installs Chromium (Debian package
# `chromium`) with apt-get when it is missing and this user can.
#
#   bash tests/browser/check_report.sh [OUT_DIR]
#
# Exit status: 0 when every figure of both reports is shown without overlapping labels and
# every broken page is rejected; 1 otherwise.
set -euo pipefail
cd "$(dirname "$0")/../.."

find_chromium() {
    for c in chromium chromium-browser google-chrome-stable google-chrome; do
        if command -v "$c" >/dev/null 2>&1; then
            command -v "$c"
            return 0
        fi
    done
    return 1
}

if ! CHROMIUM=$(find_chromium); then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "chromium not found: installing the Debian package"
        start=$(date +%s)
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq
        apt-get install -y -qq chromium >/dev/null
        echo "chromium installed in $(( $(date +%s) - start )) s"
        CHROMIUM=$(find_chromium)
    else
        echo "check_report: chromium is not installed and cannot be installed here (needs root and apt-get)" >&2
        exit 1
    fi
fi
"$CHROMIUM" --version 2>/dev/null || true

if [ $# -ge 1 ]; then
    OUT="$1"
    mkdir -p "$OUT"
else
    OUT=$(mktemp -d -t impactcal-report-XXXXXX)
    trap 'rm -rf "$OUT"' EXIT
fi

# The example as `cargo test --workspace` builds it (examples too): after it, as in CI, this
# is a no-op, where `cargo run --example` would unify features differently and build the
# workspace's crates again.
cargo test --workspace --no-run --quiet
"${CARGO_TARGET_DIR:-target}/debug/examples/report_gallery" "$OUT/report" >/dev/null
python3 tests/browser/check_report.py --chromium "$CHROMIUM" --report "$OUT/report" --negative-controls
"${CARGO_TARGET_DIR:-target}/debug/examples/loop_report" "$OUT/loop" >/dev/null
python3 tests/browser/check_report.py --chromium "$CHROMIUM" --report "$OUT/loop"
"${CARGO_TARGET_DIR:-target}/debug/examples/airframe_report" "$OUT/airframe" >/dev/null
python3 tests/browser/check_report.py --chromium "$CHROMIUM" --report "$OUT/airframe"
