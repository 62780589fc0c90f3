#!/usr/bin/env python3
"""report.html in a real browser: Debian's chromium, headless, loads the page offline.

  html_browser_test.py CHROMIUM OIIOTOOL OUT_DIR [--max-mb 8] [--screenshot FILE] -- ISOLINK ARGS...

Runs `ISOLINK ARGS... -o OUT_DIR` (run, sweep or pack; OUT_DIR is removed first), then checks
OUT_DIR/report.html (the screenshot goes to OUT_DIR_screenshot.png unless --screenshot says):
- the file names no network address of any kind and is under --max-mb megabytes;
- chromium (no network: --disable-background-networking and friends, and the page has nothing to
  fetch) loads it, and within the virtual-time budget the script sets data-ready="1" on <body>;
- the verdict the page shows (#verdict) is the verdict of report.json (run, pack) or of the
  points in results.csv (sweep: PASS only when every point passes);
- every plot drew: one dygraph canvas per waveform / margin plot;
- a screenshot is not blank: enough non-white pixels, many colours, and the waveform trace's own
  colour (#1f3f77) or the margin plot's present.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

CHROMIUM_FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-default-apps", "--disable-extensions", "--hide-scrollbars", "--mute-audio",
]
NETWORK = re.compile(r"(https?:|ftp:|wss?:)//|\b(src|href)\s*=\s*[\"']?//|@import|sourceMappingURL",
                     re.I)


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def chromium(browser, args, profile):
    cmd = [browser] + CHROMIUM_FLAGS + ["--user-data-dir=" + profile] + args
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    if p.returncode != 0:
        fail("chromium exit %d: %s\n%s" % (p.returncode, " ".join(cmd), p.stderr[-3000:]))
    return p.stdout


def read_image(oiiotool, path):
    """The screenshot as 8-bit RGB rows (OpenImageIO's oiiotool writes it as a binary PPM)."""
    with tempfile.TemporaryDirectory() as d:
        ppm = os.path.join(d, "shot.ppm")
        subprocess.run([oiiotool, path, "--ch", "R,G,B", "-d", "uint8", "-o", ppm], check=True)
        data = open(ppm, "rb").read()
    m = re.match(rb"P6\s+(\d+)\s+(\d+)\s+255\s", data)
    if not m:
        fail("oiiotool did not write a PPM")
    w, h = int(m.group(1)), int(m.group(2))
    px = data[m.end():]
    return w, h, [px[y * w * 3:(y + 1) * w * 3] for y in range(h)]


def pixel_stats(oiiotool, path, want):
    w, h, rows = read_image(oiiotool, path)
    nonwhite, colours, near, total = 0, set(), 0, 0
    for row in rows[::2]:  # every other row and column is plenty
        for x in range(0, w * 3, 6):
            r, g, b = row[x], row[x + 1], row[x + 2]
            total += 1
            if r < 245 or g < 245 or b < 245:
                nonwhite += 1
            colours.add((r >> 3, g >> 3, b >> 3))
            if abs(r - want[0]) < 40 and abs(g - want[1]) < 40 and abs(b - want[2]) < 40:
                near += 1
    return w, h, nonwhite / total, len(colours), near


def main():
    argv = sys.argv[1:]
    sep = argv.index("--")
    opts, cmd = argv[:sep], argv[sep + 1:]
    browser, oiiotool, out = opts[0], opts[1], opts[2]
    max_mb = float(opts[opts.index("--max-mb") + 1]) if "--max-mb" in opts else 8.0
    shot = opts[opts.index("--screenshot") + 1] if "--screenshot" in opts else None

    shutil.rmtree(out, ignore_errors=True)  # the test's own folder: a fresh report each run
    p = subprocess.run(cmd + ["-o", out, "-q"], capture_output=True, text=True, timeout=600)
    if p.returncode not in (0, 1):
        fail("%s exited %d: %s" % (" ".join(cmd), p.returncode, p.stderr[-2000:]))
    page = os.path.join(out, "report.html")
    if not os.path.isfile(page):
        fail("no report.html in " + out)
    size = os.path.getsize(page)
    text = open(page, encoding="utf-8").read()
    m = NETWORK.search(text)
    if m:
        fail("report.html names a network address: ..." + text[max(0, m.start() - 80):m.end() + 80])
    if size >= max_mb * 1e6:
        fail("report.html is %.2f MB, limit %.1f MB" % (size / 1e6, max_mb))
    print("report.html: %.2f MB, no network reference" % (size / 1e6))

    kind = re.search(r'<body data-kind="(\w+)"', text).group(1)
    if kind == "sweep":
        with open(os.path.join(out, "results.csv")) as f:
            verdicts = [r["verdict"] for r in csv.DictReader(f)]
        expected = "PASS" if all(v == "pass" for v in verdicts) else "FAIL"
        plots = 1
    else:
        report = json.load(open(os.path.join(out, "report.json")))
        expected = report["verdict"].upper()
        plots = len(report.get("directions", [])) if kind == "run" else 0

    url = "file://" + os.path.abspath(page)
    with tempfile.TemporaryDirectory() as profile:
        dom = chromium(browser, ["--virtual-time-budget=30000", "--dump-dom", url], profile)
    body = re.search(r"<body[^>]*>", dom)
    if not body or 'data-ready="1"' not in body.group(0):
        err = re.search(r'class="error">([^<]*)', dom)
        fail("the page never set data-ready=\"1\" (body: %s)%s" %
             (body.group(0) if body else "none", "; " + err.group(1) if err else ""))
    v = re.search(r'id="verdict"[^>]*>([^<]*)<', dom)
    if not v or v.group(1).strip() != expected:
        fail("the page shows verdict %r, the reports say %r" % (v.group(1) if v else None, expected))
    print("data-ready=\"1\"; verdict %s as in the reports" % expected)
    canvases = len(re.findall(r"<canvas", dom))
    if plots and canvases < 2 * plots:  # dygraph draws each plot on two canvases
        fail("%d canvases for %d plots" % (canvases, plots))

    shot = shot or out + "_screenshot.png"
    with tempfile.TemporaryDirectory() as profile:
        chromium(browser, ["--virtual-time-budget=30000", "--window-size=1400,1800",
                           "--screenshot=" + os.path.abspath(shot), url], profile)
    want = (0x1F, 0x3F, 0x77) if kind == "run" else (0x00, 0x80, 0x80)
    w, h, frac, ncol, near = pixel_stats(oiiotool, shot, want)
    print("screenshot %dx%d: %.1f %% non-white, %d colours, %d pixels near the trace colour"
          % (w, h, frac * 100, ncol, near))
    if frac < 0.03 or ncol < 40:
        fail("the screenshot looks blank")
    if kind == "run" and near < 500:
        fail("the waveform trace is not on the screenshot")
    print("ok")


if __name__ == "__main__":
    main()
