"""isolink.load_spec: the spec with its defaults (README 'Link specs' and netlists/link/README)."""
import pytest

import isolink
from conftest import SPEC


def test_keys_and_defaults(cli_run):
    report, _ = cli_run
    s = isolink.load_spec(str(SPEC))
    assert s["name"] == "py-one-byte"
    assert s["cable"]["length"] == 1.0
    assert s["tx"]["isolation"]["cap"] == pytest.approx(2.2e-9, rel=1e-12)
    # Defaults: 24 AWG, 25 degC, 1 ns tstep.
    assert s["cable"]["gauge"] == 24
    assert s["cable"]["temperature"] == pytest.approx(25.0)
    assert s["sim"]["tstep"] == pytest.approx(1e-9)
    # The spec isolink run simulated (report.json's "spec") is the same object.
    assert s == report["spec"]
