#!/usr/bin/env python3
"""Our car pole model calibrated to LS-DYNA's four outputs at one design, as if they were a
test, and the check of that calibration at the design and at five designs held out.

Standard library only; drives the impactcal CLI (release build) like car_pole_sobol.py, and
runs our solver the way car_pole_crosscode.sh does. Subcommands (WORK keeps every file, a
finished run is never run again):

  calibrate RESULTS WORK [TARGET]
      The surrogate: an ERBF fit (`surrogate fit --kind erbf --auto`) of our solver's four
      outputs over the designs in RESULTS (car_pole_crosscode.sh's results.csv). The test:
      LS-DYNA's outputs at TARGET (default `base`, the box centre, the mean of LS-DYNA's five
      repeats; or a row of p9_X.csv). The misfit: J(p) = mean over the four outputs of
      ((s_k(p) - y_k) / sigma_k)^2, sigma_k the standard deviation of LS-DYNA's output k
      over the study's 330 runs (the spread the nine parameters make, which puts the four
      on one scale without looking at the target). CORS-RBF (`optimize suggest`, batches of
      4, 200 evaluations of the surrogate, seed 0) minimises it over the study's box;
      `optimize answer` gives the calibrated point. Writes WORK/calibration.json.
  verify WORK RESULTS [THREADS [CONTROL]]
      Runs our solver at the calibrated point of TARGET and at five held-out designs with
      the calibration carried over (each parameter scaled by its calibrated factor
      p*_i / p0_i); the held-out designs are the first five of RESULTS' maximin order
      that are not the target (chosen from the inputs only). Writes WORK/verify.csv.
  effect WORK RESULTS CONTROL [THREADS]
      The candidate effect CONTROL (a controlled rerun of car_pole_crosscode.py, e.g.
      hourglass-viscous) added to the model, the nine parameters at each design's own
      values: runs at the target and the held-out designs, WORK/effect-CONTROL.csv.
  recalibrate WORK RESULTS CONTROL
      The nine parameters calibrated again with CONTROL added: its effect (the mean shift
      of our outputs over the `effect` runs) added to the surrogate; then
      `verify WORK RESULTS THREADS CONTROL` runs the model with CONTROL at the new point
      and carries it to the held-out designs (WORK/verify-CONTROL.csv).
  report WORK RESULTS
      Errors before (our solver at the design as given, from RESULTS) and after (at the
      calibrated or carried-over point) against LS-DYNA, per output and design; and the
      residual the nine parameters leave at the target, set against the candidate effects
      the controlled reruns at the base design measured (RESULTS' control rows): the share
      of the residual (in sigma units) each one's direction explains.
  selftest
"""
import csv
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from car_pole_crosscode import (  # noqa: E402
    BASE_REPEATS, CONTROLS, DATA, NAMES, OUTPUTS, control_include, outputs,
    parameter_deck, read_x, read_y)
from car_pole_sobol import BIN, run, write_inputs  # noqa: E402

BASE = [3.0, 2.0, 5.0, 1.0, 1.0, 400.0, 400.0, 400.0, 400.0]
BUDGET = 200
BATCH = 4
HELD_OUT = 5


def sigma():
    y = read_y()
    out = {}
    for k in OUTPUTS:
        m = sum(y[k]) / len(y[k])
        out[k] = math.sqrt(sum((v - m) ** 2 for v in y[k]) / (len(y[k]) - 1))
    return out


def lsdyna_at(target):
    if target == "base":
        return {k: sum(v) / len(v) for k, v in BASE_REPEATS.items()}
    y = read_y()
    return {k: y[k][int(target)] for k in OUTPUTS}


def design_of(target):
    return BASE if target == "base" else read_x()[int(target)]


def design_rows(results):
    with open(results) as f:
        return [r for r in csv.DictReader(f) if r["row"].isdigit()]


def misfit(s, y, sig):
    return sum(((s[k] - y[k]) / sig[k]) ** 2 for k in OUTPUTS) / len(OUTPUTS)


