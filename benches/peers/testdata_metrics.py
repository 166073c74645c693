"""Peer comparison for test data, CFC filters and curve metrics.

Peers: objective-rating-metrics (ISO/TS 18571, the implementation pyisomme calls) and
pyisomme (ISO-MME reader and writer, ISO 6487 CFC filter).

    python testdata_metrics.py generate WORK   # inputs and the peers' answers
    python testdata_metrics.py report WORK     # compare with WORK/ours.json, time the peer
    python testdata_metrics.py fixtures WORK ROOT  # copy the small fixtures into the repository

Run through testdata_metrics.sh, which builds the venv and runs our side in between.
"""

import json
import logging
import math
import shutil
import statistics
import sys
import time
import zipfile
from pathlib import Path

import numpy as np

logging.disable(logging.CRITICAL)

N_REF = 301          # samples per ISO 18571 validation curve (10 kHz, 30 ms)
DT = 1e-4


def r6(values):
    """Rounds to 6 significant digits so both sides read the very same decimal numbers."""
    return [float(f"{v:.6e}") for v in values]


# ---------------------------------------------------------------------------------------------
# ISO/TS 18571 curve pairs
# ---------------------------------------------------------------------------------------------

def shapes():
    t = np.arange(N_REF) * DT

    def half_sine(t0=0.006, width=0.012, amp=40.0):
        x = np.where((t >= t0) & (t <= t0 + width), np.sin(np.pi * (t - t0) / width), 0.0)
        return amp * x

    def crash_pulse(t0=0.004, amp=-25.0, stretch=1.0, ripple=0.25):
        s = (t - t0) / stretch
        base = np.where(s > 0, (s / 0.008) ** 2 * np.exp(2 - 2 * s / 0.008), 0.0)
        return amp * base * (1 + ripple * np.sin(2 * np.pi * 450 * np.clip(s, 0, None)))

    def damped(t0=0.002, f=180.0, zeta=0.12, amp=3.0):
        s = np.clip(t - t0, 0, None)
        return amp * np.exp(-zeta * 2 * np.pi * f * s) * np.sin(2 * np.pi * f * s)

    def plateau(t0=0.005, rise=0.004, hold=0.010, amp=12.0):
        s = t - t0
        up = np.clip(s / rise, 0, 1)
        down = np.clip(1 - (s - rise - hold) / 0.006, 0, 1)
        return amp * np.minimum(up, down) + 0.4 * amp * np.exp(-((s - 0.018) / 0.002) ** 2)

    return {"half_sine": half_sine, "crash_pulse": crash_pulse, "damped": damped, "plateau": plateau}


def iso_cases():
    f = shapes()
    rng = np.random.default_rng(18571)
    refs = {name: r6(fn()) for name, fn in f.items()}
    cases = []

    def add(name, ref, comp):
        cases.append({"name": name, "reference": ref, "comparison": r6(comp)})

    for ref in refs:
        add(f"{ref}: itself", ref, refs[ref])
    add("half_sine: 0.5 ms late", "half_sine", f["half_sine"](t0=0.0065))
    add("half_sine: 1.5 ms early", "half_sine", f["half_sine"](t0=0.0045))
    add("half_sine: 3 ms late", "half_sine", f["half_sine"](t0=0.009))
    add("half_sine: 7 ms late (beyond the search)", "half_sine", f["half_sine"](t0=0.013))
    add("crash_pulse: 1 ms late", "crash_pulse", f["crash_pulse"](t0=0.005))
    add("crash_pulse: 2.5 ms early", "crash_pulse", f["crash_pulse"](t0=0.0015))
    add("damped: 0.8 ms late", "damped", f["damped"](t0=0.0028))
    add("plateau: 2 ms late", "plateau", f["plateau"](t0=0.007))
    for s in (0.8, 0.95, 1.1, 1.5):
        add(f"crash_pulse: scaled {s}", "crash_pulse", s * np.array(refs["crash_pulse"]))
    add("half_sine: scaled 0.6", "half_sine", 0.6 * np.array(refs["half_sine"]))
    add("damped: scaled 1.3", "damped", 1.3 * np.array(refs["damped"]))
    for ref, sigma in (("half_sine", 0.4), ("half_sine", 2.0), ("crash_pulse", 1.0),
                       ("damped", 0.15), ("plateau", 0.6), ("plateau", 3.0)):
        add(f"{ref}: noise sigma {sigma}", ref, np.array(refs[ref]) + rng.normal(0, sigma, N_REF))
    add("half_sine: wider", "half_sine", f["half_sine"](width=0.016, amp=34.0))
    add("crash_pulse: stretched, no ripple", "crash_pulse", f["crash_pulse"](stretch=1.2, ripple=0.0))
    add("crash_pulse: stronger ripple", "crash_pulse", f["crash_pulse"](ripple=0.6))
    add("damped: lighter damping, higher frequency", "damped", f["damped"](f=200.0, zeta=0.06))
    add("plateau: shorter hold", "plateau", f["plateau"](hold=0.006))
    add("plateau: clipped at 9", "plateau", np.minimum(refs["plateau"], 9.0))
    add("half_sine: 1 ms late, scaled 1.2, noise", "half_sine",
        1.2 * f["half_sine"](t0=0.007) + rng.normal(0, 0.5, N_REF))
    add("crash_pulse: sign flipped", "crash_pulse", -np.array(refs["crash_pulse"]))
    add("damped: against the half sine's shape", "damped", f["half_sine"](amp=3.0))
    return refs, cases


