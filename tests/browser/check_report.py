#!/usr/bin/env python3
"""Checks that a report.html shows every figure in a real browser (headless Chromium).

Two independent looks at the page:

1. Layout: a copy of the page with a small inline script appended is loaded with
   `chromium --headless --dump-dom`; the script measures, for every expected figure, the
   bounding box of its <svg> and how many of its graphic elements have a non-empty box, and
   writes the result into the DOM, which the dump returns.
2. Pixels: a screenshot of the whole page (the window as tall as the page) is decoded (PNG,
   standard library only) and must not be blank; the region of each figure, cropped at the
   position the layout step measured, must hold drawn (non-background) pixels too.

The expected figures are the SVG files the report wrote beside report.html, so a figure that
is missing from the page fails. `--negative-controls` breaks the page in six ways (a figure
removed, a figure's drawing emptied, a figure shrunk to zero size, a figure hidden, a label
written twice a few pixels apart, the whole page hidden) and fails unless the check rejects
every one of them.

Labels: within each figure, the boxes of the <text> elements as the browser laid them out
must not overlap by more than OVERLAP_PX pixels in both directions.

Python standard library only.
"""

import argparse
import html
import json
import os
import re
import struct
import subprocess
import sys
import tempfile
import zlib
from pathlib import Path

WIDTH = 1100
MIN_SVG_WIDTH = 300
MIN_SVG_HEIGHT = 150
MIN_MARKS = 5  # drawn non-text elements with a non-empty box
MIN_TEXTS = 2  # axis descriptions at least
MIN_INK = 0.01  # fraction of a figure's pixels that differ from white
MIN_PAGE_STD = 5.0  # standard deviation of the page's grey levels (0..255)
OVERLAP_PX = 2  # two text boxes overlap when they share more than this in x and in y

PROBE = """
<script>
(function () {
  var names = %s;
  var out = {page: {width: document.documentElement.scrollWidth,
                    height: document.documentElement.scrollHeight}, figures: {}};
  names.forEach(function (name) {
    var fig = document.getElementById(name);
    var r = {present: !!fig, svg: false};
    if (fig) {
      var svg = fig.querySelector('svg');
      if (svg) {
        var box = svg.getBoundingClientRect();
        var marks = 0, texts = 0;
        svg.querySelectorAll('polyline,polygon,rect,circle,line,path,text').forEach(function (e) {
          var b = e.getBoundingClientRect();
          if (b.width > 0 || b.height > 0) {
            if (e.tagName.toLowerCase() === 'text') { texts++; } else { marks++; }
          }
        });
        // Boxes of the texts as laid out, and every pair that overlaps by more than
        // OVERLAP_PX in both directions (a shared edge or a descender touching is not an
        // overlap a reader notices).
        var boxes = [];
        svg.querySelectorAll('text').forEach(function (e) {
          var b = e.getBoundingClientRect();
          if (b.width > 0 && b.height > 0 && e.textContent.trim() !== '') {
            boxes.push({t: e.textContent.trim(), l: b.left, r: b.right, u: b.top, d: b.bottom});
          }
        });
        var overlaps = [];
        for (var i = 0; i < boxes.length; i++) {
          for (var j = i + 1; j < boxes.length; j++) {
            var a = boxes[i], c = boxes[j];
            var w = Math.min(a.r, c.r) - Math.max(a.l, c.l);
            var h = Math.min(a.d, c.d) - Math.max(a.u, c.u);
            if (w > %s && h > %s) { overlaps.push([a.t, c.t, Math.round(w), Math.round(h)]); }
          }
        }
        r = {present: true, svg: true, x: box.left + window.scrollX, y: box.top + window.scrollY,
             width: box.width, height: box.height, marks: marks, texts: texts,
             overlaps: overlaps};
      }
    }
    out.figures[name] = r;
  });
  var pre = document.createElement('pre');
  pre.id = 'impactcal-check';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
</script>
"""


def chromium_args(chromium, profile):
    return [
        chromium,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--no-first-run",
        "--disable-dev-shm-usage",
        "--hide-scrollbars",
        "--force-device-scale-factor=1",
        "--user-data-dir=" + str(profile),
    ]


