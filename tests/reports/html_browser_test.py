#!/usr/bin/env python3
"""report.html in a real browser: Debian's chromium, headless, loads the page offline.

  html_browser_test.py CHROMIUM OIIOTOOL OUT_DIR [--max-mb 8] [--screenshot FILE] -- ISOLINK ARGS...

Runs `ISOLINK ARGS... -o OUT_DIR` (run, sweep, pack or stress; OUT_DIR is removed first), then checks
OUT_DIR/report.html (the screenshot goes to OUT_DIR_screenshot.png unless --screenshot says):
- the file names no network address of any kind and is under --max-mb megabytes;
- chromium (no network: --disable-background-networking and friends, and the page has nothing to
  fetch) loads it, and within the virtual-time budget the script sets data-ready="1" on <body>;
- the verdict the page shows (#verdict) is the verdict of report.json (run, pack; stress: PASS
  when it survives and communicates, as its exit status) or of the
  points in results.csv (sweep: PASS only when every point passes);
- every plot drew: one dygraph canvas per waveform / margin plot;
- a screenshot is not blank: enough non-white pixels, many colours, and the waveform trace's own
  colour (#1f3f77) or the margin plot's present;
- with real mouse events (DevTools protocol on a pipe, cdp_pipe.py): a run's waveform, on the first
  screen, dragged down to a 500 ns window (two pulses; a long record a twentieth of the view at a
  time, each drag answered within 20 s), shows every sample in it (full resolution) where the
  whole record was min/max decimated; a sweep's margin plot, hovered on a point, names that cell's points with their
  verdicts from results.csv and plots their worst margin, and a click highlights their rows.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cdp_pipe  # noqa: E402

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


# The dygraph, its data and where a data point lies on the page, evaluated in the page.
PLOT_JS = "(() => { const p = isolinkPlots.find(p => p.kind === %r); return p ? (%s) : null; })()"


def check_wave_zoom(b):
    """Drag-zoom the first waveform to 500 ns: every sample of the record inside it is plotted."""
    g = "p.graph"
    before = b.eval(PLOT_JS % ("wave", "{rows: %s.numRows(), samples: p.time.length, "
                                       "t0: p.time[0], t1: p.time[p.time.length - 1]}" % g))
    if before is None:
        fail("no waveform plot registered in isolinkPlots")
    if before["samples"] > 4000 and before["rows"] > 4100:
        fail("whole record: %d rows for %d samples (no min/max decimation)"
             % (before["rows"], before["samples"]))
    # The zoom's start: 100 ns before the first pulse from 30 % of the record on (where the samples
    # come closer than 5 ns: a long record is mostly idle between its frames).
    a = b.eval(PLOT_JS % ("wave", "(() => { const t = p.time, from = t[0] + 0.3 * (t[t.length - 1] - t[0]);"
                                  " let i = t.findIndex(x => x >= from);"
                                  " while (i + 1 < t.length && t[i + 1] - t[i] > 5e-9) ++i;"
                                  " return t[i] - 100e-9; })()"))
    b.eval("window.scrollTo(0, 0)")
    # As a reviewer zooms: drags each to about a twentieth of the view until one is 500 ns
    # (dygraph ignores drags under 10 pixels, which 500 ns of a long record is), each answered
    # within 20 s (the page stays responsive on a 200 ms record) before the next.
    # The waveform is on the first screen: nothing above it (a long record's decoded bytes or
    # traffic) pushes it down the page.
    top = b.eval(PLOT_JS % ("wave", "{top: p.graph.graphDiv.getBoundingClientRect().top,"
                                    " screen: window.innerHeight}"))
    if top["top"] > top["screen"]:
        fail("the waveform starts %d px down the page, below the first screen (%d px)"
             % (top["top"], top["screen"]))
    width = ("(() => { const r = %s.xAxisRange(); return r[1] - r[0]; })()" % g)
    view = before["t1"] - before["t0"]
    while True:
        step = max(500e-9, view / 20)
        pos = b.eval(PLOT_JS % ("wave", "(() => { const g = p.graph, r = g.graphDiv.getBoundingClientRect(),"
                                        " ar = g.getArea(); return {xa: r.left + g.toDomXCoord(%r),"
                                        " xz: r.left + g.toDomXCoord(%r), y: r.top + ar.y + ar.h / 2}; })()"
                                % (a, a + step)))
        b.drag(pos["xa"], pos["y"], pos["xz"], pos["y"])
        if not b.wait_for(PLOT_JS % ("wave", width) + " < %r" % (0.5 * view), timeout=20):
            fail("a drag from %.4g s over %.3g s was not answered within 20 s (view still %.3g s)"
                 % (a, step, b.eval(PLOT_JS % ("wave", width))))
        view = b.eval(PLOT_JS % ("wave", width))
        time.sleep(0.3)  # the rebuild after a zoom runs from a timer
        if step == 500e-9:
            break
    count = ("(() => { const g = p.graph, r = g.xAxisRange(); let rows = 0, samples = 0;"
             " for (let i = 0; i < g.numRows(); ++i) { const x = g.getValue(i, 0);"
             " if (x >= r[0] && x <= r[1]) ++rows; }"
             " for (const x of p.time) if (x >= r[0] && x <= r[1]) ++samples;"
             " return {lo: r[0], hi: r[1], rows: rows, samples: samples}; })()")
    ok = b.wait_for(PLOT_JS % ("wave", count) + ".rows === " + PLOT_JS % ("wave", count) +
                    ".samples", timeout=20)
    after = b.eval(PLOT_JS % ("wave", count))
    span = after["hi"] - after["lo"]
    if not 400e-9 < span < 600e-9:
        fail("the drag over 500 ns zoomed to %.3g s" % span)
    # Two pulses need at least their eight corners, in any thinning the page chose (a 200 ms
    # record keeps its samples within 20 mV: 9 of them over two pulses).
    if not ok or after["rows"] < 8:
        fail("zoomed to %.3g s: %d rows plotted for %d samples" % (span, after["rows"],
                                                                  after["samples"]))
    print("zoom: whole record %d rows for %d samples; dragged to %.3g ns: %d of %d samples"
          % (before["rows"], before["samples"], span * 1e9, after["rows"], after["samples"]))


def check_sweep_hover_click(b, out):
    """Hover a margin-plot point: it names its cell's points and verdicts; a click marks the rows.

    The point's x is placed with toPercentXCoord: dygraph 2.2.1's toDomXCoord ignores a log axis."""
    with open(os.path.join(out, "results.csv")) as f:
        rows = sorted(csv.DictReader(f), key=lambda r: int(r["point"]))  # written as they finish
    pick = b.eval(PLOT_JS % ("margin", "(() => { const g = p.graph, n = g.numRows(),"
                                       " ns = g.getLabels().length - 1, row = Math.min(2, n - 1),"
                                       " col = Math.min(3, ns), x = g.getValue(row, 0),"
                                       " y = g.getValue(row, col), r = g.graphDiv.getBoundingClientRect(),"
                                       " ar = g.getArea(); return {px: r.left + ar.x + g.toPercentXCoord(x) * ar.w,"
                                       " py: r.top + g.toDomYCoord(y), x: x, y: y, col: col,"
                                       " labels: g.getLabels()}; })()"))
    if pick is None:
        fail("no margin plot registered in isolinkPlots")
    x_key = pick["labels"][0]
    cell = [r for r in rows if abs(float(r[x_key]) - pick["x"]) <= 1e-9 * abs(pick["x"])]
    series = pick["labels"][pick["col"]]
    if " = " in series:  # one line per value of the second axis, in the sweep's order
        s_key = series.split(" = ")[0]
        values = list(dict.fromkeys(r[s_key] for r in rows))
        cell = [r for r in cell if r[s_key] == values[pick["col"] - 1]]
    if not cell:
        fail("no results.csv row at %s = %g" % (x_key, pick["x"]))
    margins = [float(r["worst_margin_rel"]) for r in cell if r["worst_margin_rel"]]
    if margins and abs(min(margins) * 100 - pick["y"]) > 1e-4:
        fail("the plot shows %g %% where results.csv's worst is %g %%" % (pick["y"], min(margins) * 100))
    b.eval("window.scrollTo(0, 0)")
    b.mouse("mouseMoved", pick["px"], pick["py"])
    want = ["point %s:" % r["point"] for r in cell]
    info_js = "document.getElementById('point-info').textContent"
    if not b.wait_for(" && ".join("%s.includes(%r)" % (info_js, w) for w in want), timeout=10):
        fail("hovering %s = %g shows %r, expected %s" % (x_key, pick["x"], b.eval(info_js), want))
    info = b.eval(info_js)
    for r in cell:
        line = next(l for l in info.split("\n") if l.startswith("point %s:" % r["point"]))
        if r["verdict"].upper() not in line:
            fail("hover line %r does not say %s" % (line, r["verdict"].upper()))
    b.click(pick["px"], pick["py"])
    marked = "Array.from(document.querySelectorAll('tr.hl')).map(t => t.id).sort().join(',')"
    expect = ",".join(sorted("point-" + r["point"] for r in cell))
    if not b.wait_for("%s === %r" % (marked, expect), timeout=10):
        fail("a click marked rows %r, expected %r" % (b.eval(marked), expect))
    print("hover on %s = %g: %s; click marked %s" % (x_key, pick["x"], info.replace("\n", " | "),
                                                     expect))


def interact(browser, url, kind, out):
    with tempfile.TemporaryDirectory() as profile:
        with cdp_pipe.Browser(browser, CHROMIUM_FLAGS, url, profile) as b:
            if not b.wait_for("document.body && document.body.dataset.ready === '1'", timeout=90):
                fail("data-ready never became 1 under the DevTools pipe")
            if kind == "run":
                check_wave_zoom(b)
            elif kind == "sweep":
                check_sweep_hover_click(b, out)


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
    elif kind == "stress":  # the badge is the exit status's verdict: pass when nothing broke
        report = json.load(open(os.path.join(out, "report.json")))
        expected = "PASS" if report["survives"] and report["communicates"] else "FAIL"
        plots = len(report["scenarios"])  # one pin plot per scenario
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

    if kind in ("run", "sweep") and (plots or kind == "sweep"):
        interact(browser, url, kind, out)

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
