#!/usr/bin/env bash
# Stops the daemons that start.sh started under $1 (by their pid files).
set -uo pipefail
ROOT=$(realpath -m "${1:?usage: stop.sh DIR}")
for pidfile in "$ROOT/run/slurmd.pid" "$ROOT/run/slurmctld.pid" "$ROOT/munge/munged.pid"; do
  if [ -f "$pidfile" ]; then
    pid=$(cat "$pidfile")
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  fi
done
