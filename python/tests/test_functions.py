"""Every function on specs given as dicts, against the isolink executable on the same spec (the dict
written to a file as JSON, which is YAML), and against closed forms where there is one."""
import csv
import json
import math
import threading
import time

import numpy as np
import pytest

import isolink
from conftest import ONE_BYTE, cli

SKIP = {"seconds", "run_time_s", "source"}  # wall times; the file the spec was read from


def same(a, b, path="$", extra=()):
    """The module's value a equals the CLI's b: the same keys (but `extra` in a, wall times and
    sources), numbers within 1e-9 relative (the same computation in two processes)."""
    if isinstance(b, dict):
        assert isinstance(a, dict), path
        assert [k for k in a if k not in extra and k not in SKIP] == \
            [k for k in b if k not in SKIP], path
        for k in b:
            if k not in SKIP and not (k == "spec" and isinstance(b[k], str)):
                same(a[k], b[k], f"{path}.{k}", extra)
    elif isinstance(b, list):
        assert isinstance(a, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{i}]", extra)
    elif isinstance(b, float) and not isinstance(a, bool):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-15), path
    else:
        assert a == b, path


def as_file(tmp_path, name, obj):
    path = tmp_path / name
    path.write_text(obj if isinstance(obj, str) else json.dumps(obj, indent=1))
    return path


def test_dict_spec_is_the_file_spec(mod_run):
    """The dict with one_byte.yaml's content gives the file's run (whose equality with the CLI
    test_run.py proves), spec and defaults included."""
    r = isolink.run(ONE_BYTE)
    waves = [d.pop("wave") for d in r["directions"]]
    same(r, {**mod_run, "directions": [{k: v for k, v in d.items() if k != "wave"}
                                       for d in mod_run["directions"]]})
    for w, want in zip(waves, (d["wave"] for d in mod_run["directions"])):
        assert list(w) == list(want)
        for k in w:
            np.testing.assert_array_equal(w[k], want[k])
    assert r["spec"]["source"] == "spec"  # the argument's name stands for the file


@pytest.fixture(scope="module")
def worst_dict():
    return isolink.worst(ONE_BYTE)


def test_worst_equals_the_cli(exe, tmp_path, worst_dict):
    out, _ = cli(exe, "worst", as_file(tmp_path, "spec.json", ONE_BYTE), "--json", "-q")
    want = json.loads(out)
    same(worst_dict, want)
    vstart = worst_dict["directions"][0]["worst"]["vstart"]
    # The worst VSTART is no higher than the spec's own traffic gives (the worst over all traffic).
    assert vstart["value"] > 1.6 and vstart["margin"] == pytest.approx(vstart["value"] - 1.6)


def test_run_with_worst_has_the_worst_case(worst_dict):
    r = isolink.run(ONE_BYTE, worst=True)
    same(r["worst_case"], worst_dict)
    spec_vstart = r["directions"][0]["check"]["summary"]["worst"]["vstart"]["value"]
    assert r["worst_case"]["directions"][0]["worst"]["vstart"]["value"] <= spec_vstart + 1e-9


NOISE = dict(ONE_BYTE, noise={"band": ["1meg", "100meg"], "points_per_decade": 2,
                              "time_domain": False})


def test_noise_equals_the_cli(exe, tmp_path):
    got = isolink.noise(NOISE)
    out, _ = cli(exe, "noise", as_file(tmp_path, "noise.json", NOISE), "--json", "--no-images",
                 "-o", tmp_path / "out", expect_rc=0 if got["verdict"] == "pass" else 1)
    same(got, json.loads(out))
    # 1 MHz to 100 MHz at 2 points per decade: 5 frequencies, both ends included.
    freqs = [p["freq_hz"] for p in got["directions"][0]["points"]]
    assert freqs == pytest.approx([1e6, 10**6.5, 1e7, 10**7.5, 1e8], rel=1e-9)


RC = """* RC step: 1 V through 100 ohm into 1 nF (tau 100 ns)
V1 in 0 PULSE(0 1 10n 1n 1n 1u 2u)
R1 in out 100
C1 out 0 1n
.tran 1n 600n
.end
"""


