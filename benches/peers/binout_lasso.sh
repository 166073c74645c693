#!/usr/bin/env bash
# Peer check of the binout (LSDA) reader: lasso-python's `lasso.dyna.Binout` reads every
# branch and state variable of LS-DYNA's binout files, and benches/harness/binout_peer.rs
# compares its values with impactcal's reading of the same files, branch by branch, and
# prints the largest differences.
#
# Usage: benches/peers/binout_lasso.sh [BINOUT ...]   (from anywhere; default: the three
# binout files of crates/impactcal-runner/tests/data/lsdyna)
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV=benches/peers/.venv-lasso
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
if [ "$#" -eq 0 ]; then
    set -- crates/impactcal-runner/tests/data/lsdyna/binout/*/binout
fi
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet --upgrade pip
fi
"$VENV/bin/pip" install --quiet lasso-python==2.0.4
"$VENV/bin/python" - "$WORK/lasso.json" "$@" <<'PY'
import json, sys
import numpy as np
from lasso.dyna import Binout

out = {}
for path in sys.argv[2:]:
    b = Binout(path)
    branches = {}

    def walk(*p):
        names = b.read(*p)
        try:
            sub = b.read(*p, "time") if p else None
        except Exception:
            sub = None
        if isinstance(sub, np.ndarray) and sub.ndim == 1 and sub.size > 0:
            entry = {"time": sub.tolist()}
            for v in names:
                if v == "time":
                    continue
                a = np.asarray(b.read(*p, v))
                if a.ndim >= 1 and a.shape[0] == sub.size and a.dtype.kind in "iuf":
                    entry[v] = a.reshape(sub.size, -1).tolist()
            branches["/".join(p)] = entry
            return
        for n in names:
            if n != "metadata":
                try:
                    walk(*p, n)
                except Exception:
                    pass

    for top in b.read():
        walk(top)
    out[path] = branches
json.dump(out, open(sys.argv[1], "w"))
import lasso
print(f"lasso-python {getattr(lasso, '__version__', '2.0.4')}: {sum(len(v) for v in out.values())} branches read")
PY
cargo run --quiet --release --example binout_peer -- "$WORK/lasso.json"
