"""isolink.sweep against `isolink sweep` (results.csv) on a two-point sweep of the test link."""
import csv

import pytest

import isolink
from conftest import SPEC, cli


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sweep") / "sweep.yaml"
    path.write_text(f"name: py-sweep\nbase: {SPEC}\nsweep:\n  cable.length: [1, 3]\n")
    return path


def test_rows_equal_results_csv(exe, sweep_file, tmp_path, mod_run):
    out = tmp_path / "cli"
    cli(exe, "sweep", sweep_file, "-o", out, "-j", "2", "--no-plots", "-q")
    with open(out / "results.csv", newline="") as f:
        expected = sorted(csv.DictReader(f), key=lambda r: int(r["point"]))
    rows = isolink.sweep(str(sweep_file), jobs=2)
    assert [r["point"] for r in rows] == [0, 1]
    assert [r["cable.length"] for r in rows] == [1.0, 3.0]
    for got, want in zip(rows, expected):
        assert list(got) == list(want)  # results.csv's columns, in its order
        for k, text in want.items():
            if k == "seconds":  # wall time
                assert got[k] > 0
            elif text == "":
                assert got[k] is None, k
            elif text in ("true", "false"):
                assert got[k] is (text == "true"), k
            elif isinstance(got[k], str):
                assert got[k] == text, k
            else:
                assert got[k] == float(text), k
    assert [r["verdict"] for r in rows] == ["pass", "pass"]
    # Point 0 is the base link: its VSTART margin is isolink.run's, to results.csv's 6 digits.
    margin = mod_run["directions"][0]["check"]["summary"]["worst"]["vstart"]["margin"]
    assert rows[0]["margin_vstart_V"] == pytest.approx(margin, rel=1e-5)
    # The two points are different links (3 m is not the base spec's 1 m).
    assert rows[1]["margin_vstart_V"] != rows[0]["margin_vstart_V"]


def test_out_folder_keeps_results_csv(sweep_file, tmp_path):
    # One point (zip of one length) so that the folder's file can be read back against the rows.
    path = tmp_path / "one.yaml"
    path.write_text(f"name: py-one\nbase: {SPEC}\nsweep:\n  cable.length: [2]\n")
    rows = isolink.sweep(str(path), out=str(tmp_path / "o"), jobs=1)
    with open(tmp_path / "o" / "results.csv", newline="") as f:
        (want,) = list(csv.DictReader(f))
    assert len(rows) == 1 and rows[0]["verdict"] == want["verdict"]
    assert rows[0]["margin_vend_V"] == float(want["margin_vend_V"])
    assert (tmp_path / "o" / "summary.json").exists()
