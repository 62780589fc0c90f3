#!/usr/bin/env python3
"""The random link corpus (tools/link_corpus.py) on the LTI engine's reduced model (issue 28).

    python3 lti_corpus_test.py ISOLINK_BINARY SOURCE_DIR WORK_DIR SEED FIRST COUNT TOL_MV [TSTOP]

For specs FIRST..FIRST+COUNT-1 of the corpus drawn with SEED, in both directions: the exported
netlist through `isolink sim --engine lti` must take the reduced model (no march: its stderr says
"LTI engine, reduced model"), and its v(rxp,rxn) must agree with `isolink sim --engine transient
--reltol 1e-6` within TOL_MV at every LTI row (the transient's rows, its accepted steps at
reltol 1e-6, linearly interpolated between). With TSTOP (e.g. 20u) both runs stop there
(`--tstop`): the first frame and its ringing, at a fraction of the reference's cost (the
transient's steps grow with the time simulated, the reduced model's cost does not).
Exit 0 when every direction passes, 1 otherwise (each failure named).
"""
import bisect
import csv
import os
import subprocess
import sys
import time

isolink, source, work = (os.path.abspath(a) for a in sys.argv[1:4])
seed, first, count, tol_mv = int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6]), float(sys.argv[7])
window = ["--tstop", sys.argv[8]] if len(sys.argv) > 8 else []
os.makedirs(work, exist_ok=True)
subprocess.run([sys.executable, os.path.join(source, "tools", "link_corpus.py"), "--seed",
                str(seed), "--first", str(first), "--count", str(count), "--out", work], check=True)


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return [float(r[0]) for r in rows[1:]], [float(r[1]) for r in rows[1:]]


def sim(netlist, out, *args):
    start = time.monotonic()
    r = subprocess.run([isolink, "sim", netlist, "-p", "v(rxp,rxn)", "-o", out, *window, *args],
                       capture_output=True, text=True)
    return r, time.monotonic() - start


failures = []
for i in range(first, first + count):
    spec = os.path.join(work, "link_%03d.yaml" % i)
    with open(spec) as f:
        length = next(l for l in f if l.startswith("cable:")).split("length: ")[1].split(",")[0]
    for d in ("down", "up"):
        name = "link_%03d %s (%s m)" % (i, d, length)
        cir = os.path.join(work, "link_%03d_%s.cir" % (i, d))
        subprocess.run([isolink, "export-spice", spec, "--direction", d, "-o", cir], check=True,
                       capture_output=True)
        lti, t_lti = sim(cir, cir + ".lti.csv", "--engine", "lti")
        if lti.returncode != 0 or "LTI engine, reduced model" not in lti.stderr:
            failures.append("%s: not the reduced model: %s" % (name, lti.stderr.strip()))
            continue
        tr, t_tr = sim(cir, cir + ".tr.csv", "--engine", "transient", "--reltol", "1e-6")
        if tr.returncode != 0:
            failures.append("%s: transient failed: %s" % (name, tr.stderr.strip()))
            continue
        ta, va = load(cir + ".lti.csv")
        tb, vb = load(cir + ".tr.csv")
        worst, at = 0.0, 0.0
        for t, v in zip(ta, va):
            j = bisect.bisect_right(tb, t) - 1
            if j < 0 or j + 1 >= len(tb):
                continue
            f = (t - tb[j]) / (tb[j + 1] - tb[j])
            dev = abs(vb[j] + f * (vb[j + 1] - vb[j]) - v)
            if dev > worst:
                worst, at = dev, t
        print("%s: reduced model %.2f s, transient %.2f s, max |LTI - transient| %.3f mV at %.4g s"
              % (name, t_lti, t_tr, 1e3 * worst, at), flush=True)
        if not worst * 1e3 <= tol_mv:
            failures.append("%s: %.3f mV from the transient at %.4g s, over %g mV"
                            % (name, 1e3 * worst, at, tol_mv))
for f in failures:
    print("FAIL " + f)
sys.exit(1 if failures else 0)
