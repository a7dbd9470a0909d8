#!/usr/bin/python3
"""Oracle test: the quality report (report.html and its figures) in headless Chromium.

isohex-report-demo (built beside the CLI) writes the report of a jittered ball with
inverted hexes. Checked here, each by means independent of the C++ code:
  * the histogram PNGs decode with PIL to the figure size, and their coloured bars (red
    inverted, orange questionable, green acceptable) are where report.json has non-zero
    counts, in bin order, with heights proportional to the counts;
  * report.html fetches nothing (no external src/href/url/@import);
  * Chromium loads the page without a console message or script error, and the viewer's
    status element reports the first frame; its triangle count equals the count this script
    derives from the embedded data (decoded with base64/zlib/numpy) by the viewer's rule: a
    quad is drawn when exactly one of its cells is kept (centroid on the kept side of the
    cut, scaled Jacobian at most the filter value);
  * the screenshot's canvas region shows the mesh in the scaled-Jacobian colours (blue/green
    and red faces), and only red ones when the filter keeps inverted hexes alone;
  * a mesh over the embedding limit gives the boundary-plus-worst-hexes view, said so on
    the page.
Exits 77 (ctest: skipped) when chromium is not installed; scripts/install-deps.sh installs it.
"""
import argparse
import base64
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys
import zlib

import numpy as np

FAILURES = []


def check(ok, what):
    if not ok:
        FAILURES.append(what)
        print("FAIL:", what)


BROWSER_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--use-gl=angle",
                 "--use-angle=swiftshader", "--virtual-time-budget=8000", "--window-size=1200,900",
                 "--enable-logging=stderr", "--v=0", "--hide-scrollbars", "--no-first-run",
                 "--disable-extensions", "--disable-background-networking"]


def chromium(browser, url, mode, tmp):
    """Runs headless chromium; returns (stdout, console lines that are not driver notes)."""
    env = dict(os.environ, HOME=tmp)  # a private profile folder, not the user's
    cmd = [browser] + BROWSER_FLAGS + ["--user-data-dir=" + os.path.join(tmp, "profile")] + mode + [url]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=env, cwd=tmp)
    console = [l for l in r.stderr.splitlines() if ":CONSOLE" in l and "GL Driver Message" not in l]
    check(r.returncode == 0, f"chromium exit code {r.returncode} for {url}: {r.stderr[-500:]}")
    return r.stdout, console


class StatusParser(html.parser.HTMLParser):
    """Collects the viewer status element's attributes and text, and the error list."""

    def __init__(self):
        super().__init__()
        self.status, self.text, self.errors, self.note = None, "", [], ""
        self._in = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id") == "viewer-status":
            self.status, self._in = a, "status"
        elif a.get("id") == "viewer-note":
            self._in = "note"
        elif self._in == "errors" and tag == "li":
            self.errors.append("")
        elif a.get("id") == "viewer-errors":
            self._in = "errors"

    def handle_endtag(self, tag):
        if tag in ("div", "p", "ul"):
            self._in = None

    def handle_data(self, data):
        if self._in == "status":
            self.text += data
        elif self._in == "note":
            self.note += data
        elif self._in == "errors" and self.errors:
            self.errors[-1] += data


def load_page(browser, page, fragment, tmp):
    dom, console = chromium(browser, "file://" + page + fragment, ["--dump-dom"], tmp)
    p = StatusParser()
    p.feed(dom)
    check(not console, f"console messages on {fragment or 'load'}: {console}")
    check(p.status is not None, "no viewer-status element in the DOM")
    if p.status is None:
        return None, p
    check(p.status.get("data-state") == "ok", f"viewer status {p.status.get('data-state')}: {p.text.strip()}")
    check(not p.errors, f"viewer errors: {p.errors}")
    return p.status, p


