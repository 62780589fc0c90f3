"""isolink.run against `isolink run --no-worst` on the same link (python/tests/one_byte.yaml)."""
import csv
import math

import numpy as np
import pytest

import isolink
from conftest import SPEC


def same(a, b, rel=1e-9, path="$"):
    """Recursive equality; floats within rel (the same computation in two processes)."""
    if isinstance(a, float) or isinstance(b, float):
        assert a == pytest.approx(b, rel=rel, abs=1e-15), path
    elif isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a:
            same(a[k], b[k], rel, f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, rel, f"{path}[{i}]")
    else:
        assert a == b, path


def test_verdict_and_metrics_equal_the_cli(cli_run, mod_run):
    report, _ = cli_run
    assert mod_run["verdict"] == report["verdict"] == "pass"
    assert mod_run["pass"] is True
    assert [d["direction"] for d in mod_run["directions"]] == ["down"]
    d, c = mod_run["directions"][0], report["directions"][0]
    assert d["pass"] is True and d["verdict"] == c["verdict"] == "pass"
    # The whole check object (pulses, margins, decoded bytes) as report.json has it.
    same(d["check"], c["check"])
    same(d["check"]["summary"]["worst"]["vstart"], c["check"]["summary"]["worst"]["vstart"])
    # The byte the spec sends comes back decoded.
    assert d["check"]["decoded"]["bytes"] == "5A"
    same(mod_run["spec"], report["spec"])


def test_waveforms_are_numpy_and_match_wave_csv(cli_run, mod_run):
    report, wave_csv = cli_run
    w = mod_run["directions"][0]["wave"]
    assert list(w) == ["time", "v(rxp,rxn)", "v(rxp)", "v(rxn)", "v(txp,txn)"]
    t = w["time"]
    assert isinstance(t, np.ndarray) and t.dtype == np.float64 and t.ndim == 1
    assert np.all(np.diff(t) > 0)
    for name in w:
        assert w[name].shape == t.shape
    # v(rxp,rxn) is V(rxp) - V(rxn) by definition.
    np.testing.assert_allclose(w["v(rxp,rxn)"], w["v(rxp)"] - w["v(rxn)"], rtol=0, atol=1e-9)
    # wave.csv holds the engine's own rows, thinned (analysis/link_run_wave.h): each of its times
    # is a row of the module's waveform, its values are those rows' (9 significant digits), and
    # linear interpolation between its rows stays within the tolerance report.json states of every
    # row the module returns.
    with open(wave_csv, newline="") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    assert header[:2] == ["time", "down v(rxp,rxn)"]
    tol = report["wave_csv"]["tolerance_v"]
    assert report["wave_csv"]["mode"] == "thinned" and 1e-3 <= tol <= 50e-3
    assert 2 < len(data) < len(t)
    # The nearest row of the module's waveform to each time (printed with 12 digits).
    index = np.clip(np.searchsorted(t, data[:, 0]), 1, len(t) - 1)
    index -= (np.abs(t[index - 1] - data[:, 0]) < np.abs(t[index] - data[:, 0])).astype(int)
    np.testing.assert_allclose(t[index], data[:, 0], rtol=1e-11, atol=0)
    for k, name in enumerate(header[1:], 1):
        probe = name.split(" ", 1)[1]
        np.testing.assert_allclose(data[:, k], w[probe][index], rtol=2e-8, atol=1e-12, err_msg=name)
        back = np.interp(t, data[:, 0], data[:, k])
        assert np.max(np.abs(back - w[probe])) <= tol * (1 + 1e-6) + 1e-8, name
    # The receiver sees the pulses the checker measured: VSTART of the worst pulse is the peak
    # of |v| over its first half, which the samples bound from below.
    vstart = mod_run["directions"][0]["check"]["summary"]["vstart_min"]
    assert np.max(np.abs(w["v(rxp,rxn)"])) >= vstart - 1e-12
    assert math.isfinite(vstart) and vstart > 1.6


def test_direction_and_engine_options():
    with pytest.raises(isolink.Error, match="direction: error: 'sideways' is none of down, up, both"):
        isolink.run(str(SPEC), direction="sideways")
    with pytest.raises(isolink.Error, match="fast"):
        isolink.run(str(SPEC), engine="fast")


def test_wave_rows_keeps_every_engine_row():
    """wave="rows" (as `isolink run --wave rows`): every LTI engine row, where the default record
    keeps every row up to 2 million and thins the rest within 1 mV. 24 stack writes on a 2 m cap
    link make about 3.5 million rows."""
    spec = {
        "name": "py-long",
        "cable": {"length": 2},
        "stimulus": {
            "frames": ["stack-write reg=0x0100 data=02B778BC"] * 24,
            "direction": "down",
        },
    }
    with pytest.warns(UserWarning, match="the record keeps .* within 1 mV of every engine row"):
        thinned = isolink.run(spec, engine="lti")["directions"][0]
    full = isolink.run(spec, engine="lti", wave="rows")["directions"][0]
    rows = full["solver"]["rows"]
    assert rows == thinned["solver"]["rows"] > 2_000_000
    assert len(full["wave"]["time"]) == rows
    assert 2_000_000 < len(thinned["wave"]["time"]) < rows
    # The kept rows are engine rows: the same values at the same times.
    t_full, t_thin = full["wave"]["time"], thinned["wave"]["time"]
    idx = np.searchsorted(t_full, t_thin[-1000:])
    assert np.array_equal(t_full[idx], t_thin[-1000:])
    for name in thinned["wave"]:
        assert np.array_equal(full["wave"][name][idx], thinned["wave"][name][-1000:]), name
    with pytest.raises(isolink.Error, match="wave: error: 'grid' is none of thinned, rows"):
        isolink.run(spec, wave="grid")

