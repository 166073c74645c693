#!/usr/bin/env python3
"""Cross-code comparison of the LS-OPT car pole crash model against the study's LS-DYNA runs.

Helper of benches/peers/car_pole_crosscode.sh (standard library only). Subcommands:

  select N                 indices (0-based rows of p9_X.csv) of N designs spread over the
                           box: greedy maximin in the unit cube (see `maximin`)
  deck ROW DIR             write DIR/main.k: the study's *PARAMETER values of row ROW (as
                           the study wrote them) and an *INCLUDE of the model, which the
                           caller links into DIR (the decks are GPL-3: never copied here)
  outputs DIR              the four outputs of our run in DIR, computed as the study did
  compare RESULTS [FAILED] table of ours against LS-DYNA's per output: mean and max relative
                           difference, Pearson and Spearman correlation over the designs
  controls                 names of the controlled reruns at the base design
  control NAME DIR         write DIR/main.k (base design) and DIR/car6_crash_v223.k, the
                           model with the one change NAME (under /tmp, never the project)
  story DIR                the energy story of a run in DIR (its --energies,
                           --part-energies and --part-velocities CSV): global kinetic,
                           internal, hourglass and contact energies and the body's x
                           velocity every 0.01 s, when the hourglass energy peaks and how
                           much of it is given back by the end, per part
  selftest                 checks of the metric code against hand-computed values

The study's outputs (dbrizard/GSA-car-crash@477fb05, LSDYNAmodel.py, CAR6model.getGSAoutput)
and ours:
  dmax  x displacement of node 605 (body, rear centre) at the last nodout sample (0.2 s)
  fmax  largest sampled x force of rigid wall 2 (the pole) over the run
  vfin  x rigid-body velocity (matsum) of part 1 (the body) at the last sample
  IE    global internal energy (glstat, hourglass energy apart) at the last sample
"""
import csv
import math
import os
import sys

DATA = os.environ.get("CAR_POLE_DATA", "/work/shared/data/car_pole")
NAMES = ["tbumper", "trailb", "trailf", "tgrill", "thood",
         "ybumper", "yrailf", "yrailb", "ybody"]
BOUNDS = [(2, 4), (1, 3), (3, 7), (0.5, 1.5), (0.5, 1.5),
          (300, 500), (300, 500), (300, 500), (300, 500)]
OUTPUTS = ["dmax", "fmax", "vfin", "IE"]
# The deck's initial speed (mm/s) of the nodes *INITIAL_VELOCITY_NODE lists.
V0 = 8333.0
# The box centre: the base design of main_v223.k, run five times by the study's author
# (MODIFICATIONS_LOG.md, "base design output 2024-05-03"): the mean of the five repeats.
BASE_REPEATS = {
    "fmax": [772836.8125, 775579.75, 772913.375, 770100.4375, 773196.375],
    "dmax": [-641.872802734375, -643.6537475585938, -642.1265869140625,
             -643.90771484375, -642.2013549804688],
    "vfin": [-710.947021484375, -716.1944580078125, -693.0195922851562,
             -730.5367431640625, -706.6123657226562],
    "IE": [1.20394832e8, 1.2032208e8, 1.20379344e8, 1.2035144e8, 1.20424064e8],
}


def read_column(path):
    with open(path) as f:
        return [float(line) for line in f if line.strip()]


def read_x():
    with open(os.path.join(DATA, "p9_X.csv")) as f:
        return [[float(v) for v in line.split(",")] for line in f if line.strip()]


def read_y():
    return {k: read_column(os.path.join(DATA, f"p9_Y_{k}.csv")) for k in OUTPUTS}


def unit(x):
    return [(v - lo) / (hi - lo) for v, (lo, hi) in zip(x, BOUNDS)]