@pytest.mark.parametrize("engine", ["lti", "transient"])
def test_sim_equals_the_cli_and_the_closed_form(exe, tmp_path, engine):
    path = as_file(tmp_path, "rc.cir", RC)
    got = isolink.sim(RC, ["v(out)", "i(V1)"], engine=engine, step="5n")
    out = tmp_path / "rc.csv"
    cli(exe, "sim", path, "--probe", "v(out)", "--probe", "i(V1)", "--engine", engine,
        "--step", "5n", "-o", out, "-q")
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    assert list(got) == rows[0] == ["time", "v(out)", "i(v1)"]  # names as the CLI writes them
    data = np.array(rows[1:], dtype=float)
    for k, name in enumerate(rows[0]):  # the CSV's 9 significant digits
        np.testing.assert_allclose(got[name], data[:, k], rtol=2e-8, atol=1e-15)
    # A path gives the same; the 5 ns grid.
    by_path = isolink.sim(str(path), ["v(out)"], engine=engine, step=5e-9)
    np.testing.assert_allclose(by_path["v(out)"], got["v(out)"], rtol=0, atol=0)
    assert np.diff(got["time"]) == pytest.approx(5e-9, rel=1e-9)
    # The step (a 1 ns ramp from 10 ns, its middle at 10.5 ns) charges the cap with tau = 100 ns.
    t, v = got["time"], got["v(out)"]
    k = np.searchsorted(t, 310.5e-9)
    assert v[k] == pytest.approx(1 - math.exp(-(t[k] - 10.5e-9) / 100e-9), abs=2e-3)


SWEEP = {"name": "py-dict-sweep", "base": ONE_BYTE, "sweep": {"cable.length": [1, 3]}}


def test_sweep_dict_equals_the_cli(exe, tmp_path):
    rows = isolink.sweep(SWEEP, jobs=2)
    out = tmp_path / "out"
    cli(exe, "sweep", as_file(tmp_path, "sweep.json", SWEEP), "-o", out, "-j", "2", "--no-plots",
        "-q")
    with open(out / "results.csv", newline="") as f:
        want = sorted(csv.DictReader(f), key=lambda r: int(r["point"]))
    assert len(rows) == len(want) == 2
    for got, w in zip(rows, want):
        assert list(got) == list(w)
        for k, text in w.items():
            if k == "seconds":
                continue
            if text == "":
                assert got[k] is None, k
            elif isinstance(got[k], (bool, str)):
                assert str(got[k]).lower() == text.lower(), k
            else:
                assert got[k] == pytest.approx(float(text), rel=1e-9), k
    assert [r["cable.length"] for r in rows] == [1.0, 3.0]


PACK = {
    "name": "py-pack",
    "stimulus": {"frames": ["raw 5A nocrc"]},
    "hops": [{"spec": dict(ONE_BYTE, tx={"device": "bq79600",
                                         "isolation": {"type": "cap", "cap": "2.2n"}})},
             {"spec": ONE_BYTE, "cable": {"length": 0.3}}],
}


def test_pack_dict_equals_the_cli(exe, tmp_path):
    got = isolink.pack(PACK, jobs=2, worst=False)
    out = tmp_path / "out"
    cli(exe, "pack", as_file(tmp_path, "pack.json", PACK), "-o", out, "--no-worst", "--no-images",
        "-q")
    want = json.loads((out / "report.json").read_text())
    same(got, want)
    assert [h["index"] for h in got["hops"]] == [1, 2]
    assert got["verdict"] == "pass"


def test_check_equals_the_cli(exe, tmp_path, mod_run):
    w = mod_run["directions"][0]["wave"]
    path = tmp_path / "wave.csv"
    with open(path, "w") as f:
        f.write("time,v\n")
        f.writelines(f"{t!r},{v!r}\n" for t, v in zip(w["time"], w["v(rxp,rxn)"]))
    got = isolink.check(w["time"], w["v(rxp,rxn)"])
    out, _ = cli(exe, "check", path, "--json")
    want = json.loads(out)
    want.pop("input")
    same(got, want, extra=("pass",))


