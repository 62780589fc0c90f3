#!/usr/bin/env python3
"""isolink at its defaults against a converged reference on the random link corpus (issue 41).

    python3 bench/corpus_reference.py MODE [ISOLINK] [SEED] [FIRST] [COUNT] [TSTOP] [MAX_LENGTH]
                                      [MIN_LENGTH]
    (defaults: build/cli/isolink 7 0 14 20u, every length; MAX_LENGTH and MIN_LENGTH in m skip
    longer and shorter cables; TSTOP `full` runs the netlist's own .tran, the whole frame)

MODE:
- `defaults` (item 3, "the transient's defaults within 10 mV of a converged reference on every
  link"): `isolink sim --engine transient` at its defaults: reltol 1e-3, then its own check
  (analysis/transient_check.h: rerun tighter until two runs agree within 5 mV);
- `nonlinear` (item 3, "every nonlinear link within 3 mV of a converged reference"): each end
  given a TVS part of the library (`esd:`, in turn PESD2CAN, ESD24VS2U, ESDCAN24-2BLY) and its
  pins' clamps (`pin_clamps: rails`), then `isolink sim` at its defaults (auto: the port model,
  its fallback the transient).
- `nonlinear-speed` (item 4, "at least 10x ngspice's default time on every nonlinear link of 3 m
  or more"): the links of `nonlinear`, `isolink sim` at its defaults and ngspice at its defaults
  (`ngspice -b`, `.options rshunt=1e12` as bench/speed_corpus.sh, `wrdata` of v(rxp,rxn)), each
  timed once with process start; the reference is the port model at reltol 1e-6 and 1e-7 with
  0.25 ns steps at most (two tolerances that agree: the full transient at 1e-6 does not finish in
  minutes on these links; the port model's linear network is checked against the exact AC
  solution, its check printed by isolink), and both runs' deviations from it are printed.
- `nonlinear-time`: the timing of `nonlinear-speed` without its reference (which takes hours
  on the 20-100 m links): isolink at its defaults best of 3 (each run's wall time with process
  start), ngspice at its defaults once, one link after the other; also the port model's size
  and its build time as isolink prints them. No deviation, no limit.
For specs FIRST..FIRST+COUNT-1 of the random link corpus (tools/link_corpus.py, drawn with SEED:
links none of the examples are), the exported netlist (down direction) through that run and the
reference, twice: `--engine transient --reltol 1e-6` with trapezoidal and with Gear-2 steps (two
methods that agree within a fraction of a millivolt make the reference converged).
Prints one table row per link (wall time of each run, max |v(rxp,rxn) - reference| over the
reference's rows, the other run linearly interpolated) and exits 1 if a run is more than the
mode's limit (10 mV, 3 mV) off on any link.
"""
import bisect
import csv
import os
import subprocess
import sys
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
args = sys.argv[1:]
mode = args.pop(0) if args else ""
if mode not in ("defaults", "nonlinear", "nonlinear-speed", "nonlinear-time"):
    sys.exit(__doc__)
isolink = os.path.abspath(args[0] if len(args) > 0 else os.path.join(here, "..", "build", "cli",
                                                                     "isolink"))
seed = int(args[1]) if len(args) > 1 else 7
first = int(args[2]) if len(args) > 2 else 0
count = int(args[3]) if len(args) > 3 else 14
tstop = args[4] if len(args) > 4 else "20u"
max_length = float(args[5]) if len(args) > 5 else float("inf")
min_length = float(args[6]) if len(args) > 6 else 0.0
LIMIT_MV = 10.0 if mode == "defaults" else 3.0
TVS = ["PESD2CAN", "ESD24VS2U", "ESDCAN24-2BLY"]


