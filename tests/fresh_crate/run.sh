#!/usr/bin/env bash
# A fresh crate that depends on impactcal by path runs a study file and a loop file
# through the library (src/main.rs, a handful of lines): its study.json and loop.json must
# be those of `impactcal study` and `impactcal close-loop` on the same files, byte for byte.
#
#   tests/fresh_crate/run.sh
#
# It builds in the workspace's target directory with the workspace's test profile and the
# workspace's Cargo.lock, so that after `cargo test --workspace` (as in CI) only the fresh
# crate itself and what its features change are compiled.
set -euo pipefail
cd "$(dirname "$0")/../.."
REPO=$(pwd)
TARGET="${CARGO_TARGET_DIR:-$REPO/target}"
W=$(mktemp -d /tmp/impactcal-fresh.XXXXXX)
trap 'rm -rf "$W"' EXIT
# The crate is copied out of the repository, as a user's own crate would live elsewhere.
cp -r tests/fresh_crate "$W/crate"
sed -i "s|path = \"../..\"|path = \"$REPO\"|" "$W/crate/Cargo.toml"
cp Cargo.lock "$W/crate/Cargo.lock"
echo "== building the fresh crate"
start=$(date +%s)
CARGO_TARGET_DIR="$TARGET" cargo build --quiet --offline --profile test \
  --manifest-path "$W/crate/Cargo.toml"
echo "built in $(( $(date +%s) - start )) s"
FRESH="$TARGET/debug/impactcal-fresh-crate"
IMPACTCAL="$TARGET/debug/impactcal"
[ -x "$IMPACTCAL" ] || CARGO_TARGET_DIR="$TARGET" cargo build --quiet -p impactcal-cli --profile test

echo "== the study file and the loop file through the library"
"$FRESH" examples/study/local.toml examples/loop/local.toml "$W/lib" | tee "$W/lib.txt"
grep -qx 'study: can-explain' "$W/lib.txt" || { echo "FAILED: the study's verdict" >&2; exit 1; }
grep -qx 'loop: Attributed' "$W/lib.txt" || { echo "FAILED: the loop's verdict" >&2; exit 1; }
echo "== the same files through the command"
"$IMPACTCAL" study --config examples/study/local.toml --out "$W/cli/study" 2> /dev/null
"$IMPACTCAL" close-loop --config examples/loop/local.toml --out "$W/cli/loop" 2> /dev/null
cmp "$W/lib/study/study.json" "$W/cli/study/study.json" \
  || { echo "FAILED: study.json differs from the command's" >&2; exit 1; }
cmp "$W/lib/loop/loop.json" "$W/cli/loop/loop.json" \
  || { echo "FAILED: loop.json differs from the command's" >&2; exit 1; }
echo "== fresh crate test passed"
