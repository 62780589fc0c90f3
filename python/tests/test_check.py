"""isolink.check: a hand-built frame with closed-form metrics, and `isolink check --json`."""
import csv
import json

import numpy as np
import pytest

import isolink
from conftest import cli
from test_run import same

T = 250e-9  # one half bit
TR = 20e-9  # a transition from -A to +A
A = 2.5     # plateau (V)


def frame_half_bits(byte):
    """Preamble +, sync 00, SOF 1, 8 data bits LSB first, error bit 0, postamble - (docs/physics.md rule 8.12;
    'Eye metrics' 12): a bit 0 is (-, +), a 1 is (+, -)."""
    couplet = {0: [-1, 1], 1: [1, -1]}
    bits = [0, 0, 1] + [(byte >> i) & 1 for i in range(8)] + [0]
    return [1] + [s for b in bits for s in couplet[b]] + [-1]


def frame_wave(byte, t0=1e-6):
    """Piecewise linear: level s*A per half bit, each sign change a ramp of TR centred on the
    boundary; from and back to idle 0 with the same slope (starting at t0, ending at the frame's
    end). Sampled every 1 ns: every corner is a sample, so linear interpolation is exact."""
    s = frame_half_bits(byte)
    corners = [(0.0, 0.0), (t0, 0.0), (t0 + TR / 2, s[0] * A)]
    for i in range(1, len(s)):
        if s[i] != s[i - 1]:
            corners += [(t0 + i * T - TR / 2, s[i - 1] * A), (t0 + i * T + TR / 2, s[i] * A)]
    end = t0 + len(s) * T
    corners += [(end - TR / 2, s[-1] * A), (end, 0.0), (end + 6e-6, 0.0)]
    t = np.round(np.arange(0, round((end + 6e-6) * 1e9) + 1)) * 1e-9
    ct, cv = zip(*corners)
    return t, np.interp(t, ct, cv), s


def test_frame_metrics_in_closed_form():
    t, v, s = frame_wave(0x5A)
    r = isolink.check(t, v, rules="bq7961x")
    assert r["verdict"] == "pass" and r["pass"] is True
    assert r["decoded"]["bytes"] == "5A"
    m = r["summary"]
    # Pulses: runs of equal half bits.
    runs = 1 + sum(1 for i in range(1, len(s)) if s[i] != s[i - 1])
    assert m["pulses"] == runs
    # Plateaus at A: VSTART (max over the first half) and VEND (20 ns before the end) are A.
    assert m["vstart_min"] == pytest.approx(A, abs=1e-9)
    assert m["vend_min"] == pytest.approx(A, abs=1e-9)
    # Width a_next - a between same-slope crossings: exactly k*T (single and double pulses).
    assert m["width_min_ns"] == pytest.approx(T * 1e9, abs=1e-6)
    assert m["width_max_ns"] == pytest.approx(2 * T * 1e9, abs=1e-6)
    # Edge: from -1.2 V to +1.2 V on a ramp of 2A per TR: TR * 2.4 / (2A) = 9.6 ns.
    assert m["edge_max_ns"] == pytest.approx(TR * 1.2 / A * 1e9, abs=1e-6)
    # Margins against bq7961x: VSTART 1.6 V (VEND above 1.3 V), VEND 1.2 V, edge 60 ns.
    w = m["worst"]
    assert w["vstart"]["limit"] == pytest.approx(1.6) and w["vstart"]["margin"] == pytest.approx(A - 1.6)
    assert w["vend"]["margin"] == pytest.approx(A - 1.2)
    assert w["edge"]["margin"] == pytest.approx(60 - 9.6, abs=1e-6)


def test_rules_and_expect():
    t, v, _ = frame_wave(0x5A)
    # The bridge's rule set: VSTART >= 1.8 V.
    r = isolink.check(t, v, rules="bq79600")
    assert r["rules"] == "bq79600"
    assert r["summary"]["worst"]["vstart"]["limit"] == pytest.approx(1.8)
    # Bytes expected that were not sent: a fail.
    r = isolink.check(t, v, expect="5B")
    assert r["pass"] is False and r["decoded"]["match"] is False
    # Halve the amplitude: VEND 1.25 V needs VSTART 1.7 V, and VSTART is 1.25 V: fails.
    r = isolink.check(t, v / 2)
    assert r["verdict"] == "fail"
    assert r["summary"]["vstart_min"] == pytest.approx(A / 2, abs=1e-9)