def make_nonlinear(text, i):
    """Each end's isolation gets a TVS part (esd:) and the end its pins' clamps."""
    out = []
    for k, line in enumerate(text.splitlines()):
        if line.startswith(("tx:", "rx:")) and "isolation: {" in line:
            head, rest = line.split("isolation: {", 1)
            body, tail = rest.split("}", 1)
            tvs = TVS[(2 * i + k) % len(TVS)]
            line = "%sisolation: {%s, esd: %s}, pin_clamps: rails%s" % (head, body, tvs, tail)
        out.append(line)
    return "\n".join(out) + "\n"


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
    span = [] if tstop == "full" else ["--tstop", tstop]
    r = subprocess.run([isolink, "sim", cir, "-p", "v(rxp,rxn)", "-o", out, *span, *args],
                       capture_output=True, text=True)
    seconds = time.monotonic() - start  # the run alone, not the reading of its rows below
    if r.returncode != 0:
        sys.exit("isolink sim %s %s: %s" % (cir, " ".join(args), r.stderr.strip()))
    return load(out), seconds, r.stderr


def ngspice(cir, out):
    """ngspice at its defaults on the netlist (its .tran span cut to TSTOP): (rows, seconds)."""
    lines = [l for l in open(cir).read().splitlines() if l.strip().lower() != ".end"]
    if tstop != "full":
        lines = [" ".join(l.split()[:2] + [tstop]) if l.lower().startswith(".tran") else l
                 for l in lines]
    lines += [".options rshunt=1e12", ".control", "set wr_singlescale", "run",
              "wrdata %s v(rxp,rxn)" % out, ".endc", ".end"]
    with open(cir + ".ng.cir", "w") as f:
        f.write("\n".join(lines) + "\n")
    start = time.monotonic()
    subprocess.run(["ngspice", "-b", cir + ".ng.cir"], capture_output=True, text=True)
    seconds = time.monotonic() - start
    rows = [l.split() for l in open(out) if l.strip()]
    return ([float(r[0]) for r in rows], [float(r[1]) for r in rows]), seconds


def time_row(i, cir, length, iso):
    """nonlinear-time: one table row (isolink best of 3, ngspice once)."""
    runs = [sim(cir, cir + ".d.csv") for _ in range(3)]
    err = runs[0][2]
    unknowns = int(err.split(" unknowns")[0].split()[-1])
    model = err.split("; model ")[1].split(" s")[0] if "; model " in err else "-"
    modes = err.split(" modes (order ")[0].split()[-1] if " modes (order " in err else "-"
    order = err.split(" modes (order ")[1].split(",")[0] if " modes (order " in err else "-"
    steps = err.split(" steps accepted")[0].split()[-1] if " steps accepted" in err else "-"
    best = min(r[1] for r in runs)
    _, t_ng = ngspice(cir, cir + ".ng.txt")
    print("| link_%03d | %s | %s | %d | %s / %s | %s | %s | %.2f | %.2f | %.1f |"
          % (i, length, " / ".join(iso), unknowns, modes, order, model, steps, best, t_ng,
             t_ng / best), flush=True)


def speed_row(i, cir, length, iso):
    """nonlinear-speed: one table row; returns isolink's deviation (V)."""
    d, t_d, err = sim(cir, cir + ".d.csv")
    unknowns = int(err.split(" unknowns")[0].split()[-1])
    ng, t_ng = ngspice(cir, cir + ".ng.txt")
    ref = ["--engine", "port", "--tmax", "2.5e-10", "--reltol"]
    fine, t_fine, _ = sim(cir, cir + ".r7.csv", *ref, "1e-7")
    coarse, _, _ = sim(cir, cir + ".r6.csv", *ref, "1e-6")
    dev, ng_dev = deviation(fine, d), deviation(fine, ng)
    print("| link_%03d | %s | %s | %d | %.2f | %.2f | %.1f | %.2f | %.2f | %.3f | %.1f |"
          % (i, length, " / ".join(iso), unknowns, t_d, t_ng, t_ng / t_d, dev * 1e3,
             ng_dev * 1e3, deviation(fine, coarse) * 1e3, t_fine), flush=True)
    return dev