def maximin(points, n):
    """Greedy maximin subset: start from the point nearest the box centre, then add the
    point farthest (Euclidean, unit cube) from those chosen, until n. Uses inputs only."""
    if n > len(points):
        raise SystemExit(f"select: {n} designs asked, {len(points)} available")
    centre = [0.5] * len(points[0])
    d2 = lambda a, b: sum((p - q) ** 2 for p, q in zip(a, b))
    chosen = [min(range(len(points)), key=lambda i: d2(points[i], centre))]
    near = [d2(p, points[chosen[0]]) for p in points]
    while len(chosen) < n:
        i = max(range(len(points)), key=lambda j: (near[j], -j))
        chosen.append(i)
        near = [min(a, d2(p, points[i])) for a, p in zip(near, points)]
    return chosen


def parameter_deck(values, include):
    """The main deck the study's script wrote (free format, `%g`, four per line)."""
    pairs = [f"r{n},{v:g}" for n, v in zip(NAMES, values)]
    lines = ["*KEYWORD", "*PARAMETER"]
    lines += [",".join(pairs[i:i + 4]) for i in range(0, len(pairs), 4)]
    # Every output of our solver is sampled at the *DATABASE_NODOUT interval; 1e-5 s is
    # the study's rwforc and glstat interval, so that the peak force is taken as often.
    lines += ["*INCLUDE", include, "*DATABASE_NODOUT", "1.0e-5", "*END"]
    return "\n".join(lines) + "\n"


# Controlled reruns at the base design: each changes one thing of the model (in a copy of
# the include written beside the derived deck, never in the project).
CONTROLS = {
    "all-nodes-moving": "every node starts at the deck's -8333 mm/s (the deck's "
                        "*INITIAL_VELOCITY_NODE covers nodes 1-758 only)",
    "ground-frictionless": "the ground wall's FRIC 0.2 set to 0",
    "hourglass-half": "every *HOURGLASS QM 0.02 set to 0.01",
    "hourglass-viscous": "every *HOURGLASS IHQ 4 (stiffness form) set to 1 (viscous form), "
                         "QM kept",
    "warping-projection": "*CONTROL_SHELL BWC 1, PROJ 1 added: the full projection, which "
                          "in this element only removes the rigid rotation from the "
                          "membrane hourglass rates (and from their forces)",
    "hourglass-membrane-only": "every *HOURGLASS QB and QW (0: QM) set to 0.002, QM 0.02 "
                               "kept: the out-of-plane and rotation modes at a tenth",
    "hourglass-out-of-plane-only": "every *HOURGLASS QM set to 0.002, QB and QW to 0.02: "
                                   "the membrane modes at a tenth",
    "hourglass-sixteenth": "every *HOURGLASS QM 0.02 set to 0.00125: the forces a 1/4 in "
                           "the hourglass vector would give at QM 0.02",
    "contact-stiffness-double": "the single-surface contact's SFS and SFM 0 (1) set to 2: the "
                                "penalty stiffness doubled",
    "contact-friction": "the single-surface contact's FS and FD 0 set to 0.2 (the ground "
                        "wall's value)",
    "shear-factor": "every *SECTION_SHELL SHRF 0 (1) set to 0.8333 (5/6)",
}


def set_hourglass_field(name, lines, col, old, new):
    """The include with the 10-column field at `col` of every *HOURGLASS data card that reads
    `old` replaced by `new`; fails unless all seven cards changed."""
    out, n = [], 0
    for k, line in enumerate(lines):
        if k > 1 and lines[k - 2].startswith("*HOURGLASS") and line[col:col + 10].strip() == old:
            line = line[:col] + new + line[col + 10:]
            n += 1
        out.append(line)
    if n != 7:
        raise SystemExit(f"{name}: {n} *HOURGLASS cards changed, 7 expected")
    return "\n".join(out)


