"""A notebook session as a script: a capacitor-isolated link varied over cable length, then every
isolink function on specs given as dicts (nothing written to YAML files by hand).

    /usr/bin/python3 python/examples/notebook_loop.py                  # prints the tables
    /usr/bin/python3 python/examples/notebook_loop.py --plot margins.png   # + the margin plot
    /usr/bin/python3 python/examples/notebook_loop.py --check-cli /usr/local/bin/isolink

--check-cli runs the isolink executable on the same specs (each dict written to a temporary
file; JSON is YAML) and exits 1 unless every function's result equals the CLI's JSON (numbers
to 1e-9 relative, wall times aside). CTest's python.install runs it that way from an installed
prefix (python/tests/install_test.sh); python/README.md shows the loop.
"""
import argparse
import copy
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import isolink

# The link as a dict with the YAML's structure: BQ79600 bridge to a BQ7961x, 2.2 nF caps at both
# ends, 24 AWG PP pair; one byte sent down keeps each run about a second.
BASE = {
    "name": "notebook",
    "tx": {"device": "bq79600", "isolation": {"type": "cap", "cap": "2.2n"}},
    "rx": {"device": "bq7961x", "isolation": {"type": "cap", "cap": 2.2e-9}},
    "cable": {"length": 1, "material": "pp", "gauge": 24},
    "stimulus": {"frames": ["raw 5A nocrc"], "direction": "down"},
}
LENGTHS = [1, 5, 10, 20]  # m


def with_length(spec, length):
    s = copy.deepcopy(spec)
    s["cable"]["length"] = length
    return s


def margin_loop():
    """The notebook's loop: VSTART and VEND margins (V) of the received signal per length."""
    rows = []
    for length in LENGTHS:
        r = isolink.run(with_length(BASE, length))
        worst = r["directions"][0]["check"]["summary"]["worst"]
        rows.append((length, r["verdict"], worst["vstart"]["margin"], worst["vend"]["margin"]))
    print(f"{'length (m)':>10}  {'verdict':7}  {'VSTART margin (V)':>17}  {'VEND margin (V)':>15}")
    for length, verdict, vstart, vend in rows:
        print(f"{length:>10}  {verdict:7}  {vstart:>17.3f}  {vend:>15.3f}")
    return rows