def test_long_calls_release_the_gil():
    """While run() works in a thread, this thread keeps running Python. With the GIL held through
    the C++ work it would stand still from each call's start to its end: gaps as long as a call.
    The worker repeats the call for at least half a second, so the test does not depend on how
    fast one call is, only on its being long enough to see (asserted)."""
    ticks, calls = [], []
    done = threading.Event()
    spec = dict(ONE_BYTE, cable={"length": 30})  # a longer link: a tenth of a second or more

    def work():
        begin = time.monotonic()
        while time.monotonic() - begin < 0.5:
            t0 = time.monotonic()
            isolink.run(spec)
            calls.append(time.monotonic() - t0)
        done.set()

    worker = threading.Thread(target=work)
    start = time.monotonic()
    worker.start()
    while not done.is_set():
        ticks.append(time.monotonic())
        time.sleep(0.001)
    worker.join()
    gaps = np.diff([start] + ticks + [time.monotonic()])
    assert min(calls) > 0.03, calls  # else a held GIL would not show
    # With the GIL held, every call is one gap as long as itself: nearly all the time in gaps of
    # half a call or more. A loaded machine deschedules this thread now and then (the suite's
    # `python` test failed once at -j2 beside a package install; the single largest gap was the
    # criterion then): a quarter of the time in such gaps is allowed.
    long_gaps = gaps[gaps >= min(calls) / 2].sum()
    assert long_gaps < 0.25 * gaps.sum(), (long_gaps, gaps.sum(), calls, len(ticks))


CLIPPER = """* clipper: a 0 -> 5 V ramp over 1 ms through 1 kohm into a diode to ground
V1 in 0 PWL(0 0 1m 5)
R1 in out 1k
D1 out 0 DM
.model DM D(IS=1e-14)
.tran 10u 1m
.end
"""


def test_sim_takes_a_diode_and_lands_on_its_knee():
    """The SPICE diode from Python: each row within 10 uV of the v that solves
    (vin - v) / 1 kohm = is (e^(v / vt) - 1) (the rows inside the engine's steps take the diode's
    current as a straight line over the step: the kept run's trtol reltol |v| is 7 uV)."""
    got = isolink.sim(CLIPPER, ["v(in)", "v(out)"])
    vt = 1.38064852e-23 * 300.15 / 1.6021766208e-19
    vin, vout = got["v(in)"], got["v(out)"]
    assert len(vout) > 100  # a row each TSTEP at least
    residual = (vin - vout) / 1e3 - 1e-14 * np.expm1(vout / vt) - 1e-12 * vout
    slope = 1e-3 + 1e-14 / vt * np.exp(vout / vt) + 1e-12  # d residual / d v
    assert np.max(np.abs(residual / slope)) < 1e-5  # volts, at up to 0.69 V
    assert vout[-1] == pytest.approx(0.6929, abs=1e-3)
    with pytest.raises(isolink.Error, match="LTI engine cannot simulate it"):
        isolink.sim(CLIPPER, ["v(out)"], engine="lti")


TVS = dict(ONE_BYTE, name="py-tvs",
           rx={"device": "bq7961x", "isolation": {"type": "cap", "cap": 2.2e-9, "esd": "PESD2CAN"}})


def test_run_takes_a_tvs_part_and_says_why_it_has_no_worst_case():
    """esd: a TVS part makes the link nonlinear: the run is its traffic on the port model,
    the worst case is reported as not computed with the reason, and below its standoff voltage
    the TVS acts mostly as its junction capacitance: the same link with a linear capacitor of
    the part's 0 V figure (25 pF) reproduces at least three quarters of what the TVS does to the
    waveform (2026-12-04: 24 mV apart, against 219 mV without the TVS), but not all of it (the
    lines' swing moves the junctions off 0 V: C(V) is not a constant)."""
    r = isolink.run(TVS, worst=True)
    assert r["pass"]
    assert r["worst_case"]["computed"] is False
    assert "rx.isolation.esd: TVS PESD2CAN" in r["worst_case"]["why"]
    assert r["directions"][0]["solver"]["engine"] == "port"
    lin = isolink.run(dict(TVS, rx={"device": "bq7961x",
                                    "isolation": {"type": "cap", "cap": 2.2e-9, "esd": "25p"}}))
    bare = isolink.run(dict(TVS, rx={"device": "bq7961x",
                                     "isolation": {"type": "cap", "cap": 2.2e-9}}))

    def diff(a, b):
        wa, wb = a["directions"][0]["wave"], b["directions"][0]["wave"]
        t = np.linspace(1e-6, min(wa["time"][-1], wb["time"][-1]), 20000)
        key = "v(rxp,rxn)"
        return np.max(np.abs(np.interp(t, wa["time"], wa[key]) - np.interp(t, wb["time"], wb[key])))

    assert 1e-3 < diff(r, lin) < 0.25 * diff(r, bare)
