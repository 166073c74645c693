#!/usr/bin/env bash
# The public LS-DYNA decks of docs/shell-solver.md ("Public decks"), read and run with two
# `impactcal` binaries: before and after a change. For each deck it prints a Markdown row:
# the deck, its repository and path, and what each binary does with it (runs: the first
# cycles of the run complete; refused: the first line of the error, exit code 2).
#
#   benches/harness/public_decks.sh BEFORE_BINARY AFTER_BINARY GSA_DIR PYDYNA_DIR
#
# GSA_DIR is a checkout of github.com/dbrizard/GSA-car-crash at commit 477fb05 (GPL-3.0:
# read there, never copied into this repository); PYDYNA_DIR holds the files of
# github.com/ansys/pydyna listed below at their commits (MIT), under their paths. The after
# binary runs each deck for 20 cycles (`simulate --end-cycles 20`); the before binary has
# no such option, so a deck it would run is stopped after 120 s and reported as running.
set -u
before=$1
after=$2
gsa=$3
pydyna=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# label|directory|main file|source
decks="car5 (LS-OPT)|$gsa|lsopt_car5/car5.k|dbrizard/GSA-car-crash@477fb05 lsopt_car5/car5.k
car6 (LS-OPT)|$gsa|lsopt_car6/car6_crash.k|dbrizard/GSA-car-crash@477fb05 lsopt_car6/car6_crash.k
car6 refined, base design|$gsa|lsopt_car6_v3/main_v223.k|dbrizard/GSA-car-crash@477fb05 lsopt_car6_v3/main_v223.k (+ car6_crash_v223.k)
car6 refined, *PARAMETER|$gsa|lsopt_car6_v3/main_v223_param.k|dbrizard/GSA-car-crash@477fb05 lsopt_car6_v3/main_v223_param.k (+ car6_crash_v223.k)
ball on plate (pydyna example)|$pydyna|examples/Explicit/output/ball_plate.k|ansys/pydyna@45e0b004 examples/Explicit/output/ball_plate.k
sheet forming (pydyna example)|$pydyna|examples/Metalforming/output/model.k|ansys/pydyna@7dce3c04 examples/Metalforming/output/model.k
airbag, mechanics (pydyna test)|$pydyna|tests/testfiles/standard/mech.k|ansys/pydyna@7dce3c04 tests/testfiles/standard/mech.k
Workbench deck (pydyna test)|$pydyna|tests/testfiles/keywords/test_node_sets.k|ansys/pydyna@5f75f6c3 tests/testfiles/keywords/test_node_sets.k"

# An error line for the table: a list of unsupported keywords as their distinct names with
# their count, anything else as it is (cut at 300 characters).
condense() {
    python3 -c '
import re, sys
line = sys.stdin.read().strip()
m = re.match(r"^(.*?): (\d+) unsupported keywords: (.*)$", line)
if m:
    names = []
    for k in re.findall(r"(\*[A-Z0-9_]+) \(", m.group(3)):
        if k not in names:
            names.append(k)
    line = f"{m.group(2)} unsupported keywords: " + ", ".join(f"`{k}`" for k in names)
print(line[:300].replace("|", "\\|"))
'
}

# The outcome of one binary on one deck, as table text.
outcome() {
    local bin=$1 deck=$2 extra=$3 limit=$4
    local err="$work/err"
    timeout "$limit" "$bin" simulate --deck "$deck" $extra > /dev/null 2> "$err"
    local rc=$?
    case $rc in
        0) echo "runs" ;;
        124) echo "runs (stopped after ${limit} s)" ;;
        2) echo "refused: $(grep -v '^impactcal: warning' "$err" | head -1 | sed -e 's/^impactcal: error: //' -e "s|$(dirname "$deck")/||g" | condense)" ;;
        *) echo "fails (exit $rc): $(grep -v '^impactcal: warning' "$err" | head -1 | sed -e 's/^impactcal: //' -e 's/|/\\|/g' | cut -c1-300)" ;;
    esac
}

# A copy of the deck's folder (its .k files) with every *CONTACT keyword removed: what the
# deck holds besides segment contact, which a later issue adds.
without_contact() {
    local dir; dir=$(dirname "$1")
    rm -rf "$work/nc"; mkdir -p "$work/nc"
    for f in "$dir"/*.k; do
        awk 'BEGIN{skip=0} /^\*/{skip=(toupper($0) ~ /^\*CONTACT/)} !skip' "$f" > "$work/nc/$(basename "$f")"
    done
    echo "$work/nc/$(basename "$1")"
}

echo "| Deck | Source | Before | After | After, its *CONTACT keywords removed |"
echo "|---|---|---|---|---|"
while IFS='|' read -r label dir main source; do
    deck="$dir/$main"
    if [ ! -f "$deck" ]; then
        echo "| $label | $source | (file absent) | (file absent) | |"
        continue
    fi
    b=$(outcome "$before" "$deck" "" 120)
    a=$(outcome "$after" "$deck" "--end-cycles 20" 600)
    nc=$(outcome "$after" "$(without_contact "$deck")" "--end-cycles 20" 600)
    echo "| $label | $source | $b | $a | $nc |"
done <<< "$decks"
