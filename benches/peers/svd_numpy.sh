#!/usr/bin/env bash
# Times numpy.linalg.svd(full_matrices=False) against impactcal's thin SVD and its top-20
# randomized solver on the same matrices, in the same run, and prints the ratios.
# Usage: benches/peers/svd_numpy.sh [REPEATS]   (run from anywhere)
# Our side is benches/harness/svd_timing.rs, built as the `svd_timing` example target.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$here/../.."
repeats="${1:-3}"
venv="$here/.venv"
out="$here/out/svd"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q --upgrade pip
fi
"$venv/bin/pip" install -q numpy==2.4.6
mkdir -p "$out"
echo "== impactcal (faer) side"
(cd "$root" && cargo run -q --release --example svd_timing -- "$out" "$repeats") | tee "$out/ours.jsonl"
echo "== numpy side"
"$venv/bin/python" - "$out/ours.jsonl" "$repeats" <<'PY'
import json, sys, time
import numpy as np
ours = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
repeats = int(sys.argv[2])
print(f"numpy {np.__version__}")
np.show_config() if False else None
print(f"{'matrix':>12} {'numpy full':>11} {'ours full':>10} {'ratio':>6} {'ours top20':>11} {'speedup':>8}")
for r in ours:
    m, n = r["m"], r["n"]
    y = np.fromfile(r["file"], dtype="<f8").reshape((m, n), order="F")
    y = np.ascontiguousarray(y)
    reps = 1 if m * n > 10_000_000 else repeats
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        np.linalg.svd(y, full_matrices=False)
        ts.append(time.perf_counter() - t)
    t_np = sorted(ts)[len(ts) // 2]
    print(f"{m:>6}x{n:<5} {t_np:>10.3f}s {r['full_s']:>9.3f}s {r['full_s']/t_np:>6.2f} "
          f"{r['top20_s']:>10.4f}s {t_np/r['top20_s']:>7.1f}x")
print("ratio = ours full / numpy full (target <= 1.0); speedup = numpy full / ours top-20 (target >= 5)")
PY