with tempfile.TemporaryDirectory() as work:
    subprocess.run([sys.executable, os.path.join(here, "..", "tools", "link_corpus.py"), "--seed",
                    str(seed), "--first", str(first), "--count", str(count), "--out", work],
                   check=True)
    if mode == "nonlinear-time":
        print("| spec | length (m) | tx / rx isolation | unknowns | modes / order | model s | "
              "steps (kept run) | isolink s | ngspice s | ngspice / isolink |")
        print("|---|---|---|---|---|---|---|---|---|---|")
    elif mode == "nonlinear-speed":
        print("| spec | length (m) | tx / rx isolation | unknowns | isolink s | ngspice s | ngspice / "
              "isolink | isolink - reference (mV) | ngspice - reference (mV) | reference 1e-6 - 1e-7 "
              "(mV) | reference s |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
    else:
        print("| spec | length (m) | tx / rx isolation | unknowns | defaults s | engine, final "
              "reltol | reference (trap) s | reference (gear) s | trap - gear (mV) | defaults - "
              "reference (mV) |")
        print("|---|---|---|---|---|---|---|---|---|---|")
    worst_all, failures = 0.0, []
    for i in range(first, first + count):
        spec = os.path.join(work, "link_%03d.yaml" % i)
        text = open(spec).read()
        if mode != "defaults":
            text = make_nonlinear(text, i)
            with open(spec, "w") as f:
                f.write(text)
        length = text.split("length: ")[1].split(",")[0].split("}")[0]
        if not min_length <= float(length) <= max_length:
            continue
        iso = [l.split("type: ")[1].split(",")[0].split("}")[0]
               for l in text.splitlines() if l.startswith(("tx:", "rx:")) and "type: " in l]
        cir = os.path.join(work, "link_%03d.cir" % i)
        subprocess.run([isolink, "export-spice", spec, "--direction", "down", "-o", cir],
                       check=True, capture_output=True)
        if mode == "nonlinear-time":
            time_row(i, cir, length, iso)
            continue
        if mode == "nonlinear-speed":
            dev = speed_row(i, cir, length, iso)
            worst_all = max(worst_all, dev)
            if dev * 1e3 > LIMIT_MV:
                failures.append("link_%03d: %.2f mV" % (i, dev * 1e3))
            continue
        d, t_d, err = sim(cir, cir + ".d.csv", *(["--engine", "transient"] if mode == "defaults"
                                                 else []))
        unknowns = int(err.split(" unknowns")[0].split()[-1])
        first_line = err.split("isolink sim: ")[1]
        engine = first_line.split(" engine")[0] if " engine" in first_line.split(":")[0] \
            else "transient"
        # "checked by tightening: reltol 0.001 -> 0.0001 and ...": the last reltol is the kept one.
        reltol = err.split("tightening: reltol ")[1].split(" and")[0].split("->")[-1].strip() \
            if "tightening: reltol " in err else "-"
        ref = ["--engine", "transient", "--reltol", "1e-6", "--method"]
        trap, t_trap, _ = sim(cir, cir + ".trap.csv", *ref, "trap")
        gear, t_gear, _ = sim(cir, cir + ".gear.csv", *ref, "gear")
        ref_spread = deviation(trap, gear)
        dev = deviation(trap, d)
        worst_all = max(worst_all, dev)
        if dev * 1e3 > LIMIT_MV:
            failures.append("link_%03d: %.2f mV" % (i, dev * 1e3))
        print("| link_%03d | %s | %s | %d | %.1f | %s, %s | %.1f | %.1f | %.2f | %.2f |"
              % (i, length, " / ".join(iso) or "?", unknowns, t_d, engine, reltol, t_trap, t_gear,
                 ref_spread * 1e3, dev * 1e3), flush=True)
    if mode == "nonlinear-time":
        sys.exit(0)
    print("worst: %.2f mV over the links above (limit %g mV)%s" % (
        worst_all * 1e3, LIMIT_MV, "; FAIL " + ", ".join(failures) if failures else ""))
    sys.exit(1 if failures else 0)