def rate_peer(ref, comp):
    from objective_rating_metrics.rating import ISO18571
    t = np.arange(len(ref)) * DT
    iso = ISO18571(np.column_stack((t, ref)), np.column_stack((t, comp)))
    out = {k: getattr(iso, f"{k}_rating")(ndigits=-1)
           for k in ("corridor", "phase", "magnitude", "slope", "overall")}
    out["r"] = out.pop("overall")
    out["r_rounded"] = iso.overall_rating()
    return {k: float(v) for k, v in out.items()}


# ---------------------------------------------------------------------------------------------
# CFC filters
# ---------------------------------------------------------------------------------------------

def cfc_cases():
    from pyisomme.channel import Channel
    import pandas as pd
    rng = np.random.default_rng(6487)
    inputs = []
    for name, dt, n in (("10 kHz, 40 ms", 1e-4, 400), ("20 kHz, 30 ms", 5e-5, 600),
                        ("10 kHz, 5 ms (short)", 1e-4, 50), ("50 kHz, 6 ms", 2e-5, 300)):
        t = np.arange(n) * dt
        x = (30 * np.exp(-((t - 0.4 * n * dt) / (0.12 * n * dt)) ** 2)
             + 4 * np.sin(2 * np.pi * 900 * t) + rng.normal(0, 1.5, n) + 2.0)
        inputs.append((name, dt, r6(x)))
    cases = []
    for name, dt, x in inputs:
        for cfc, cls in ((60, "D"), (180, "C"), (600, "B"), (1000, "A")):
            if 1 / dt <= 2 * 1.25 / 0.6 * cfc:
                continue
            ch = Channel("11HEAD0000H3ACX0", pd.DataFrame({"v": x}, index=np.arange(len(x)) * dt),
                         unit="g", info=[("Sampling interval", dt)])
            y = ch.cfc(cls).get_data()
            cases.append({"name": name, "dt": dt, "cfc": cfc, "input": x,
                          "output": [float(f"{v:.10e}") for v in y]})
    return cases


# ---------------------------------------------------------------------------------------------
# ISO-MME data sets written by pyisomme
# ---------------------------------------------------------------------------------------------

ENCODINGS = {
    "ascii": ("ascii", "Crash lab 3", "Head CG acc X", "Chest deflection"),
    "utf-8": ("utf-8", "Crash-Prüfzentrum Δv → 56 km/h", "Kopf Beschleunigung X (日本)", "Brust Eindrückung Ω"),
    "iso-8859-1": ("iso-8859-1", "Crash-Prüfzentrum Köln ±0,5 °C", "Kopf-Schwerpunkt Beschleunigung X", "Brustkorb-Eindrückung (µm)"),
    "windows-1252": ("cp1252", "Prüfkosten 25.000 € „Nr. 4711“ …", "Kopf – Beschleunigung X™", "Brustkorb — Eindrückung"),
}


