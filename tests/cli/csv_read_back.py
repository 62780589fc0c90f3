#!/usr/bin/env python3
"""Every CSV file isolink writes reads back with Python's csv module as written (RFC 4180).

    python3 csv_read_back.py ISOLINK_BINARY EXAMPLES_DIR WORK_DIR

Runs `isolink sim` (two probes with commas in their names), `isolink run` (wave.csv: per-direction
probe names), `isolink check --pulses-csv` (fails/warnings lists), `isolink sweep` (results.csv) and
`isolink sweep --list` (a list value, with a comma), reads each output with csv.reader and checks
the header names exactly, that every row has as many fields as the header, and that the numeric
columns hold finite numbers. Exit status 0 when all hold, 1 otherwise (messages name the file).
"""
import csv
import io
import math
import os
import subprocess
import sys

isolink, examples, work = (os.path.abspath(a) for a in sys.argv[1:4])
os.makedirs(work, exist_ok=True)
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
    return cond


def run(*args):
    p = subprocess.run([isolink, *args], capture_output=True, text=True)
    check(p.returncode in (0, 1), f"isolink {' '.join(args)}: exit {p.returncode}: {p.stderr}")
    return p.stdout


def read(path_or_text, is_text=False):
    if not is_text and not os.path.exists(path_or_text):
        check(False, f"{path_or_text}: not written")
        return [[]]
    f = io.StringIO(path_or_text) if is_text else open(path_or_text, newline="")
    rows = list(csv.reader(f))
    check(len(rows) >= 2, f"{path_or_text if not is_text else 'stdout'}: fewer than 2 rows")
    return rows


def same_width(name, rows):
    bad = [i for i, r in enumerate(rows) if len(r) != len(rows[0])]
    check(not bad, f"{name}: rows {bad[:5]} have another field count than the header's "
          f"{len(rows[0])} ({rows[bad[0]] if bad else ''})")


def finite(name, rows, cols):
    for i, r in enumerate(rows[1:], start=2):
        for c in cols:
            try:
                ok = math.isfinite(float(r[c]))
            except (ValueError, IndexError):
                ok = False
            if not check(ok, f"{name}:{i}: column {c} is not a finite number: {r}"):
                return


# isolink sim: probe names with commas, quoted in the header.
sim = os.path.join(work, "sim.csv")
run("sim", os.path.join(examples, "cap_link_2m.cir"), "-p", "v(rxp,rxn)", "-p", "v(rxp)",
    "-o", sim, "-q")
rows = read(sim)
check(rows[0] == ["time", "v(rxp,rxn)", "v(rxp)"], f"{sim}: header {rows[0]}")
same_width(sim, rows)
finite(sim, rows, range(3))

# isolink run: wave.csv, every direction's probes on one time axis.
bundle = os.path.join(work, "run")
run("run", os.path.join(examples, "cap_2m.yaml"), "-o", bundle, "-q", "--no-worst")
wave = os.path.join(bundle, "wave.csv")
rows = read(wave)
want = ["time"] + [f"{d} {p}" for d in ("down", "up")
                   for p in ("v(rxp,rxn)", "v(rxp)", "v(rxn)", "v(txp,txn)")]
check(rows[0] == want, f"{wave}: header {rows[0]}, expected {want}")
same_width(wave, rows)
finite(wave, rows, range(len(rows[0])))

# isolink check --pulses-csv: one row per pulse; fails and warnings are lists in one field.
pulses = os.path.join(work, "pulses.csv")
run("check", sim, "--diff", "v(rxp,rxn)", "--pulses-csv", pulses)
rows = read(pulses)
check(rows[0][:4] == ["index", "sign", "start_s", "end_s"], f"{pulses}: header {rows[0]}")
same_width(pulses, rows)
finite(pulses, rows, (0, 1, 2, 3))

# isolink sweep: results.csv, and --list with a list-valued key (its cell has a comma).
sweep_file = os.path.join(work, "sweep.yaml")
with open(sweep_file, "w") as f:
    f.write(f"name: csv-check\nbase: {os.path.join(examples, 'cap_2m.yaml')}\n"
            "sweep:\n  cable.length: [1, 2]\n  stimulus.direction: down\n")
out = os.path.join(work, "sweep")
run("sweep", sweep_file, "-o", out, "-j", "2", "--no-plots", "-q")
results = os.path.join(out, "results.csv")
rows = read(results)
check(rows[0][:2] == ["point", "cable.length"], f"{results}: header {rows[0]}")
check(len(rows) == 3, f"{results}: {len(rows) - 1} points, expected 2")
same_width(results, rows)
frames = '["stack-write reg=0x0100 data=02B778BC", "stack-write reg=0x0100 data=02"]'
with open(sweep_file, "w") as f:
    f.write(f"name: csv-list\nbase: {os.path.join(examples, 'cap_2m.yaml')}\n"
            f"sweep:\n  cable.length: [2]\n  stimulus.frames: [{frames}]\n")
rows = read(run("sweep", sweep_file, "--list"), is_text=True)
check(rows[0] == ["point", "cable.length", "stimulus.frames", "spec"],
      f"sweep --list: header {rows[0]}")
same_width("sweep --list", rows)
check(len(rows) == 2 and rows[1][2] ==
      "[stack-write reg=0x0100 data=02B778BC, stack-write reg=0x0100 data=02]",
      f"sweep --list: the frames cell (a list, with a comma) came back as {rows[1:]}")

for m in failures:
    print("error: " + m, file=sys.stderr)
print(f"csv_read_back: {len(failures)} problem(s)")
sys.exit(1 if failures else 0)