def control_include(name, text):
    """The model's include text with control `name` applied; fails loudly when the card it
    changes is not where expected."""
    lines = text.split("\n")
    if name == "all-nodes-moving":
        nodes, in_nodes = [], False
        for line in lines:
            if line.startswith("*"):
                in_nodes = line.strip() == "*NODE"
            elif in_nodes and line.strip() and not line.startswith("$"):
                nodes.append(int(line[:8]))
        i = lines.index("*INITIAL_VELOCITY_NODE")
        j = i + 1
        listed = set()
        while not lines[j].startswith("*"):
            if lines[j].strip() and not lines[j].startswith("$"):
                listed.add(int(lines[j][:10]))
            j += 1
        extra = [f"{n:10d}{-8333.0:10.1f}{0.0:10.1f}{0.0:10.1f}" for n in nodes
                 if n not in listed]
        return "\n".join(lines[:j] + extra + lines[j:])
    if name == "ground-frictionless":
        i = lines.index("*RIGIDWALL_PLANAR_ID")
        k = next(j for j in range(i + 1, len(lines))
                 if lines[j].strip() and not lines[j].startswith("$")
                 and lines[j].split()[-2:] == ["0.2", "0.0"])
        lines[k] = lines[k][:60] + f"{0.0:10.1f}" + lines[k][70:]
        return "\n".join(lines)
    if name == "hourglass-half":
        return set_hourglass_field(name, lines, 20, "0.02", f"{0.01:10.2f}")
    if name == "hourglass-viscous":
        return set_hourglass_field(name, lines, 10, "4", f"{1:10d}")
    if name == "hourglass-membrane-only":
        lines = set_hourglass_field(name, lines, 60, "0.0", f"{0.002:10.3f}").split("\n")
        return set_hourglass_field(name, lines, 70, "0.0", f"{0.002:10.3f}")
    if name == "hourglass-out-of-plane-only":
        lines = set_hourglass_field(name, lines, 60, "0.0", f"{0.02:10.2f}").split("\n")
        lines = set_hourglass_field(name, lines, 70, "0.0", f"{0.02:10.2f}").split("\n")
        return set_hourglass_field(name, lines, 20, "0.02", f"{0.002:10.3f}")
    if name == "hourglass-sixteenth":
        return set_hourglass_field(name, lines, 20, "0.02", f"{0.00125:10.5f}")
    if name in ("contact-stiffness-double", "contact-friction"):
        i = lines.index("*CONTACT_AUTOMATIC_SINGLE_SURFACE_ID")
        data = [j for j in range(i + 1, i + 12) if not lines[j].startswith("$")]
        # data[0] cid, data[1] ssid..., data[2] fs fd ..., data[3] sfs sfm ...
        k, new = (data[3], f"{2.0:10.1f}") if name == "contact-stiffness-double" else (
            data[2], f"{0.2:10.1f}")
        if lines[k][:20].split() != ["0.0", "0.0"]:
            raise SystemExit(f"{name}: contact card {lines[k]!r} is not the expected one")
        lines[k] = new + new + lines[k][20:]
        return "\n".join(lines)
    if name == "shear-factor":
        out, n = [], 0
        for k, line in enumerate(lines):
            if k > 1 and lines[k - 2].startswith("*SECTION_SHELL") and line[20:30].strip() == "0.0":
                line = line[:20] + f"{0.8333:10.4f}" + line[30:]
                n += 1
            out.append(line)
        if n != 7:
            raise SystemExit(f"shear-factor: {n} *SECTION_SHELL cards changed, 7 expected")
        return "\n".join(out)
    if name == "warping-projection":
        if any(line.startswith("*CONTROL_SHELL") for line in lines):
            raise SystemExit("warping-projection: the model already has *CONTROL_SHELL")
        i = lines.index("*CONTROL_TERMINATION")
        card = " " * 50 + f"{1:10d}{0:10d}{1:10d}"
        return "\n".join(lines[:i] + ["*CONTROL_SHELL", card] + lines[i:])
    raise SystemExit(f"unknown control {name}; known: {', '.join(CONTROLS)}")


def read_wide(path):
    """Our wide CSV: header `time,<labels>`, one row per sample."""
    with open(path) as f:
        rows = list(csv.reader(f))
    if len(rows) < 2:
        raise SystemExit(f"{path}: no samples")
    header = rows[0]
    cols = {h: [float(r[i]) for r in rows[1:]] for i, h in enumerate(header)}
    return cols


def column(cols, label, path):
    if label not in cols:
        raise SystemExit(f"{path}: no column {label}")
    return cols[label]


