"""Errors: isolink.Error (a ValueError) carries the CLI's message, file:line:col included."""
import pytest

import isolink
from conftest import SPEC, cli

BAD_SPEC = """name: bad
tx: {device: bq7961x}
cable: {length: 3, lenght: 4}
"""


@pytest.fixture
def bad_spec(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(BAD_SPEC)
    return path


def test_spec_error_is_the_cli_message(exe, bad_spec):
    _, err = cli(exe, "run", bad_spec, "-o", bad_spec.parent / "out", expect_rc=2)
    with pytest.raises(isolink.Error) as e:
        isolink.run(str(bad_spec))
    assert str(e.value) == err.rstrip("\n")
    # Line 3, column 20: where `lenght` is.
    assert str(e.value).startswith(f"{bad_spec}:3:20: error:")
    assert isinstance(e.value, ValueError)
    with pytest.raises(isolink.Error) as e2:
        isolink.load_spec(str(bad_spec))
    assert str(e2.value) == str(e.value)


def test_sweep_error_is_the_cli_message(exe, tmp_path):
    path = tmp_path / "bad_sweep.yaml"
    path.write_text(f"base: {SPEC}\nsweep:\n  cable.lenght: [1, 2]\n")
    _, err = cli(exe, "sweep", path, "-o", tmp_path / "out", expect_rc=2)
    with pytest.raises(isolink.Error) as e:
        isolink.sweep(str(path))
    assert str(e.value) == err.rstrip("\n")
    assert str(e.value).startswith(f"{path}:3:3: error:")


def test_rules_error_is_the_cli_message(exe, cli_run):
    _, wave_csv = cli_run
    _, err = cli(exe, "check", wave_csv, "--rules", "nosuch", expect_rc=2)
    with pytest.raises(isolink.Error) as e:
        isolink.check([0.0, 1.0], [0.0, 0.0], rules="nosuch")
    assert "isolink check: " + str(e.value) == err.rstrip("\n")


def test_missing_file(exe, tmp_path):
    missing = tmp_path / "none.yaml"
    _, err = cli(exe, "run", missing, expect_rc=2)
    with pytest.raises(isolink.Error) as e:
        isolink.run(str(missing))
    assert str(e.value) == err.rstrip("\n")
