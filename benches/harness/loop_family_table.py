#!/usr/bin/env python3
"""The family's records (one JSON line per case, benches/harness/loop_family.sh) as the
markdown table of docs/validation.md, "The closed loop over a family of hidden effects".

    python3 benches/harness/loop_family_table.py RECORDS
"""
import json
import sys


def g(x, f="{:.4g}"):
    return "-" if x is None else f.format(x)


def row(r):
    if r.get("failed"):
        return f"| {r['kind']} {r['level']} | {r['seed']} | failed | | | | | | | | |"
    h = r.get("hidden") or {}
    first = r.get("first") or {}
    added = r.get("added") or []
    hid = next((a for a in added if a["name"] == h.get("name")), None)
    truth = (f"{h['name']} {g(h['truth'])} (held {g(h['held'])})" if h else "nothing")
    ranked = (f"{first.get('name')} (kappa {g(first.get('kappa'), '{:.2f}')}, "
              f"share {g(first.get('explained'), '{:.2f}')})" if first else "-")
    if hid:
        found = (f"{g(hid['value'], '{:.5g}')} [{g(hid['lower'], '{:.5g}')}, "
                 f"{g(hid['upper'], '{:.5g}')}] {'inside' if r['truth_inside'] else 'outside'}")
    else:
        found = "not added"
    others = [a["name"] for a in added if a is not hid]
    if others:
        found += "; also " + ", ".join(others)
    c, ho = r["calibration"], r.get("holdout") or [None] * 3
    return (f"| {r['kind']} {r['level']} | {r['seed']} | {truth} | {ranked} (rank "
            f"{g(r.get('hidden_rank'), '{}')}) | {found} | {r['verdict']} | "
            f"{g(r['gain'], '{:.4f}')} ({g(r['other_gains_max_dev'], '{:.1e}')}) | "
            f"{(r['tau'] - r['tau_true']) / r['dt']:+.3f} | "
            f"{c[0]:.3f} -> {c[1]:.3f} -> {c[2]:.3f} | "
            f"{g(ho[0], '{:.3f}')} -> {g(ho[1], '{:.3f}')} -> {g(ho[2], '{:.3f}')} | "
            f"{g(r['chi2_red'][1], '{:.3f}')} ({g(r['threshold'], '{:.3f}')}) | {r['runs']} |")


print("| case | seed | hidden | ranked first | added (truth inside its 95 % interval?) "
      "| verdict | gain (1.12) (other gains' largest deviation) | tau error (samples) "
      "| calibration nominal -> calibrated -> enriched | holdout | chi2_red final (threshold) "
      "| runs |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for line in open(sys.argv[1]):
    print(row(json.loads(line)))