def outputs(run):
    nodes = os.path.join(run, "nodes.csv")
    walls = os.path.join(run, "walls.csv")
    parts = os.path.join(run, "part_velocities.csv")
    energies = os.path.join(run, "energies.csv")
    n = read_wide(nodes)
    w = read_wide(walls)
    p = read_wide(parts)
    e = read_wide(energies)
    out = {
        "dmax": column(n, "605.x", nodes)[-1],
        "fmax": max(column(w, "2.fx", walls)),
        "vfin": column(p, "1.vx", parts)[-1],
        "IE": column(e, "internal", energies)[-1],
        # Beside the study's four: the pole's normal force, the hourglass energy, the
        # time of the last sample (a check that the run reached 0.2 s).
        "fmax_normal": max(column(w, "2.f", walls)),
        "HE": column(e, "hourglass", energies)[-1],
        "t_end": column(e, "time", energies)[-1],
    }
    return out


def story(run):
    """Prints where a run's energy goes over time (see the module docs, `story`)."""
    e = read_wide(os.path.join(run, "energies.csv"))
    v = read_wide(os.path.join(run, "part_velocities.csv"))
    p = read_wide(os.path.join(run, "part_energies.csv"))
    t, vx = e["time"], column(v, "1.vx", run)
    print(f"{'t':>6} {'kinetic':>10} {'internal':>10} {'hourglass':>10} {'contact':>10} "
          f"{'body vx':>9}")
    every = max(1, round(0.01 / (t[1] - t[0])))
    for k in list(range(0, len(t), every)):
        print(f"{t[k]:6.3f} {e['kinetic'][k]:10.4g} {e['internal'][k]:10.4g} "
              f"{e['hourglass'][k]:10.4g} {e['contact'][k]:10.4g} {vx[k]:9.1f}")
    he = e["hourglass"]
    k = max(range(len(he)), key=lambda j: he[j])
    print(f"hourglass energy: peak {he[k]:.4g} at t = {t[k]:.4f}, last {he[-1]:.4g} "
          f"(given back {he[k] - he[-1]:.4g})")
    turn = next((t[j] for j in range(len(vx)) if vx[j] > 0), None)
    print(f"body x velocity: last {vx[-1]:.1f}, first positive (rebound) at "
          f"{'never' if turn is None else f't = {turn:.4f}'}")
    print(f"{'part':>5} {'HE peak':>10} {'at t':>7} {'HE last':>10} {'IE last':>10}")
    parts = sorted({c.split(".")[0] for c in p if c != "time"}, key=int)
    for q in parts:
        h = p[f"{q}.hourglass"]
        j = max(range(len(h)), key=lambda i: h[i])
        print(f"{q:>5} {h[j]:10.4g} {t[j]:7.4f} {h[-1]:10.4g} {p[f'{q}.internal'][-1]:10.4g}")


