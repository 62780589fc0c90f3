"""isolink.compare: the link's own simulated waveform, written as a capture, against its spec
(a match with a residual of the simulation's own grid error), the same object as
`isolink compare --json`, and a bad key raising isolink.Error."""
import json

import numpy as np
import pytest

import isolink
from conftest import SPEC, cli


@pytest.fixture(scope="module")
def own_capture(tmp_path_factory):
    run = isolink.run(str(SPEC), direction="down")
    wave = run["directions"][0]["wave"]
    path = tmp_path_factory.mktemp("compare") / "own.csv"
    np.savetxt(path, np.column_stack([wave["time"] + 2e-6, wave["v(rxp,rxn)"]]), delimiter=",",
               header="time,v(rxp,rxn)", comments="", fmt="%.12e")
    return path


def test_own_simulation_matches(own_capture, exe):
    r = isolink.compare([str(own_capture)], str(SPEC))
    assert r["verdict"] == "match"
    assert r["findings"] == []
    # The run's 2 us shift is recovered to well under a sample; the residual is the LTI output
    # grid's linear interpolation (within 1 mV by its rule) plus rounding.
    assert r["offset_s"] == pytest.approx(2e-6, abs=0.2e-9)
    assert r["residual"]["rms_v"] < 2e-3
    out, _ = cli(exe, "compare", own_capture, SPEC, "--json")
    j = json.loads(out)
    assert j["verdict"] == r["verdict"]
    assert j["residual"]["rms_v"] == pytest.approx(r["residual"]["rms_v"], rel=1e-9)


def test_bad_key_raises(own_capture):
    with pytest.raises(isolink.Error, match="rx.isolation.colour"):
        isolink.compare([str(own_capture)], str(SPEC), fit=["rx.isolation.colour"])
