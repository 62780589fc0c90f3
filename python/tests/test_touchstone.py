"""A measured cable (cable: {touchstone: FILE}) through the module: the test link's own cable
written as .s4p by `isolink export-touchstone` (its AC analysis, 10 kHz-500 MHz), read back and
fitted (docs/touchstone.md), must give the native cable's received waveform within 2 mV (issue
44's bound); a sweep over that link runs on the fast path, one row per point."""
import copy

import numpy as np
import pytest

import isolink
from conftest import ONE_BYTE, SPEC, cli


@pytest.fixture(scope="module")
def s4p(exe, tmp_path_factory):
    path = tmp_path_factory.mktemp("touchstone") / "cable.s4p"
    cli(exe, "export-touchstone", SPEC, "-o", path)
    return path


def measured(s4p):
    spec = copy.deepcopy(ONE_BYTE)
    spec["name"] = "py-one-byte-s4p"
    spec["cable"] = {"touchstone": str(s4p)}
    return spec


def test_measured_cable_gives_the_native_waveform(s4p, mod_run):
    got = isolink.run(measured(s4p))
    assert got["verdict"] == mod_run["verdict"] == "pass"
    native = mod_run["directions"][0]["wave"]
    fitted = got["directions"][0]["wave"]
    # The two runs' rows differ (each engine's grid follows its own model): compare on the
    # native rows, the fitted waveform interpolated linearly (within its stated 1 mV).
    t = native["time"]
    v = np.interp(t, fitted["time"], fitted["v(rxp,rxn)"])
    dev = np.max(np.abs(v - native["v(rxp,rxn)"]))
    assert dev < 2e-3, f"max |dv(rxp,rxn)| = {dev * 1e3:.2f} mV"
    # The waveform is not trivially equal: the pulses swing volts.
    assert np.ptp(native["v(rxp,rxn)"]) > 1.0
    assert got["directions"][0]["check"]["decoded"]["bytes"] == "5A"


def test_a_native_key_beside_the_file_is_refused(s4p):
    spec = measured(s4p)
    spec["cable"]["material"] = "pp"
    with pytest.raises(isolink.Error, match="cable.material"):
        isolink.run(spec)


def test_sweep_over_a_measured_cable(s4p, tmp_path, mod_run):
    base = tmp_path / "base.yaml"
    base.write_text(
        "name: py-s4p-sweep\n"
        "tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}\n"
        "rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}\n"
        f"cable: {{touchstone: {s4p}}}\n"
        'stimulus: {frames: ["raw 5A nocrc"], direction: down}\n')
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"name: py-s4p-sweep\nbase: {base}\nsweep:\n  rx.isolation.cap: [2.2n, 1.1n]\n")
    rows = isolink.sweep(str(sweep), jobs=1)
    assert [r["point"] for r in rows] == [0, 1]
    assert [r["verdict"] for r in rows] == ["pass", "pass"]
    # Point 0 is the measured link at its design: its VSTART margin is the native link's within
    # the 2 mV the waveforms agree to (results at 6 digits).
    margin = mod_run["directions"][0]["check"]["summary"]["worst"]["vstart"]["margin"]
    assert rows[0]["margin_vstart_V"] == pytest.approx(margin, abs=2e-3)
    # Halving the receive cap moves the margin (a higher-pass coupling: the pulses droop more).
    assert rows[1]["margin_vstart_V"] != pytest.approx(rows[0]["margin_vstart_V"], abs=1e-3)
