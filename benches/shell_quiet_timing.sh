#!/bin/bash
# Times the shell solver on 1 and 2 threads, alternately, on a shared machine, and logs
# for every run the CPU seconds that OTHER processes used meanwhile (busy time from
# /proc/stat minus the run's own user + system time), so that only clean runs are quoted.
#
#   benches/shell_quiet_timing.sh [SECONDS] [BINARY]   (default 240 s; the timing example)
#   then: the runs with others_cpu_s below 0.1 are the clean ones.
#
# Build the binary first (benches/harness/shell_timing.rs): cargo build --release --example shell_timing
set -eu
end=$((SECONDS + ${1:-240}))
bin=${2:-${CARGO_TARGET_DIR:-target}/release/examples/shell_timing}
hz=$(getconf CLK_TCK)
busy() { read -r _ a b c _ _ f g h _ < /proc/stat; echo "$((a + b + c + f + g + h))"; }
TIMEFORMAT="%3U %3S %3R"
out=$(mktemp)
while [ $SECONDS -lt $end ]; do
  for t in 1 2; do
    b0=$(busy)
    { time "$bin" "$t" 40 3 > "$out" 2>&1 ; } 2> "$out.time"
    b1=$(busy)
    read -r u s r < "$out.time"
    others=$(awk -v b="$((b1 - b0))" -v hz="$hz" -v u="$u" -v s="$s" 'BEGIN { printf "%.2f", b / hz - u - s }')
    echo "$(date +%T) t=$t others_cpu_s=$others wall_s=$r $(cut -c29- "$out")"
  done
done
rm -f "$out" "$out.time"
