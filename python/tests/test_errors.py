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


# --- specs given as dicts: the location is the key path --------------------------------------

def test_dict_error_names_the_key_path(exe, bad_spec):
    _, err = cli(exe, "run", bad_spec, "-o", bad_spec.parent / "out", expect_rc=2)
    message = err.split(": error: ", 1)[1].split("\n")[0]  # the CLI's message, past its location
    spec = {"name": "bad", "tx": {"device": "bq7961x"}, "cable": {"length": 3, "lenght": 4}}
    for call in (isolink.run, isolink.worst, isolink.noise, isolink.load_spec):
        with pytest.raises(isolink.Error) as e:
            call(spec)
        assert str(e.value) == "cable.lenght: error: " + message
    assert message.startswith("unknown key 'cable.lenght' in 'cable' (known keys: length,")


def test_dict_value_and_list_item_errors():
    with pytest.raises(isolink.Error) as e:
        isolink.load_spec({"cable": {"length": "3 furlongs"}})
    assert str(e.value).startswith("cable.length: error: key 'cable.length': expected a number in m")
    with pytest.raises(isolink.Error) as e:
        isolink.load_spec({"cable": {"length": float("nan")}})
    assert str(e.value) == "cable.length: error: nan is not a finite number"
    with pytest.raises(isolink.Error) as e:
        isolink.load_spec({"stimulus": {"frames": ["raw 5A", object()]}})
    assert str(e.value).startswith("stimulus.frames[1]: error: a object cannot be a spec value")
    with pytest.raises(isolink.Error) as e:
        isolink.load_spec({"tx": {"device": "bq9999"}})
    assert str(e.value).startswith("tx.device: error: ")
    with pytest.raises(isolink.Error) as e:
        isolink.run(["not", "a", "spec"])
    assert str(e.value) == "spec: error: expected a path (str or os.PathLike) or a dict, got list"


def test_sweep_and_pack_dicts_name_key_paths():
    with pytest.raises(isolink.Error) as e:
        isolink.sweep({"base": {"cable": {"length": 1}}, "sweep": {"cable.lenght": [1, 2]}})
    assert str(e.value).startswith("sweep.cable.lenght: error: ")
    with pytest.raises(isolink.Error) as e:  # an error inside an inline base, read per point too
        isolink.sweep({"base": {"cable": {"lenght": 1}}, "sweep": {"cable.length": [1, 2]}})
    assert "base.cable.lenght: error: unknown key 'cable.lenght'" in str(e.value)
    with pytest.raises(isolink.Error) as e:
        isolink.pack({"hops": [{"spec": {"cable": {"length": 1}}, "cable": {"lenght": 2}}]})
    assert "hops[0].cable.lenght: error: " in str(e.value)


def test_sim_errors():
    with pytest.raises(isolink.Error) as e:
        isolink.sim("* x\nR1 a 0 -5\n.tran 1n 10n\n.end\n", ["v(a)"])
    assert str(e.value).startswith("<netlist>:2:8: error: resistance of r1 must be positive")
    with pytest.raises(isolink.Error) as e:
        isolink.sim("* x\nR1 a 0 5\n.tran 1n 10n\n.end\n", ["v(a)"], step="fast")
    assert str(e.value) == "step: error: expects a positive time such as 10n or 1e-8, got 'fast'"
