"""isolink: signal integrity of BMS daisy-chain links (type stub for editors).

The docstrings with arguments, units and return shapes are the module's own: help(isolink.run).
Results are the JSON the isolink CLI writes for the same input, as dicts and lists.
"""

import os
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

# A spec: a path to a YAML file, or a dict with the YAML's structure.
Spec = Union[str, "os.PathLike[str]", Mapping[str, Any]]
# A time in seconds: a number, or SPICE text such as "10n".
Time = Union[float, str]

class Error(ValueError):
    """The CLI's message: "file:line:col: error: ..." for a file, "key.path: error: ..." for a dict."""

def run(
    spec: Spec,
    *,
    direction: Optional[str] = None,
    engine: str = "auto",
    worst: bool = False,
    wave: str = "thinned",
    parts: Sequence[str] = [],
) -> dict[str, Any]:
    """`isolink run SPEC --no-worst` (worst=True: with the worst case): report.json's content,
    with "pass" and each direction's waveforms under "wave" (numpy arrays, s and V)."""

def worst(
    spec: Spec,
    *,
    direction: Optional[str] = None,
    edge_engine: str = "auto",
    parts: Sequence[str] = [],
) -> dict[str, Any]:
    """`isolink worst SPEC --json`: the worst case over all legal traffic."""

def noise(spec: Spec, *, parts: Sequence[str] = []) -> dict[str, Any]:
    """`isolink noise SPEC --json`: common-mode noise immunity over frequency."""

def sim(
    netlist: Union[str, "os.PathLike[str]"],
    probes: Sequence[str],
    *,
    engine: str = "auto",
    step: Optional[Time] = None,
    tstop: Optional[Time] = None,
    tmax: Optional[Time] = None,
    method: Optional[str] = None,
    reltol: Optional[float] = None,
) -> dict[str, npt.NDArray[np.float64]]:
    """`isolink sim NETLIST --probe ...`: {"time": array (s), probe: array (V or A), ...}.
    netlist: a path, or the netlist's text (a str with a line break)."""

def sweep(
    sweep: Spec,
    *,
    out: Optional[str] = None,
    jobs: int = 0,
    engine: str = "auto",
    parts: Sequence[str] = [],
) -> list[dict[str, Any]]:
    """`isolink sweep --no-plots`: results.csv's rows as dicts, in point order."""

def stress(
    spec: Spec,
    *,
    only: Sequence[str] = [],
    parts: Sequence[str] = [],
) -> dict[str, Any]:
    """`isolink stress SPEC --json`: the scenarios' peaks, parts, traffic and verdicts."""

def pack(
    pack_spec: Spec,
    *,
    jobs: int = 0,
    worst: bool = True,
    parts: Sequence[str] = [],
) -> dict[str, Any]:
    """`isolink pack` (worst=False: --no-worst): the pack's report.json."""

def check(
    t: npt.ArrayLike,
    v: npt.ArrayLike,
    *,
    rules: str = "bq7961x",
    expect: Optional[str] = None,
) -> dict[str, Any]:
    """`isolink check --json` for samples v (V) at times t (s), plus "pass"."""

def compare(
    capture: Sequence[str],
    spec: str,
    *,
    direction: str = "down",
    fit: Sequence[str] = [],
    bounds: dict[str, tuple[float, float]] = {},
    frames: str = "",
    p: str = "",
    n: str = "",
    diff: str = "",
    parts: Sequence[str] = [],
) -> dict[str, Any]:
    """`isolink compare --json`: a capture against the link spec's simulation (and a fit)."""

def load_spec(spec: Spec) -> dict[str, Any]:
    """The link spec with every default filled in (report.json's "spec")."""