def embedded_data(page):
    text = open(page, encoding="utf-8").read()
    info = json.loads(re.search(r'id="mesh-info">(.*?)</script>', text, re.S).group(1))
    blob = zlib.decompress(base64.b64decode(re.search(r'id="mesh-data">(.*?)</script>', text, re.S).group(1)))
    check(len(blob) == info["bytes"], f"mesh data inflates to {len(blob)} bytes, info says {info['bytes']}")
    off = 0

    def take(dtype, n):
        nonlocal off
        a = np.frombuffer(blob, dtype=dtype, count=n, offset=off)
        off += 4 * n
        return a
    d = {"info": info, "points": take("<f4", 3 * info["points"]).reshape(-1, 3),
         "quads": take("<u4", 4 * info["quads"]).reshape(-1, 4), "sides": take("<i4", 2 * info["quads"]).reshape(-1, 2),
         "centroids": take("<f4", 3 * info["cells"]).reshape(-1, 3), "sj": take("<f4", info["cells"])}
    check(off == len(blob), "mesh data has trailing bytes")
    check(d["quads"].max() < info["points"] and d["sides"].max() < info["cells"], "mesh data indices out of range")
    return d, text


def expected_triangles(d, axis=0, cut=0.55, flip=False, sj_max=1.0):
    """The viewer's rule, in float64 on the float32 data (as JavaScript computes)."""
    c = d["centroids"][:, axis].astype(np.float64)
    lo, hi = c.min(), c.max()
    frac = round(1000 * cut) / 1000
    eps = 1e-6 * (hi - lo + 1e-30)
    if flip:
        side = c >= (hi - frac * (hi - lo)) - eps
    else:
        side = c <= (lo + frac * (hi - lo)) + eps
    sj = d["sj"].astype(np.float64)
    degenerate = ~(np.abs(sj) < 1e29)
    kept = side & ((sj_max >= 1) | degenerate | (sj <= round(100 * sj_max) / 100))
    s = d["sides"]
    ka = (s[:, 0] >= 0) & kept[np.maximum(s[:, 0], 0)]
    kb = (s[:, 1] >= 0) & kept[np.maximum(s[:, 1], 0)]
    return 2 * int(np.count_nonzero(ka != kb))


