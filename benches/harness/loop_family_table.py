#!/usr/bin/env python3
"""The family's records (one JSON line per case, benches/harness/loop_family.sh) as the
markdown table of docs/validation.md, "The closed loop over a family of hidden effects".

    python3 benches/harness/loop_family_table.py RECORDS [RECORDS...]
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
records = [json.loads(line) for path in sys.argv[1:] for line in open(path)]
for r in records:
    print(row(r))


def share(hits, cases):
    return f"{sum(hits)}/{len(hits)} of {cases}" if hits else f"0/0 of {cases}"


# The targets over the finished cases (a failed case counts against every target).
hidden = [r for r in records if r.get("failed") or r.get("hidden")]
control = [r for r in records if not r.get("failed") and not r.get("hidden")]
ok = [r for r in hidden if not r.get("failed")]
found = [r.get("hidden_rank") == 1 and r.get("truth_inside") is not None for r in hidden]
inside = [bool(r["truth_inside"]) for r in ok if r.get("truth_inside") is not None]
nuisance = [abs(r["gain"] / r["gain_true"] - 1) <= 0.03
            and abs(r["tau"] - r["tau_true"]) <= 0.2 * r["dt"] for r in ok + control]
cut = [r["calibration"][2] <= 0.7 * r["calibration"][0]
       and (r.get("holdout") is None or r["holdout"][2] < r["holdout"][0]) for r in ok]
print()
print(f"ranked first and added: {share(found, 'cases with a hidden effect')}; "
      f"truth inside its 95 % interval: {share(inside, 'cases where it was added')}; "
      f"gain within 3 % and trigger within a fifth of a sample: {share(nuisance, 'cases')}; "
      f"calibration error cut by 30 % and the holdout's lowered: {share(cut, 'cases')}; "
      f"attributed: {share([r['verdict'] == 'attributed' for r in ok], 'cases')}; "
      f"control silent: {share([r['verdict'] == 'no-model-form-error' for r in control], 'seeds')}")