def predict(work, points, shift=None):
    path = os.path.join(work, "query.csv")
    with open(path, "w") as f:
        f.write(",".join(NAMES) + "\n")
        for p in points:
            f.write(",".join(repr(v) for v in p) + "\n")
    out = os.path.join(work, "query_out.csv")
    run(["surrogate", "predict", "--model", os.path.join(work, "model.json"), "--params",
         path, "--out", out])
    with open(out) as f:
        return [{k: float(r[k]) + (shift[k] if shift else 0.0) for k in OUTPUTS}
                for r in csv.DictReader(f)]


def calibrate(results, work, target="base", shift=None, tag=""):
    """See the module docs; with `shift` (output -> value) the surrogate's outputs are
    moved by it (a candidate effect added to the model), and the files carry `tag`."""
    os.makedirs(work, exist_ok=True)
    shift = shift or {k: 0.0 for k in OUTPUTS}
    rows = design_rows(results)
    x_all = read_x()
    x = [x_all[int(r["row"])] for r in rows]
    write_inputs(work, x, {k: [float(r[k]) for r in rows] for k in OUTPUTS})
    p = lambda name: os.path.join(work, name)
    log = run(["surrogate", "fit", "--bounds", p("bounds.csv"), "--params", p("params.csv"),
               "--outputs", p("outputs.csv"), "--kind", "erbf", "--auto", "--out",
               p("model.json")])
    y, sig = lsdyna_at(target), sigma()
    hist = p(f"history{tag}.csv")
    if os.path.exists(hist):
        os.remove(hist)
    with open(hist, "w") as f:
        f.write(",".join(NAMES) + ",objective\n")
    n = 0
    while n < BUDGET:
        run(["optimize", "suggest", "--bounds", p("bounds.csv"), "--history", hist,
             "--batch", str(BATCH), "--seed", "0", "--out", p("suggest.csv")])
        with open(p("suggest.csv")) as f:
            pts = [[float(r[k]) for k in NAMES] for r in csv.DictReader(f)]
        with open(hist, "a") as f:
            for q, s in zip(pts, predict(work, pts, shift)):
                f.write(",".join(repr(v) for v in q) + f",{misfit(s, y, sig)!r}\n")
        n += len(pts)
    run(["optimize", "answer", "--bounds", p("bounds.csv"), "--history", hist, "--out",
         p(f"answer{tag}.json")])
    with open(p(f"answer{tag}.json")) as f:
        ans = json.load(f)
    # The objective is the surrogate's, without noise: the best sample is the answer.
    if "best_sample" not in ans:
        raise SystemExit(f"{p('answer.json')}: no best_sample in {list(ans)}")
    cal = [float(ans["best_sample"]["parameters"][k]) for k in NAMES]
    s0, s1 = predict(work, [design_of(target), cal], shift)
    out = {"target": target, "runs": len(rows), "evaluations": n, "lsdyna": y,
           "sigma": sig, "calibrated": dict(zip(NAMES, cal)),
           "surrogate_at_design": s0, "surrogate_at_calibrated": s1,
           "misfit_at_design": misfit(s0, y, sig), "misfit_at_calibrated": misfit(s1, y, sig),
           "shift": shift, "fit_log": log}
    with open(p(f"calibration{tag}.json"), "w") as f:
        json.dump(out, f, indent=1)
    print(log.strip())
    print(f"target {target}: LS-DYNA " + ", ".join(f"{k} {y[k]:.4g}" for k in OUTPUTS))
    print("calibrated: " + ", ".join(f"{k} {v:.4g}" for k, v in zip(NAMES, cal)))
    for name, s in (("surrogate at the design", s0), ("surrogate at the calibrated", s1)):
        print(f"{name}: " + ", ".join(
            f"{k} {s[k]:.4g} ({(s[k] - y[k]) / sig[k]:+.2f} sigma)" for k in OUTPUTS)
            + f"; J {misfit(s, y, sig):.3f}")


def held_out(results, target):
    return [r["row"] for r in design_rows(results) if r["row"] != target][:HELD_OUT]


