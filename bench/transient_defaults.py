#!/usr/bin/env python3
"""The transient engine at its defaults against a converged reference (issue 41, item 3: "the
transient's defaults within 10 mV of a converged reference on every link").

    python3 bench/transient_defaults.py [ISOLINK] [SEED] [FIRST] [COUNT] [TSTOP]
    (defaults: build/cli/isolink 7 0 14 20u)

For specs FIRST..FIRST+COUNT-1 of the random link corpus (tools/link_corpus.py, drawn with SEED:
links none of the examples are), the exported netlist (down direction) through:
- `isolink sim --engine transient` at its defaults: reltol 1e-3, then its own check
  (analysis/transient_check.h: rerun tighter until two runs agree within 5 mV);
- the reference, twice: `--reltol 1e-6` with trapezoidal and with Gear-2 steps. Two methods that
  agree within a fraction of a millivolt make the reference converged.
Prints one table row per link (wall time of each run, max |v(rxp,rxn) - reference| over the
reference's rows, the defaults' run linearly interpolated) and exits 1 if the defaults are more
than 10 mV off on any link.
"""
import bisect
import csv
import os
import subprocess
import sys
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
isolink = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "build",
                                                                             "cli", "isolink"))
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 7
first = int(sys.argv[3]) if len(sys.argv) > 3 else 0
count = int(sys.argv[4]) if len(sys.argv) > 4 else 14
tstop = sys.argv[5] if len(sys.argv) > 5 else "20u"
LIMIT_MV = 10.0


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return [float(r[0]) for r in rows[1:]], [float(r[1]) for r in rows[1:]]


def deviation(ref, other):
    """max |other - ref| over ref's rows inside other's span, other interpolated linearly."""
    (ta, va), (tb, vb) = ref, other
    worst = 0.0
    for t, v in zip(ta, va):
        j = bisect.bisect_right(tb, t) - 1
        if j < 0 or j + 1 >= len(tb):
            continue
        f = (t - tb[j]) / (tb[j + 1] - tb[j])
        worst = max(worst, abs(vb[j] + f * (vb[j + 1] - vb[j]) - v))
    return worst


def sim(cir, out, *args):
    start = time.monotonic()
    r = subprocess.run([isolink, "sim", cir, "-p", "v(rxp,rxn)", "-o", out, "--tstop", tstop,
                        "--engine", "transient", *args], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("isolink sim %s %s: %s" % (cir, " ".join(args), r.stderr.strip()))
    return load(out), time.monotonic() - start, r.stderr


with tempfile.TemporaryDirectory() as work:
    subprocess.run([sys.executable, os.path.join(here, "..", "tools", "link_corpus.py"), "--seed",
                    str(seed), "--first", str(first), "--count", str(count), "--out", work],
                   check=True)
    print("| spec | length (m) | tx / rx isolation | unknowns | defaults s | defaults' final reltol "
          "| reference (trap) s | reference (gear) s | trap - gear (mV) | defaults - reference (mV) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    worst_all, failures = 0.0, []
    for i in range(first, first + count):
        spec = os.path.join(work, "link_%03d.yaml" % i)
        text = open(spec).read()
        length = text.split("length: ")[1].split(",")[0].split("}")[0]
        iso = [l.split("type: ")[1].split(",")[0].split("}")[0]
               for l in text.splitlines() if l.startswith(("tx:", "rx:")) and "type: " in l]
        cir = os.path.join(work, "link_%03d.cir" % i)
        subprocess.run([isolink, "export-spice", spec, "--direction", "down", "-o", cir],
                       check=True, capture_output=True)
        d, t_d, err = sim(cir, cir + ".d.csv")
        unknowns = int(err.split(" unknowns")[0].split()[-1])
        # "checked by tightening: reltol 0.001 -> 0.0001 and ...": the last reltol is the kept one.
        reltol = err.split("reltol ")[1].split(" and")[0].split("->")[-1].strip() \
            if "tightening: reltol " in err else "?"
        trap, t_trap, _ = sim(cir, cir + ".trap.csv", "--reltol", "1e-6", "--method", "trap")
        gear, t_gear, _ = sim(cir, cir + ".gear.csv", "--reltol", "1e-6", "--method", "gear")
        ref_spread = deviation(trap, gear)
        dev = deviation(trap, d)
        worst_all = max(worst_all, dev)
        if dev * 1e3 > LIMIT_MV:
            failures.append("link_%03d: %.2f mV" % (i, dev * 1e3))
        print("| link_%03d | %s | %s | %d | %.1f | %s | %.1f | %.1f | %.2f | %.2f |"
              % (i, length, " / ".join(iso) or "?", unknowns, t_d, reltol, t_trap, t_gear,
                 ref_spread * 1e3, dev * 1e3), flush=True)
    print("worst: %.2f mV over %d links (limit %g mV)%s" % (
        worst_all * 1e3, count, LIMIT_MV, "; FAIL " + ", ".join(failures) if failures else ""))
    sys.exit(1 if failures else 0)
