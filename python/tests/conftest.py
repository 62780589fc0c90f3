"""Shared fixtures: the isolink executable (CTest passes its path in ISOLINK_EXE), the test link,
and one run of it through each front end (the simulations are the slow part: each runs once)."""
import json
import os
import pathlib
import subprocess

import pytest

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
SPEC = HERE / "one_byte.yaml"
# one_byte.yaml as a dict with the YAML's structure (quantities as numbers or as the YAML's text).
ONE_BYTE = {
    "name": "py-one-byte",
    "tx": {"device": "bq7961x", "isolation": {"type": "cap", "cap": "2.2n"}},
    "rx": {"device": "bq7961x", "isolation": {"type": "cap", "cap": 2.2e-9}},
    "cable": {"length": 1, "material": "pp"},
    "stimulus": {"frames": ["raw 5A nocrc"], "direction": "down"},
}


@pytest.fixture(scope="session")
def exe():
    path = os.environ.get("ISOLINK_EXE", str(ROOT / "build" / "cli" / "isolink"))
    assert os.access(path, os.X_OK), f"no isolink executable at {path} (set ISOLINK_EXE)"
    return path


def cli(exe, *args, expect_rc=0):
    """Runs the isolink executable; returns (stdout, stderr) after checking the exit status."""
    p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == expect_rc, f"isolink {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}"
    return p.stdout, p.stderr


@pytest.fixture(scope="session")
def cli_run(exe, tmp_path_factory):
    """`isolink run one_byte.yaml --no-worst --no-images`: its report.json and wave.csv path."""
    out = tmp_path_factory.mktemp("cli_run") / "bundle"
    cli(exe, "run", SPEC, "-o", out, "--no-worst", "--no-images", "-q")
    return json.loads((out / "report.json").read_text()), out / "wave.csv"


@pytest.fixture(scope="session")
def mod_run():
    import isolink
    return isolink.run(str(SPEC))