def run(args):
    done = subprocess.run(args, capture_output=True, text=True, timeout=180)
    if done.returncode != 0:
        raise SystemExit(f"chromium failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return done.stdout


def measure(chromium, page, names, work):
    """Layout of every expected figure, as the browser computed it."""
    text = page.read_text(encoding="utf-8")
    probe = PROBE % (json.dumps(names), OVERLAP_PX, OVERLAP_PX)
    if "</body>" in text:
        probed = text.replace("</body>", probe + "</body>", 1)
    else:
        probed = text + probe
    copy = work / "probe.html"
    copy.write_text(probed, encoding="utf-8")
    dom = run(chromium_args(chromium, work / "profile") + [
        f"--window-size={WIDTH},900", "--dump-dom", copy.as_uri()])
    found = re.search(r'<pre id="impactcal-check">(.*?)</pre>', dom, re.S)
    if not found:
        raise SystemExit("the probe script left no result in the page")
    return json.loads(html.unescape(found.group(1)))


def read_png(path):
    """Width, height and grey levels (row-major list of 0..255) of an 8-bit RGB(A) PNG."""
    data = path.read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    pos, idat, width, height, colour = 8, b"", 0, 0, 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace != 0:
                raise SystemExit(f"{path}: unsupported PNG (depth {depth}, colour {colour})")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    grey = [0] * (width * height)
    prev = bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind = raw[start]
        line = bytearray(raw[start + 1:start + 1 + stride])
        if kind == 1:
            for i in range(channels, stride):
                line[i] = (line[i] + line[i - channels]) & 0xFF
        elif kind == 2:
            for i in range(stride):
                line[i] = (line[i] + prev[i]) & 0xFF
        elif kind == 3:
            for i in range(stride):
                left = line[i - channels] if i >= channels else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xFF
        elif kind == 4:
            for i in range(stride):
                a = line[i - channels] if i >= channels else 0
                b = prev[i]
                c = prev[i - channels] if i >= channels else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 0xFF
        row = y * width
        for x in range(width):
            i = x * channels
            grey[row + x] = (299 * line[i] + 587 * line[i + 1] + 114 * line[i + 2]) // 1000
        prev = line
    return width, height, grey


def region_stats(image, x0, y0, x1, y1):
    """Standard deviation of the grey levels and the fraction of non-white pixels."""
    width, height, grey = image
    x0, y0 = max(0, int(x0)), max(0, int(y0))
    x1, y1 = min(width, int(x1)), min(height, int(y1))
    if x1 <= x0 or y1 <= y0:
        return 0.0, 0.0
    n = s = s2 = ink = 0
    for y in range(y0, y1):
        row = grey[y * width + x0:y * width + x1]
        n += len(row)
        s += sum(row)
        s2 += sum(v * v for v in row)
        ink += sum(1 for v in row if v < 245)
    mean = s / n
    return max(0.0, s2 / n - mean * mean) ** 0.5, ink / n


def check(chromium, page, names, work):
    """Problems found with `page` (an empty list when every figure is shown)."""
    problems = []
    layout = measure(chromium, page, names, work)
    for name in names:
        f = layout["figures"].get(name, {})
        if not f.get("present"):
            problems.append(f"{name}: no <figure id=\"{name}\"> in the page")
        elif not f.get("svg"):
            problems.append(f"{name}: the figure holds no <svg>")
        elif f["width"] < MIN_SVG_WIDTH or f["height"] < MIN_SVG_HEIGHT:
            problems.append(f"{name}: shown {f['width']:.0f} x {f['height']:.0f} px, "
                            f"below {MIN_SVG_WIDTH} x {MIN_SVG_HEIGHT}")
        elif f["marks"] < MIN_MARKS or f["texts"] < MIN_TEXTS:
            problems.append(f"{name}: {f['marks']} drawn marks and {f['texts']} texts "
                            f"(at least {MIN_MARKS} and {MIN_TEXTS} expected)")
        elif f["overlaps"]:
            shown = "; ".join(f"'{a}' and '{b}' ({w} x {h} px)"
                              for a, b, w, h in f["overlaps"][:5])
            problems.append(f"{name}: {len(f['overlaps'])} pairs of text labels overlap: "
                            f"{shown}")
    height = max(200, min(30000, int(layout["page"]["height"])))
    shot = work / "page.png"
    run(chromium_args(chromium, work / "profile") + [
        f"--window-size={WIDTH},{height}", f"--screenshot={shot}", page.as_uri()])
    image = read_png(shot)
    std, ink = region_stats(image, 0, 0, image[0], image[1])
    summary = {"page": f"{image[0]} x {image[1]} px, grey std {std:.1f}, ink {ink:.3f}"}
    if std < MIN_PAGE_STD:
        problems.append(f"the screenshot is blank (grey std {std:.2f} < {MIN_PAGE_STD})")
    for name in names:
        f = layout["figures"].get(name, {})
        if not f.get("svg") or f["width"] <= 0 or f["height"] <= 0:
            continue
        std, ink = region_stats(image, f["x"], f["y"], f["x"] + f["width"], f["y"] + f["height"])
        summary[name] = (f"{f['width']:.0f} x {f['height']:.0f} px at y {f['y']:.0f}, "
                         f"{f['marks']} marks, {f['texts']} texts, "
                         f"{len(f.get('overlaps', []))} overlapping labels, ink {ink:.3f}")
        if ink < MIN_INK:
            problems.append(f"{name}: its region of the screenshot is blank "
                            f"(ink {ink:.4f} < {MIN_INK})")
    return problems, summary


def break_page(text, names, how):
    """The page broken one way (see --negative-controls)."""
    figures = list(re.finditer(r'<figure id="([^"]+)">.*?</figure>\n', text, re.S))
    if len(figures) < 5:
        raise SystemExit("negative controls need at least five figures")
    pick = {m.group(1): m for m in figures}

    def svg_open(m):
        return text.index("<svg ", m.start())

    if how == "figure removed":
        m = pick[names[0]]
        return text[:m.start()] + text[m.end():]
    if how == "drawing emptied":
        m = pick[names[1]]
        start = text.index(">", svg_open(m)) + 1
        end = text.index("</svg>", start)
        return text[:start] + text[end:]
    if how == "zero size":
        at = svg_open(pick[names[2]]) + len("<svg ")
        return text[:at] + 'style="width:0;height:0" ' + text[at:]
    if how == "figure hidden":
        at = svg_open(pick[names[3]]) + len("<svg ")
        return text[:at] + 'style="visibility:hidden" ' + text[at:]
    if how == "labels overlap":
        # The figure's first label written a second time, shifted by a few pixels.
        m = pick[names[4 % len(names)]]
        found = re.compile(r"<text[^>]*>[^<]+</text>").search(text, svg_open(m), m.end())
        if not found:
            raise SystemExit("negative control: the figure holds no text label")
        twin = re.sub(r'x="([-0-9.]+)"', lambda v: f'x="{float(v.group(1)) + 3}"',
                      found.group(0), count=1)
        return text[:found.end()] + twin + text[found.end():]
    if how == "page hidden":
        return text.replace("<body>", '<body style="display:none">', 1)
    raise ValueError(how)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chromium", default="chromium")
    parser.add_argument("--report", required=True, type=Path,
                        help="folder holding report.html and one SVG file per figure")
    parser.add_argument("--screenshot", type=Path,
                        help="keep the screenshot of the whole page (PNG) at this path, "
                             "to look at")
    parser.add_argument("--negative-controls", action="store_true",
                        help="also check that six broken copies of the page are rejected")
    args = parser.parse_args()

    page = args.report / "report.html"
    names = sorted(p.stem for p in args.report.glob("*.svg"))
    text = page.read_text(encoding="utf-8")
    # Reading order, as the page holds them.
    order = [n for n in re.findall(r'<figure id="([^"]+)">', text) if n in names]
    names = order + [n for n in names if n not in order]
    if not names:
        raise SystemExit(f"{args.report}: no figures to check")

    with tempfile.TemporaryDirectory(prefix="impactcal-browser-") as tmp:
        work = Path(tmp)
        problems, summary = check(args.chromium, page, names, work)
        if args.screenshot:
            args.screenshot.write_bytes((work / "page.png").read_bytes())
        for key, value in summary.items():
            print(f"  {key}: {value}")
        if problems:
            print("report.html FAILS the browser check:", file=sys.stderr)
            for p in problems:
                print("  " + p, file=sys.stderr)
            return 1
        print(f"report.html shows all {len(names)} figures")
        if args.negative_controls:
            missed = []
            for how in ["figure removed", "drawing emptied", "zero size", "figure hidden",
                        "labels overlap", "page hidden"]:
                broken = work / "broken" / how.replace(" ", "-")
                broken.mkdir(parents=True)
                bad = broken / "report.html"
                bad.write_text(break_page(text, names, how), encoding="utf-8")
                found, _ = check(args.chromium, bad, names, work)
                if found:
                    print(f"  negative control `{how}`: rejected:")
                    for p in found:
                        print(f"    {p}")
                else:
                    print(f"  negative control `{how}`: NOT DETECTED")
                    missed.append(how)
            if missed:
                print("the check accepted broken pages: " + ", ".join(missed), file=sys.stderr)
                return 1
            print("every broken page was rejected")
    return 0


if __name__ == "__main__":
    sys.exit(main())
