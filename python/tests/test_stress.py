"""isolink.stress against `isolink stress --json` on the same spec, and against what the circuit's
symmetry demands: a 0.5 m cap link with a 1 uF Y cap at the tx end, ESD only (about 1.5 s)."""
import json

import pytest

import isolink
from conftest import cli
from test_functions import same

YCAP = {
    "name": "py-ycap",
    "tx": {"device": "bq79600", "y_cap": "1u"},
    "rx": {"device": "bq7961x"},
    "cable": {"length": 0.5},
    "stress": {"only": ["esd"]},
}


@pytest.fixture(scope="module")
def mod_stress():
    return isolink.stress(YCAP)


def test_stress_is_the_cli_json(exe, tmp_path, mod_stress):
    path = tmp_path / "ycap.yaml"
    path.write_text(json.dumps(YCAP))
    out, _ = cli(exe, "stress", path, "--json", "-q", "-o", tmp_path / "out",
                 expect_rc=0 if mod_stress["survives"] else 1)
    same(mod_stress, json.loads(out))
    assert (tmp_path / "out" / "stress.png").is_file()
    assert (tmp_path / "out" / "report.html").is_file()


def test_stress_peaks_follow_the_circuit(mod_stress):
    sc = {s["id"]: s for s in mod_stress["scenarios"]}
    assert sorted(sc) == sorted(f"esd_{e}_{l}_{p}" for e in ("tx", "rx") for l in ("p", "n")
                                for p in ("pos", "neg"))
    limit = mod_stress["limits"]["pin_abs_max_V"]["value"]
    for s in sc.values():
        pins = s["peak_pin_v"]
        assert sorted(pins) == ["rxn", "rxp", "txn", "txp"]
        for v in pins.values():  # every pin starts idle at the 2.5 V bias
            assert v["min"] <= 2.5 + 1e-3 and v["max"] >= 2.5 - 1e-3
        worst = max(max(abs(v["max"]), abs(v["min"])) for v in pins.values())
        assert s["survives"] == (worst <= limit and s["peak_cm_V"] <= limit), s["id"]
        assert s["communicates"] is None  # no traffic during ESD
    # P and N are built alike: a zap into N is a zap into P with the pins' names swapped.
    for e in ("tx", "rx"):
        for p in ("pos", "neg"):
            a, b = sc[f"esd_{e}_p_{p}"]["peak_pin_v"], sc[f"esd_{e}_n_{p}"]["peak_pin_v"]
            for d in ("tx", "rx"):
                for k in ("max", "min"):
                    assert a[d + "p"][k] == pytest.approx(b[d + "n"][k], abs=1e-3)
    # The zapped line's own pin goes the discharge's way first.
    assert sc["esd_rx_p_pos"]["peak_pin_v"]["rxp"]["max"] > 5
    assert sc["esd_rx_p_neg"]["peak_pin_v"]["rxp"]["min"] < 0
    # The 1 uF Y cap holds the tx connector near ground: the tx pins stay within a volt or so of
    # the bias where the rx end (no Y cap) swings far further.
    tx = sc["esd_tx_p_pos"]["peak_pin_v"]["txp"]["max"] - 2.5
    rx = sc["esd_rx_p_pos"]["peak_pin_v"]["rxp"]["max"] - 2.5
    assert tx < 1.5 and rx > 5 * tx


def test_stress_refuses_an_unknown_kind():
    with pytest.raises(isolink.Error, match="bogus"):
        isolink.stress(YCAP, only=["bogus"])