def ranks(v):
    """Ranks 1..n, ties sharing their mean rank."""
    order = sorted(range(len(v)), key=lambda i: v[i])
    r = [0.0] * len(v)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and v[order[j + 1]] == v[order[i]]:
            j += 1
        for k in range(i, j + 1):
            r[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return r


def pearson(a, b):
    n = len(a)
    ma, mb = sum(a) / n, sum(b) / n
    sab = sum((x - ma) * (y - mb) for x, y in zip(a, b))
    saa = sum((x - ma) ** 2 for x in a)
    sbb = sum((y - mb) ** 2 for y in b)
    if saa == 0 or sbb == 0:
        return float("nan")
    return sab / math.sqrt(saa * sbb)


def spearman(a, b):
    return pearson(ranks(a), ranks(b))


def rel(ours, theirs):
    """Relative difference ours / theirs - 1: for the negative dmax and vfin, negative when
    our magnitude is the smaller."""
    return ours / theirs - 1.0


def summary(ours, theirs):
    d = [rel(o, t) for o, t in zip(ours, theirs)]
    return {
        "mean": sum(d) / len(d),
        "mean_abs": sum(abs(x) for x in d) / len(d),
        "max_abs": max(abs(x) for x in d),
        "pearson": pearson(ours, theirs),
        "spearman": spearman(ours, theirs),
    }


def compare(results, failures=None):
    with open(results) as f:
        rows = list(csv.DictReader(f))
    failed = []
    if failures and os.path.exists(failures):
        with open(failures) as f:
            failed = [line.strip() for line in f if line.strip()]
    y = read_y()
    designs = [r for r in rows if r["row"].isdigit()]
    base = [r for r in rows if r["row"] == "base"]
    controls = [r for r in rows if r["row"] in CONTROLS]
    if not designs:
        raise SystemExit(f"{results}: no design rows")
    print(f"{len(designs)} designs of p9_X.csv (rows {', '.join(r['row'] for r in designs)})")
    for line in failed:
        print(f"not compared (our run failed): design {line}")
    print()
    print("| output | LS-DYNA range | ours range | mean rel. diff. | mean abs. rel. diff. "
          "| max abs. rel. diff. | Pearson | Spearman |")
    print("|---|---|---|---|---|---|---|---|")
    for k in OUTPUTS:
        theirs = [y[k][int(r["row"])] for r in designs]
        ours = [float(r[k]) for r in designs]
        s = summary(ours, theirs)
        print(f"| {k} | {min(theirs):.4g} to {max(theirs):.4g} | {min(ours):.4g} to "
              f"{max(ours):.4g} | {100 * s['mean']:+.2f} % | {100 * s['mean_abs']:.2f} % | "
              f"{100 * s['max_abs']:.2f} % | {s['pearson']:.3f} | {s['spearman']:.3f} |")
    # Not one of the study's outputs: our internal plus hourglass energy against LS-DYNA's
    # internal energy, the measure of how our hourglass share enters the IE difference.
    theirs = [y["IE"][int(r["row"])] for r in designs]
    ours = [float(r["IE"]) + float(r["HE"]) for r in designs]
    s = summary(ours, theirs)
    print(f"| ours IE + HE against IE (not the study's output) | | {min(ours):.4g} to "
          f"{max(ours):.4g} | {100 * s['mean']:+.2f} % | {100 * s['mean_abs']:.2f} % | "
          f"{100 * s['max_abs']:.2f} % | {s['pearson']:.3f} | {s['spearman']:.3f} |")
    # vfin is a small remainder of the initial 8333 mm/s: its difference on that scale.
    d = [(float(r["vfin"]) - y["vfin"][int(r["row"])]) / V0 for r in designs]
    print(f"| vfin difference over the initial speed {V0:g} mm/s | | | "
          f"{100 * sum(d) / len(d):+.2f} % | {100 * sum(abs(x) for x in d) / len(d):.2f} % | "
          f"{100 * max(abs(x) for x in d):.2f} % | | |")
    print()
    print("| row | " + " | ".join(f"{k} LS-DYNA | {k} ours" for k in OUTPUTS) + " |")
    print("|---" * (1 + 2 * len(OUTPUTS)) + "|")
    for r in designs:
        i = int(r["row"])
        cells = [f"{y[k][i]:.4g} | {float(r[k]):.4g} ({100 * rel(float(r[k]), y[k][i]):+.1f} %)"
                 for k in OUTPUTS]
        print(f"| {i} | " + " | ".join(cells) + " |")
    for r in base:
        cells = []
        for k in OUTPUTS:
            m = sum(BASE_REPEATS[k]) / len(BASE_REPEATS[k])
            cells.append(f"{m:.4g} | {float(r[k]):.4g} ({100 * rel(float(r[k]), m):+.1f} %)")
        print("| base (mean of 5 repeats) | " + " | ".join(cells) + " |")
    if not (base and controls):
        return
    print()
    print("Controlled reruns at the base design: each output, and its change from our base run "
          "and (in brackets) the gap to LS-DYNA's mean that the change closes")
    print()
    print("| control | " + " | ".join(OUTPUTS) + " | HE |")
    print("|---" * (2 + len(OUTPUTS)) + "|")
    b = base[0]
    for r in controls:
        cells = []
        for k in OUTPUTS:
            ours, ref = float(r[k]), float(b[k])
            m = sum(BASE_REPEATS[k]) / len(BASE_REPEATS[k])
            gap = m - ref
            closed = (ours - ref) / gap if gap else float("nan")
            cells.append(f"{ours:.4g} ({100 * rel(ours, ref):+.1f} %; {100 * closed:+.0f} %)")
        he = float(r["HE"])
        cells.append(f"{he:.4g} ({100 * rel(he, float(b['HE'])):+.1f} %)")
        print(f"| {r['row']} | " + " | ".join(cells) + " |")


def selftest():
    close = lambda a, b: abs(a - b) < 1e-12
    assert ranks([3.0, 1.0, 2.0, 2.0]) == [4.0, 1.0, 2.5, 2.5]
    assert close(pearson([1, 2, 3], [2, 4, 6]), 1.0)
    assert close(pearson([1, 2, 3], [3, 2, 1]), -1.0)
    # Hand-computed: x = 1..4, y = 1, 3, 2, 4: sxy = 4, sxx = syy = 5, r = 0.8.
    assert close(pearson([1, 2, 3, 4], [1, 3, 2, 4]), 0.8)
    # Monotone but not linear: Spearman 1, Pearson below 1.
    assert close(spearman([1, 2, 3, 4], [1, 10, 100, 1000]), 1.0)
    assert pearson([1, 2, 3, 4], [1, 10, 100, 1000]) < 0.9
    assert close(rel(-110.0, -100.0), 0.1)
    assert close(rel(90.0, 100.0), -0.1)
    s = summary([1.1, 1.8], [1.0, 2.0])
    assert close(s["mean"], 0.0) and close(s["max_abs"], 0.1) and close(s["mean_abs"], 0.1)
    # Maximin: on the corners and centre of a square, the centre first, then corners.
    pts = [[0, 0], [1, 1], [0.5, 0.5], [0, 1], [1, 0]]
    got = maximin(pts, 3)
    assert got[0] == 2 and set(got[1:]) <= {0, 1, 3, 4}, got
    deck = parameter_deck([3, 2, 5, 1, 1, 400, 400, 400, 400.123456789], "m.k")
    assert "rtbumper,3,rtrailb,2,rtrailf,5,rtgrill,1\n" in deck, deck
    assert "rybody,400.123\n" in deck, deck
    print("selftest: ok")


def main(argv):
    if not argv:
        raise SystemExit(__doc__)
    cmd = argv[0]
    if cmd == "select":
        x = read_x()
        print(" ".join(str(i) for i in maximin([unit(r) for r in x], int(argv[1]))))
    elif cmd == "deck":
        row, out = argv[1], argv[2]
        values = [3, 2, 5, 1, 1, 400, 400, 400, 400] if row == "base" else read_x()[int(row)]
        with open(os.path.join(out, "main.k"), "w") as f:
            f.write(parameter_deck(values, "car6_crash_v223.k"))
    elif cmd == "controls":
        print(" ".join(CONTROLS))
    elif cmd == "control":
        name, out = argv[1], argv[2]
        with open(os.path.join(DATA, "decks", "car6_crash_v223.k")) as f:
            text = f.read()
        with open(os.path.join(out, "car6_crash_v223.k"), "w") as f:
            f.write(control_include(name, text))
        with open(os.path.join(out, "main.k"), "w") as f:
            f.write(parameter_deck([3, 2, 5, 1, 1, 400, 400, 400, 400], "car6_crash_v223.k"))
    elif cmd == "outputs":
        o = outputs(argv[1])
        print(",".join(f"{o[k]!r}" for k in OUTPUTS + ["fmax_normal", "HE", "t_end"]))
    elif cmd == "header":
        print(",".join(["row"] + OUTPUTS + ["fmax_normal", "HE", "t_end", "cycles",
                                            "wall_s"]))
    elif cmd == "compare":
        compare(argv[1], argv[2] if len(argv) > 2 else None)
    elif cmd == "story":
        story(argv[1])
    elif cmd == "selftest":
        selftest()
    else:
        raise SystemExit(f"unknown subcommand {cmd}\n{__doc__}")


if __name__ == "__main__":
    main(sys.argv[1:])