def plot(rows, path):
    """The margins over length (Debian: python3-matplotlib)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    lengths = [r[0] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(lengths, [r[2] for r in rows], "o-", label="VSTART margin")
    ax.plot(lengths, [r[3] for r in rows], "s-", label="VEND margin")
    ax.axhline(0, color="red", lw=0.8)
    ax.set_xlabel("cable length (m)")
    ax.set_ylabel("margin (V)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print(f"plot: {path}")


# A small netlist for sim(): a 1 V step through 100 ohm into 1 nF (tau = 100 ns).
RC_NETLIST = """* RC step
V1 in 0 PULSE(0 1 10n 1n 1n 1u 2u)
R1 in out 100
C1 out 0 1n
.tran 1n 600n
.end
"""

# A sweep and a pack, as dicts around the same link.
SWEEP = {"name": "nb-sweep", "base": BASE, "sweep": {"cable.length": [1, 3]}}
PACK = {
    "name": "nb-pack",
    "stimulus": {"frames": ["raw 5A nocrc"]},
    "hops": [{"spec": BASE}, {"spec": BASE, "cable": {"length": 0.3},
                              "tx": {"device": "bq7961x"}}],
}
# The noise analysis over a narrow band (a few points keep it short).
NOISE = dict(BASE, noise={"band": ["1meg", "100meg"], "points_per_decade": 2,
                          "time_domain": False})


def every_function():
    """Each function on a dict; returns {name: result} for the CLI check."""
    out = {}
    out["run"] = isolink.run(BASE, worst=True)
    out["worst"] = isolink.worst(BASE)
    out["noise"] = isolink.noise(NOISE)
    out["sim"] = isolink.sim(RC_NETLIST, ["v(out)"], step="5n")
    out["sweep"] = isolink.sweep(SWEEP, jobs=2)
    out["pack"] = isolink.pack(PACK, jobs=2, worst=False)
    wave = out["run"]["directions"][0]["wave"]
    out["check"] = isolink.check(wave["time"], wave["v(rxp,rxn)"], rules="bq7961x")
    print(f"run: {out['run']['verdict']}, worst case {out['run']['worst_case']['verdict']}")
    print(f"worst: VSTART {out['worst']['directions'][0]['worst']['vstart']['value']:.3f} V")
    print(f"noise: {out['noise']['verdict']}, lowest immunity "
          f"{out['noise']['immunity_min_db']:.1f} dB re the test level")
    v = out["sim"]["v(out)"]
    print(f"sim: v(out) = {v[-1]:.4f} V at {out['sim']['time'][-1] * 1e9:.0f} ns")
    print(f"sweep: " + ", ".join(f"{r['cable.length']} m {r['verdict']}" for r in out["sweep"]))
    print(f"pack: {out['pack']['verdict']}, weakest hop {out['pack']['weakest_hop']}")
    print(f"check: {out['check']['verdict']}, decoded {out['check']['decoded']['bytes']}")
    return out


# --- the CLI check ------------------------------------------------------------------------------

# Wall times; the file a spec was read from; what the CLI's wave.csv holds (a file of the bundle,
# not part of the run: the module returns every engine row).
SKIP = {"seconds", "run_time_s", "source", "wave_csv"}


def same(a, b, path="", skip_extra=()):
    """Differences between the module's value a and the CLI's b (numbers to 1e-9 relative)."""
    if isinstance(b, dict):
        if not isinstance(a, dict):
            return [f"{path}: {type(a).__name__} against a dict"]
        diffs = []
        keys = [k for k in b if k not in SKIP]
        extra = set(a) - set(b) - set(skip_extra) - SKIP
        if extra:
            diffs.append(f"{path}: keys only in the module: {sorted(extra)}")
        for k in keys:
            if k not in a:
                diffs.append(f"{path}.{k}: missing in the module")
            elif not (k == "spec" and isinstance(b[k], str)):  # a pack hop's file name
                diffs += same(a[k], b[k], f"{path}.{k}", skip_extra)
        return diffs
    if isinstance(b, list):
        if not isinstance(a, list) or len(a) != len(b):
            return [f"{path}: lists differ in length"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in same(x, y, f"{path}[{i}]", skip_extra)]
    if isinstance(b, float) or isinstance(a, float):
        if isinstance(a, bool) or isinstance(b, bool):
            return [] if a == b else [f"{path}: {a!r} != {b!r}"]
        ok = math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-15)
        return [] if ok else [f"{path}: {a!r} != {b!r}"]
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


def cli(exe, *args, rc=(0, 1)):
    p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    if p.returncode not in rc:
        raise SystemExit(f"isolink {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}")
    return p.stdout


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]


def check_cli(exe, got):
    """Each function's result against the CLI on the same spec; the failures, as text."""
    tmp = tempfile.mkdtemp(prefix="isolink-notebook-")

    def file(name, obj):
        path = os.path.join(tmp, name)
        with open(path, "w") as f:
            f.write(obj if isinstance(obj, str) else json.dumps(obj, indent=1))
        return path

    spec = file("spec.json", BASE)
    failures = []
    cli(exe, "run", spec, "-o", os.path.join(tmp, "run"), "--no-images", "-q")
    with open(os.path.join(tmp, "run", "report.json")) as f:
        failures += same(got["run"], json.load(f), "run", skip_extra=("pass", "wave"))
    failures += same(got["worst"], json.loads(cli(exe, "worst", spec, "--json")), "worst")
    failures += same(got["noise"],
                     json.loads(cli(exe, "noise", file("noise.json", NOISE), "--json",
                                    "--no-images", "-o", os.path.join(tmp, "noise"))), "noise")
    csv_path = os.path.join(tmp, "sim.csv")
    cli(exe, "sim", file("rc.cir", RC_NETLIST), "--probe", "v(out)", "--step", "5n", "-o", csv_path,
        "-q", rc=(0,))
    header, rows = read_csv(csv_path)
    for k, name in enumerate(header):  # the CSV's 9 significant digits
        col = [r[k] for r in rows]
        mod = list(got["sim"][name])
        if len(col) != len(mod) or any(not math.isclose(x, y, rel_tol=2e-8, abs_tol=1e-12)
                                       for x, y in zip(mod, col)):
            failures.append(f"sim.{name}: differs from the CLI's CSV")
    out = os.path.join(tmp, "sweep")
    cli(exe, "sweep", file("sweep.json", SWEEP), "-o", out, "--no-plots", "-q")
    with open(os.path.join(out, "results.csv"), newline="") as f:
        want = sorted(csv.DictReader(f), key=lambda r: int(r["point"]))
    for g, w in zip(got["sweep"], want):
        for k, text in w.items():
            v = g[k]
            ok = (k == "seconds" or (text == "" and v is None) or
                  (isinstance(v, bool) and v == (text == "true")) or
                  (isinstance(v, str) and v == text) or
                  (isinstance(v, (int, float)) and not isinstance(v, bool) and
                   math.isclose(v, float(text), rel_tol=1e-9)))
            if not ok:
                failures.append(f"sweep[{g['point']}].{k}: {v!r} != {text!r}")
    if len(got["sweep"]) != len(want):
        failures.append("sweep: a different number of points")
    cli(exe, "pack", file("pack.json", PACK), "-o", os.path.join(tmp, "pack"), "--no-worst",
        "--no-images", "-q")
    with open(os.path.join(tmp, "pack", "report.json")) as f:
        failures += same(got["pack"], json.load(f), "pack")
    wave = got["run"]["directions"][0]["wave"]
    with open(os.path.join(tmp, "wave.csv"), "w") as f:
        f.write("time,v\n")
        f.writelines(f"{t!r},{v!r}\n" for t, v in zip(wave["time"], wave["v(rxp,rxn)"]))
    want = json.loads(cli(exe, "check", os.path.join(tmp, "wave.csv"), "--json"))
    want.pop("input", None)
    failures += same(got["check"], want, "check", skip_extra=("pass",))
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the margin plot to this PNG (needs python3-matplotlib)")
    ap.add_argument("--check-cli", metavar="ISOLINK", help="compare with this isolink executable")
    a = ap.parse_args()
    rows = margin_loop()
    if a.plot:
        plot(rows, a.plot)
    results = every_function()
    if a.check_cli:
        failures = check_cli(a.check_cli, results)
        for f in failures:
            print("MISMATCH", f)
        print(f"CLI check: {'every function matches' if not failures else 'mismatches'}")
        return 1 if failures else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