def simulate(deck_values, run_dir, threads, control=None):
    """Our four outputs (and HE) of the model at `deck_values`, with the include as the
    study gives it or, with `control`, changed as that controlled rerun changes it."""
    os.makedirs(run_dir, exist_ok=True)
    link = os.path.join(run_dir, "car6_crash_v223.k")
    if control is None:
        if not os.path.lexists(link):
            os.symlink(os.path.join(DATA, "decks", "car6_crash_v223.k"), link)
    else:
        with open(os.path.join(DATA, "decks", "car6_crash_v223.k")) as f:
            text = control_include(control, f.read())
        with open(link, "w") as f:
            f.write(text)
    with open(os.path.join(run_dir, "main.k"), "w") as f:
        f.write(parameter_deck(deck_values, "car6_crash_v223.k"))
    d = lambda name: os.path.join(run_dir, name)
    with open(d("log.txt"), "w") as log:
        r = subprocess.run([BIN, "simulate", "--deck", d("main.k"), "--threads", str(threads),
                            "--quantity", "displacement", "--out", d("nodes.csv"),
                            "--energies", d("energies.csv"), "--wall-forces", d("walls.csv"),
                            "--part-velocities", d("part_velocities.csv")],
                           stderr=log, stdin=subprocess.DEVNULL)
    if r.returncode != 0:
        raise SystemExit(f"{run_dir}: our solver failed (see log.txt)")
    o = outputs(run_dir)
    for name in ("nodes.csv", "energies.csv", "walls.csv", "part_velocities.csv"):
        os.remove(d(name))
    if control is not None:
        os.remove(link)
    return o


def designs_done(path, header):
    """The designs a resumable results file already holds; a new file gets `header`."""
    if not os.path.exists(path):
        with open(path, "w") as f:
            f.write(",".join(header) + "\n")
        return set()
    with open(path) as f:
        return {r["design"] for r in csv.DictReader(f)}


def verify(work, results, threads=1, control=None):
    tag = f"-{control}" if control else ""
    with open(os.path.join(work, f"calibration{tag}.json")) as f:
        cal = json.load(f)
    target = cal["target"]
    factor = [cal["calibrated"][k] / v for k, v in zip(NAMES, design_of(target))]
    path = os.path.join(work, f"verify{tag}.csv")
    done = designs_done(path, ["design"] + NAMES + OUTPUTS + ["HE"])
    for design in [target] + held_out(results, target):
        if design in done:
            continue
        values = [v * a for v, a in zip(design_of(design), factor)]
        print(f"== {design}: " + ", ".join(f"{k} {v:.4g}" for k, v in zip(NAMES, values)),
              flush=True)
        o = simulate(values, os.path.join(work, f"run{tag}-cal-{design}" if tag else
                                          f"run-{design}"), threads, control)
        with open(path, "a") as f:
            f.write(f"{design}," + ",".join(repr(v) for v in values) + ","
                    + ",".join(repr(o[k]) for k in OUTPUTS + ["HE"]) + "\n")


def effect(work, results, control, threads=1):
    """The candidate effect `control` added to the model as it stands (the nine parameters
    at each design's own values, no recalibration), at the target and the held-out
    designs: WORK/effect-<control>.csv."""
    with open(os.path.join(work, "calibration.json")) as f:
        target = json.load(f)["target"]
    path = os.path.join(work, f"effect-{control}.csv")
    done = designs_done(path, ["design"] + OUTPUTS + ["HE"])
    for design in [target] + held_out(results, target):
        if design in done:
            continue
        print(f"== {design} with {control}", flush=True)
        o = simulate(design_of(design), os.path.join(work, f"run-{control}-{design}"),
                     threads, control)
        with open(path, "a") as f:
            f.write(f"{design}," + ",".join(repr(o[k]) for k in OUTPUTS + ["HE"]) + "\n")