def test_equals_isolink_check_json_on_wave_csv(exe, cli_run):
    _, wave_csv = cli_run
    out, _ = cli(exe, "check", wave_csv, "--json")
    expected = json.loads(out)
    del expected["input"]
    with open(wave_csv, newline="") as f:
        rows = list(csv.reader(f))
    data = np.array(rows[1:], dtype=float)
    got = isolink.check(data[:, 0], data[:, 1])  # the first signal column, as the CLI takes
    assert got.pop("pass") is True
    same(got, expected, rel=1e-12)


def bytes_wave(data, period=10.3e-6, t0=20e-6):
    """The bytes as frame_wave draws one, a byte every `period` (3.8 us of idle between the 6.5 us
    frames, as the bridge forwards a command)."""
    t = np.round(np.arange(0, round((t0 + len(data) * period + 6e-6) * 1e9) + 1)) * 1e-9
    v = np.zeros_like(t)
    for i, b in enumerate(data):
        _, vb, _ = frame_wave(b, t0=t0 + i * period)
        v[: len(vb)] += vb
    return t, v


def test_commands_are_parsed_from_the_bytes():
    # TI's worked example: stack write 02 B7 78 BC to 0x0100, CRC 0A 35 (low byte first).
    t, v = bytes_wave([0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC, 0x0A, 0x35])
    r = isolink.check(t, v)
    assert r["pass"] is True
    assert len(r["commands"]) == 1
    c = r["commands"][0]
    assert (c["kind"], c["register"], c["data"], c["crc"]) == ("stack-write", "0x0100", "02 B7 78 BC", "0A35")
    assert c["crc_ok"] is True and c["flags"] == [] and c["device"] is None
    assert c["text"] == "stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok"
    assert r["commands_note"] is None
    # The same bytes with the CRC sent high byte first: the waveform still passes, the command
    # is the firmware's problem.
    t, v = bytes_wave([0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC, 0x35, 0x0A])
    r = isolink.check(t, v)
    assert r["pass"] is True
    assert r["commands"][0]["flags"] == ["bad_crc"]
    assert r["commands"][0]["crc_expected"] == "0A35"
    assert r["commands_note"].startswith("the waveform meets every receiver rule, but command 0 has a bad CRC")


def test_bad_samples_raise():
    t, v, _ = frame_wave(0x5A)
    t[2] = t[1]
    with pytest.raises(isolink.Error, match="time does not increase at sample 2"):
        isolink.check(t, v)
    with pytest.raises(isolink.Error, match="3 time samples but 2 values"):
        isolink.check([0, 1, 2], [0, 1])
    with pytest.raises(isolink.Error, match="one-dimensional"):
        isolink.check(np.zeros((2, 2)), np.zeros((2, 2)))


def test_failing_daisy_chain_pulses_fail_though_nothing_decodes(exe, tmp_path):
    """eye/README.md "Verdict": pulses with the daisy-chain's timing that fail their rules are a
    failed link even when no frame decodes; the same pulses meeting the rules are inconclusive.
    Here P and N are swapped (the signs flipped: nothing decodes). At 0.6 A = 1.5 V every pulse
    fails VSTART (1.6 V): fail, as `isolink check` says on the same samples. At A: inconclusive."""
    t, v, s = frame_wave(0x5A)
    r = isolink.check(t, -0.6 * v)
    assert r["verdict"] == "fail" and r["pass"] is False
    assert r["decoded"]["bytes"] == ""
    runs = 1 + sum(1 for i in range(1, len(s)) if s[i] != s[i - 1])
    assert r["summary"]["pulses"] == r["summary"]["failing"] == runs
    assert any("have the daisy-chain's timing" in x and x.endswith("a failed link")
               for x in r["reasons"]), r["reasons"]
    path = tmp_path / "swapped.csv"
    np.savetxt(path, np.column_stack([t, -0.6 * v]), delimiter=",", header="time,v", comments="",
               fmt="%.12g")
    out, _ = cli(exe, "check", path, "--json", expect_rc=1)
    assert json.loads(out)["verdict"] == "fail"
    r = isolink.check(t, -v)
    assert r["verdict"] == "inconclusive"
    assert any("meet the rules: P and N swapped" in x for x in r["reasons"]), r["reasons"]