def isomme_sets(work):
    from pyisomme import Isomme
    from pyisomme.channel import create_sample
    sets = {}
    for label, (codec, lab, head_name, chest_name) in ENCODINGS.items():
        head = create_sample("11HEAD0000H3ACXA", t_range=(-0.002, 0.01, 25), mode="pulse", y_range=(0, 48.5), unit="g")
        head.info.update({"Name of the channel": head_name})
        chest = create_sample("11CHST0000H3DSXB", t_range=(-0.002, 0.01, 25), mode="sin", y_range=(-3, 21), unit="mm")
        chest.info.update({"Name of the channel": chest_name})
        force = create_sample("11FEMRLE00H3FOZB", t_range=(-0.002, 0.01, 25), mode="linear", y_range=(0.5, -4.25), unit="kN")
        iso = Isomme(test_number="T13", channels=[head, chest, force],
                     test_info=[("Data format edition number", 1.6), ("Laboratory name", lab)])
        base = work / "isomme" / label
        utf8_dir = work / "isomme_utf8" / label
        iso.write(utf8_dir / "T13")
        # pyisomme writes UTF-8; transcode its files byte for byte into the target encoding.
        for src in (utf8_dir / "T13").rglob("*"):
            if src.is_file():
                dst = base / "T13" / src.relative_to(utf8_dir / "T13")
                dst.parent.mkdir(parents=True, exist_ok=True)
                dst.write_bytes(src.read_text(encoding="utf-8").encode(codec))
        zpath = base / "T13.zip"
        with zipfile.ZipFile(zpath, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted((base / "T13").rglob("*")):
                if f.is_file():
                    z.write(f, f.relative_to(base / "T13").as_posix())
        expected = []
        for path in (base / "T13", zpath):
            back = Isomme().read(path)
            chans = []
            for ch in back.channels:
                idx = ch.data.index.to_numpy()
                chans.append({"code": str(ch.code), "unit": ch.unit.to_isomme(),
                              "name": ch.get_info("Name of the channel"),
                              "time": [float(v) for v in idx], "values": [float(v) for v in ch.get_data()]})
            expected.append({"path": str(path.relative_to(work)), "laboratory": back.test_info.get("Laboratory name"),
                             "channels": chans})
        sets[label] = expected
    return sets


# ---------------------------------------------------------------------------------------------

def generate(work):
    work.mkdir(parents=True, exist_ok=True)
    refs, cases = iso_cases()
    for c in cases:
        c["peer"] = rate_peer(refs[c["reference"]], c["comparison"])
    (work / "iso18571_pairs.json").write_text(json.dumps({"dt": DT, "references": refs, "cases": cases}))
    (work / "cfc_pyisomme.json").write_text(json.dumps({"cases": cfc_cases()}))
    (work / "isomme_expected.json").write_text(json.dumps(isomme_sets(work), ensure_ascii=False))


def report(work):
    import objective_rating_metrics
    import pyisomme
    from importlib.metadata import version
    ours = json.loads((work / "ours.json").read_text())
    print(f"peers: objective-rating-metrics {version('objective-rating-metrics')}, "
          f"pyisomme {version('pyisomme')}, numpy {np.__version__}")
    # ISO 18571
    pairs = json.loads((work / "iso18571_pairs.json").read_text())
    keys = ("r", "corridor", "phase", "magnitude", "slope")
    print(f"\n== ISO/TS 18571 on {len(pairs['cases'])} curve pairs (10 kHz, {N_REF} samples): "
          "|ours - objective-rating-metrics|, unrounded")
    print(f"{'case':<46}" + "".join(f"{k:>11}" for k in keys) + f"{'R ours':>9}{'R peer':>9}")
    worst = 0.0
    for c, o in zip(pairs["cases"], ours["iso18571"]):
        d = [abs(o[k] - c["peer"][k]) for k in keys]
        worst = max(worst, *d)
        print(f"{c['name'][:45]:<46}" + "".join(f"{v:>11.1e}" for v in d)
              + f"{o['r']:>9.4f}{c['peer']['r_rounded']:>9.3f}")
    print(f"largest difference of R or a score over all pairs: {worst:.1e} (target < 1e-3)")
    # CFC
    cfc = json.loads((work / "cfc_pyisomme.json").read_text())["cases"]
    print(f"\n== CFC filters against pyisomme's ISO-6487 filter: max |ours - pyisomme| / max |pyisomme|")
    worst_cfc = 0.0
    for c, o in zip(cfc, ours["cfc"]):
        ref = np.array(c["output"])
        d = float(np.max(np.abs(np.array(o) - ref)) / np.max(np.abs(ref)))
        worst_cfc = max(worst_cfc, d)
        print(f"{c['name']:<24} CFC {c['cfc']:<5} {d:.1e}")
    print(f"largest: {worst_cfc:.1e} (target < 1e-6)")
    # ISO-MME
    exp = json.loads((work / "isomme_expected.json").read_text())
    print("\n== ISO-MME sets written by pyisomme, read back by both")
    ok_all = True
    for label, sets in exp.items():
        for e in sets:
            o = ours["isomme"][e["path"]]
            same = len(o["channels"]) == len(e["channels"])
            dv = 0.0
            for oc, ec in zip(o["channels"], e["channels"]):
                same &= oc["code"] == ec["code"] and oc["unit"] == ec["unit"] and oc["name"] == ec["name"]
                dv = max(dv, max(abs(a - b) for a, b in zip(oc["values"], ec["values"])))
                t = np.array(ec["time"])
                dv_t = max(abs(oc["start"] - t[0]), abs(oc["dt"] - (t[1] - t[0])))
                same &= dv_t < 1e-12
            same &= o["laboratory"] == e["laboratory"] and dv == 0.0
            ok_all &= same
            print(f"{e['path']:<34} encoding {o['encoding']:<13} channels {len(o['channels'])} "
                  f"codes/units/names/lab {'same' if same else 'DIFFER'}, max value difference {dv:.1e}")
    print(f"all sets agree: {ok_all}")
    # Speed
    bench = ours["bench"]
    n_pairs, n = bench["pairs"], bench["samples"]
    data = np.fromfile(work / "bench_pairs.bin", dtype="<f8").reshape(n_pairs, 2, n)
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 1
    from objective_rating_metrics.rating import ISO18571
    t = np.arange(n) * DT
    rate_peer(data[0, 0], data[0, 1])  # compile numba's DTW before timing
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        rs = []
        for k in range(n_pairs):
            iso = ISO18571(np.column_stack((t, data[k, 0])), np.column_stack((t, data[k, 1])))
            rs.append(iso.overall_rating(ndigits=-1))
        times.append(time.perf_counter() - t0)
    peer = statistics.median(times)
    d = max(abs(a - b) for a, b in zip(rs, bench["r"]))
    print(f"\n== speed: ISO/TS 18571 on {n_pairs} pairs of {n} samples")
    print(f"ours {bench['seconds']:.3f} s (median of {bench['repeats']}, {bench['threads']} threads), "
          f"objective-rating-metrics {peer:.1f} s (median of {reps}, one process): "
          f"ratio peer/ours {peer / bench['seconds']:.0f}x; max |R ours - R peer| {d:.1e}")


def fixtures(work, root):
    """Copies the inputs and the peers' answers the Rust tests read (a few tens of kB)."""
    core = root / "crates/impactcal-core/tests/data"
    cal = root / "crates/impactcal-calibrate/tests/data"
    cal.mkdir(parents=True, exist_ok=True)
    shutil.copy(work / "iso18571_pairs.json", cal / "iso18571_pairs.json")
    shutil.copy(work / "cfc_pyisomme.json", core / "cfc_pyisomme.json")
    dst = core / "isomme"
    if dst.exists():
        shutil.rmtree(dst)
    shutil.copytree(work / "isomme", dst)
    shutil.copy(work / "isomme_expected.json", dst / "expected.json")


if __name__ == "__main__":
    what, work = sys.argv[1], Path(sys.argv[2])
    if what == "generate":
        generate(work)
    elif what == "report":
        report(work)
    elif what == "fixtures":
        fixtures(work, Path(sys.argv[3]))
    else:
        sys.exit(f"unknown step {what}")