def recalibrate(work, results, control):
    """The loop's recalibration: the nine parameters calibrated again with the candidate
    `control` added, its effect taken as the mean shift of our outputs over the runs of
    `effect` (ours with it minus ours without, at the target and the held-out designs),
    added to the surrogate of the model without it. Writes WORK/calibration-CONTROL.json."""
    with open(results) as f:
        before = {r["row"]: r for r in csv.DictReader(f)}
    with open(os.path.join(work, f"effect-{control}.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["design"] in before]
    if not rows:
        raise SystemExit(f"{work}/effect-{control}.csv: no run to take the effect from")
    shift = {k: sum(float(r[k]) - float(before[r["design"]][k]) for r in rows) / len(rows)
             for k in OUTPUTS}
    print(f"{control}: mean shift over {len(rows)} designs: "
          + ", ".join(f"{k} {v:+.4g}" for k, v in shift.items()))
    with open(os.path.join(work, "calibration.json")) as f:
        target = json.load(f)["target"]
    calibrate(results, work, target, shift, f"-{control}")


def report(work, results):
    with open(os.path.join(work, "calibration.json")) as f:
        cal = json.load(f)
    target, sig = cal["target"], cal["sigma"]
    with open(results) as f:
        before = {r["row"]: r for r in csv.DictReader(f)}
    with open(os.path.join(work, "verify.csv")) as f:
        after = {r["design"]: r for r in csv.DictReader(f)}
    print(f"Calibrated to LS-DYNA at design {target} ({cal['runs']} runs of ours behind the "
          f"surrogate, {cal['evaluations']} CORS evaluations of it): factors "
          + ", ".join(f"{k} {cal['calibrated'][k] / v:.3f}"
                      for k, v in zip(NAMES, design_of(target))))
    print()
    print("| design | " + " | ".join(f"{k} before | {k} after" for k in OUTPUTS)
          + " | J before | J after |")
    print("|---|" + "---|" * (2 * len(OUTPUTS) + 2))
    for design in [target] + held_out(results, target):
        if design not in after or design not in before:
            print(f"| {design} | not run |")
            continue
        y = lsdyna_at(design)
        b = {k: float(before[design][k]) for k in OUTPUTS}
        a = {k: float(after[design][k]) for k in OUTPUTS}
        cells = [f"{100 * (b[k] / y[k] - 1):+.1f} % | {100 * (a[k] / y[k] - 1):+.1f} %"
                 for k in OUTPUTS]
        label = f"{design} (target)" if design == target else f"{design} (held out)"
        print(f"| {label} | " + " | ".join(cells)
              + f" | {misfit(b, y, sig):.3f} | {misfit(a, y, sig):.3f} |")
    loop_table(work, target, sig, before, after, results)
    if target != "base" or target not in after:
        return
    # The residual at the target, in sigma units, against each candidate's direction
    # measured at the base design (control run minus base run, in sigma units).
    y = lsdyna_at(target)
    r = [(y[k] - float(after[target][k])) / sig[k] for k in OUTPUTS]
    base = before["base"]
    print()
    print("Residual at the target after calibration (LS-DYNA - ours, sigma): "
          + ", ".join(f"{k} {v:+.2f}" for k, v in zip(OUTPUTS, r)))
    print()
    print("| candidate (control at the base design) | direction (sigma): "
          + ", ".join(OUTPUTS) + " | amplitude (least squares) | explained | reach | "
          "amplitude within reach | explained within reach |")
    print("|---|---|---|---|---|---|---|")
    rr = sum(v * v for v in r)
    best = None
    for name in CONTROLS:
        if name not in before:
            continue
        d = [(float(before[name][k]) - float(base[k])) / sig[k] for k in OUTPUTS]
        dd = sum(v * v for v in d)
        amp = sum(a * b for a, b in zip(d, r)) / dd if dd else 0.0
        lo, hi = REACH.get(name, (0.0, 0.0))
        held = min(max(amp, lo), hi)
        share = lambda a: 1 - sum((x - a * y) ** 2 for x, y in zip(r, d)) / rr
        print(f"| {name} | " + ", ".join(f"{v:+.2f}" for v in d) + f" | {amp:+.2f} | "
              f"{100 * share(amp):.0f} % | {lo:g} to {hi:g} | {held:+.2f} | "
              f"{100 * share(held):.0f} % |")
        if best is None or share(held) > best[1]:
            best = (name, share(held))
    if best:
        print()
        print(f"Largest share within reach: {best[0]} ({100 * best[1]:.0f} %)")


def loop_table(work, target, sig, before, after, results):
    """The errors at the target and the held-out designs at each stage: as given, the nine
    calibrated, each candidate added as is, and added with the nine recalibrated."""
    stages = [("as given", before, "row"), ("nine calibrated", after, "design")]
    for name in sorted(os.listdir(work)):
        if name.startswith("effect-") and name.endswith(".csv"):
            control = name[len("effect-"):-len(".csv")]
            for label, path in ((f"{control} added", name),
                                (f"{control} added, nine recalibrated",
                                 f"verify-{control}.csv")):
                if os.path.exists(os.path.join(work, path)):
                    with open(os.path.join(work, path)) as f:
                        stages.append((label, {r["design"]: r for r in csv.DictReader(f)},
                                       "design"))
    print()
    print("The loop's stages: relative error of each output against LS-DYNA, and J")
    print()
    print("| design | stage | " + " | ".join(OUTPUTS) + " | J |")
    print("|---|---|" + "---|" * (len(OUTPUTS) + 1))
    for design in [target] + held_out(results, target):
        y = lsdyna_at(design)
        for label, rows, _ in stages:
            if design not in rows:
                continue
            o = {k: float(rows[design][k]) for k in OUTPUTS}
            name = f"{design} (target)" if design == target else f"{design} (held out)"
            print(f"| {name} | {label} | "
                  + " | ".join(f"{100 * (o[k] / y[k] - 1):+.1f} %" for k in OUTPUTS)
                  + f" | {misfit(o, y, sig):.3f} |")


# How far each controlled change can be carried, in units of the change the control made
# (amplitude 1 = the control itself): the range over which the candidate is physical.
# A switch (a form, the projection) reaches 0 to 1; a coefficient halved (QM 0.02 to 0.01)
# reaches 2 (QM 0); the contact friction 0.2 reaches 3 (FS 0 to 0.6); the contact
# stiffness doubled reaches -0.9 (scale factor 0.1) to 9 (10); SHRF 5/6 reaches 0 to 1.
# The initial velocity of the deck's nodes is the deck's, the same in both codes: no
# candidate between the codes (reach 0).
REACH = {
    "all-nodes-moving": (0.0, 0.0),
    "ground-frictionless": (0.0, 1.0),
    "hourglass-half": (-1.0, 2.0),
    "hourglass-viscous": (0.0, 1.0),
    "warping-projection": (0.0, 1.0),
    "hourglass-membrane-only": (0.0, 10.0 / 9.0),
    "hourglass-out-of-plane-only": (0.0, 10.0 / 9.0),
    "hourglass-sixteenth": (-1.0, 16.0 / 15.0),
    "contact-stiffness-double": (-0.9, 9.0),
    "contact-friction": (0.0, 3.0),
    "shear-factor": (0.0, 1.0),
}


def selftest():
    sig = {k: 1.0 for k in OUTPUTS}
    y = {k: 0.0 for k in OUTPUTS}
    s = {"dmax": 2.0, "fmax": 0.0, "vfin": 0.0, "IE": 0.0}
    assert misfit(s, y, sig) == 1.0
    assert design_of("base") == BASE
    print("selftest: ok")


def main(argv):
    if not argv:
        raise SystemExit(__doc__)
    if argv[0] == "calibrate":
        calibrate(argv[1], argv[2], argv[3] if len(argv) > 3 else "base")
    elif argv[0] == "verify":
        verify(argv[1], argv[2], int(argv[3]) if len(argv) > 3 else 1,
               argv[4] if len(argv) > 4 else None)
    elif argv[0] == "recalibrate":
        recalibrate(argv[1], argv[2], argv[3])
    elif argv[0] == "effect":
        effect(argv[1], argv[2], argv[3], int(argv[4]) if len(argv) > 4 else 1)
    elif argv[0] == "report":
        report(argv[1], argv[2])
    elif argv[0] == "selftest":
        selftest()
    else:
        raise SystemExit(f"unknown subcommand {argv[0]}\n{__doc__}")


if __name__ == "__main__":
    main(sys.argv[1:])