def check_histogram_png(path, stage):
    from PIL import Image
    img = np.asarray(Image.open(path).convert("RGB")).astype(int)
    check(img.shape[1] == 900 and img.shape[0] > 400, f"{path}: size {img.shape}")
    colours = {"red": (0xcc, 0x33, 0x11), "orange": (0xee, 0x77, 0x33), "green": (0x22, 0x88, 0x33)}
    col_class = np.full(img.shape[1], "", dtype=object)
    col_top = np.full(img.shape[1], img.shape[0])
    for name, rgb in colours.items():
        mask = np.all(img == rgb, axis=2)
        for x in np.nonzero(mask.any(axis=0))[0]:
            col_class[x] = name
            col_top[x] = min(col_top[x], np.nonzero(mask[:, x])[0].min())
    bars = []  # runs of columns of one class
    for x in range(img.shape[1]):
        if col_class[x] and bars and bars[-1][1] == x - 1 and bars[-1][2] == col_class[x]:
            bars[-1][1] = x
            bars[-1][3] = min(bars[-1][3], col_top[x])
        elif col_class[x]:
            bars.append([x, x, col_class[x], col_top[x]])
    h = stage["scaled_jacobian"]["histogram"]
    want = [(lo, c) for lo, c in zip(h["edges"], h["counts"]) if c > 0]
    check(len(bars) == len(want), f"{path}: {len(bars)} bars drawn, {len(want)} non-zero bins")
    if len(bars) != len(want):
        return
    baseline = max(np.nonzero(np.all(img[:, (bars[0][0] + bars[0][1]) // 2] == colours[bars[0][2]], axis=1))[0]) + 1
    tallest = max(c for _, c in want)
    for (x0, x1, cls, top), (lo, count) in zip(bars, want):
        cls_want = "red" if lo < 0 else "orange" if lo < 0.2 else "green"
        check(cls == cls_want, f"{path}: bar of bin {lo:.1f} is {cls}, expected {cls_want}")
        height = baseline - top
        full = baseline - min(b[3] for b in bars)
        check(abs(height / full - count / tallest) < 0.01 or (count > 0 and height >= 1 and count / tallest < 0.01),
              f"{path}: bar of bin {lo:.1f} is {height}/{full} px high for {count}/{tallest}")


def colour_stats(shot, rect):
    from PIL import Image
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    x, y, w, h = rect
    region = img[y + 2:y + h - 2, x + 2:x + w - 2]
    r, g, b = region[..., 0], region[..., 1], region[..., 2]
    coloured = (region.max(axis=2) - region.min(axis=2)) > 40
    red = coloured & (r > 2 * g) & (r > 2 * b) & (r > 60)
    cool = coloured & ((g > r + 20) | (b > r + 20))
    return region.shape[0] * region.shape[1], int(coloured.sum()), int(red.sum()), int(cool.sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--data")
    ap.add_argument("--tmp", required=True)
    args = ap.parse_args()
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if not browser:
        print("skipped: chromium not installed (scripts/install-deps.sh installs it)")
        return 77
    demo = os.path.join(os.path.dirname(os.path.abspath(args.cli)), "isohex-report-demo")
    tmp = os.path.abspath(args.tmp)
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)

    # A whole mesh (every hex embedded).
    out = os.path.join(tmp, "report")
    subprocess.run([demo, out, "--n", "14"], check=True, capture_output=True)
    report = json.load(open(os.path.join(out, "report.json")))
    for st in report["stages"]:
        check_histogram_png(os.path.join(out, st["figures"]["png"]), st)
    page = os.path.join(out, "report.html")
    d, text = embedded_data(page)
    check(not re.search(r"""(src|href)\s*=\s*["']?\s*(https?:|//)|url\(|@import|<link""", text, re.I),
          "report.html refers to something outside itself")
    check(d["info"]["complete"] and d["info"]["cells"] == report["stages"][-1]["hexes"], "viewer data is not the whole mesh")

    status, _ = load_page(browser, page, "", tmp)
    if status:
        want = expected_triangles(d)
        check(int(status.get("data-triangles", -1)) == want, f"default view: {status.get('data-triangles')} triangles, expected {want}")
        rect = [int(v) for v in status["data-rect"].split(",")]
        check(rect[1] + rect[3] <= 900 and rect[2] >= 400, f"canvas at {rect} is not within the first screen")
        shot = os.path.join(tmp, "default.png")
        chromium(browser, "file://" + page, ["--screenshot=" + shot], tmp)
        total, coloured, red, cool = colour_stats(shot, rect)
        print(f"default view: {want} triangles; canvas {total} px, {coloured} coloured, {red} red, {cool} green/blue")
        check(coloured > 0.15 * total, "the canvas shows too little of the mesh")
        check(red > 200 and cool > 2000, "the canvas lacks the inverted (red) or good (green/blue) colours")

        # Only the inverted hexes, cut across y from the other side.
        frag = "#axis=y&cut=0.8&flip=1&sj=0&edges=0"
        status2, _ = load_page(browser, page, frag, tmp)
        if status2:
            want2 = expected_triangles(d, axis=1, cut=0.8, flip=True, sj_max=0.0)
            check(int(status2.get("data-triangles", -1)) == want2 and 0 < want2 < want * 5,
                  f"{frag}: {status2.get('data-triangles')} triangles, expected {want2}")
            shot2 = os.path.join(tmp, "inverted.png")
            chromium(browser, "file://" + page + frag, ["--screenshot=" + shot2], tmp)
            total, coloured, red, cool = colour_stats(shot2, rect)
            print(f"inverted only: {want2} triangles; {coloured} coloured px, {red} red, {cool} green/blue")
            check(coloured > 0.01 * total and red > 0.9 * coloured, "inverted-only view is not red")

    # Over the limit: the boundary and the worst hexes.
    out2 = os.path.join(tmp, "capped")
    subprocess.run([demo, out2, "--n", "14", "--max-hexes", "500"], check=True, capture_output=True)
    page2 = os.path.join(out2, "report.html")
    d2, _ = embedded_data(page2)
    check(not d2["info"]["complete"] and 0 < d2["info"]["worst_hexes"] < d2["info"]["cells"] < d2["info"]["mesh_hexes"],
          f"capped viewer data: {d2['info']}")
    status3, p3 = load_page(browser, page2, "", tmp)
    if status3:
        want3 = expected_triangles(d2)
        check(int(status3.get("data-triangles", -1)) == want3, f"capped view: {status3.get('data-triangles')} triangles, expected {want3}")
        check("more than this page embeds" in p3.note, f"capped page does not say so: {p3.note!r}")

    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        return 1
    print("report in chromium: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
