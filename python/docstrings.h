// The isolink module's docstrings (help(isolink.run), editors): arguments, units, return shape.
// isolink.pyi carries the same signatures with types; python/tests/test_stub.py checks the two
// agree.
#pragma once

namespace isolink::python::doc {

inline constexpr const char* kModule = R"doc(isolink: signal integrity of BMS daisy-chain links.

The engine of the isolink command-line tool as Python functions. Results are the JSON the CLI
writes for the same input (report.json, --json), as dicts and lists; waveforms are numpy arrays.

A spec is a path (str or os.PathLike) to a YAML file, or a dict with the YAML's structure:
    isolink.run({"name": "a", "cable": {"length": 12}})
Quantities are numbers in SI units (2.2e-9) or the YAML's text ("2.2n", "2.2nF", "12m").
Relative paths inside a dict (a sweep's base, a pack's hop files) are taken from the current
working directory.

Errors raise isolink.Error (a ValueError) with the CLI's message: "file:line:col: error: ..."
for a file, and the key path for a dict ("cable.lenght: error: unknown key ...").
Long calls release the GIL: other Python threads run meanwhile.

Functions: run, worst, noise, sim, sweep, pack, check, load_spec.)doc";

inline constexpr const char* kRun = R"doc(Simulate a link with its traffic and score each receiver.

As `isolink run SPEC --no-worst` (with worst=True: without --no-worst); nothing is written.

Args:
    spec: a link spec, a path or a dict (a pack spec is refused: use pack()).
    direction: "down", "up" or "both": overrides the spec's stimulus.direction.
    engine: "auto" (LTI where it is the cheaper engine, else transient), "lti", "transient".
    worst: also the worst case over all legal traffic, under "worst_case" (as worst()).
    wave: "thinned" (the run's record: every engine row up to 2 million, then the rows that
        linear interpolation needs within 1 mV) or "rows" (every engine row, as `isolink run
        --wave rows`: memory grows with the traffic, 40 bytes a row).
    parts: extra part-library folders.

Returns:
    report.json's content: {"verdict": "pass"|"fail", "name", "run_time_s", "spec",
    "directions": [{"direction", "rules", "check": {"verdict", "reasons", "summary": {...,
    "worst": {"vstart": {"value", "limit", "margin"}, ...}}, "pulses", "decoded"}, "solver",
    ...}], "worst_case" (worst=True)}, plus "pass" (bool) at the top and in each direction, and
    each direction's waveforms under "wave": {"time": array (s), "v(rxp,rxn)": array (V),
    "v(rxp)", "v(rxn)", "v(txp,txn)"} on the engine's own time grid.)doc";

inline constexpr const char* kWorst = R"doc(The worst case over all legal traffic.

As `isolink worst SPEC --json`: lowest VSTART and VEND, narrowest and widest pulse, slowest
edge per direction, the traffic that causes each and a stimulus block that replays it.

Args:
    spec: a link spec, a path or a dict.
    direction: "down", "up" or "both": overrides the spec's stimulus.direction.
    edge_engine: "auto" (the LTI reduced model, checked against the exact AC solution) or
        "transient".
    parts: extra part-library folders.

Returns:
    `isolink worst --json`'s object: {"verdict", "seconds", "directions": [{"direction",
    "rules", "verdict", "reasons", "memory_us", "edge_response", "worst": {"vstart": {"value",
    "limit", "margin", "unit" (V; s for the widths and the edge), "bound", "frames",
    "error_bits", "gaps_us", "pulse", "reproduce" (a stimulus block)}, "vend", "width_min",
    "width_max", "edge"}, ...}]}.)doc";

inline constexpr const char* kNoise =
    R"doc(Common-mode noise immunity over frequency (BCI, ground shift).

As `isolink noise SPEC --json` (nothing written): per direction the CM->DM conversion, the pin
common mode, the immunity per frequency (A or V) and the worst frequency, confirmed in the time
domain; the spec's noise: block sets the injection, level and band.

Args:
    spec: a link spec, a path or a dict.
    parts: extra part-library folders.

Returns:
    `isolink noise --json`'s object: {"verdict", "injection", "level", "level_unit" (A or V),
    "immunity_min_db" (dB re the level), "directions": [{"direction", "points": [{"freq_hz",
    "cm_to_dm_db", "pin_cm_v", "dm_v", "immunity", "limited_by", ...}], "immunity_min":
    {"value", "freq_hz"}, "verdict", "budget", "time_domain", ...}], ...}.)doc";

inline constexpr const char* kSim =
    R"doc(Simulate a SPICE netlist (ngspice dialect), as `isolink sim`.

Args:
    netlist: a path (str or os.PathLike) or the netlist's text (a str with a line break);
        .include paths in text are taken from the current working directory.
    probes: signals to record: "v(node)", "v(a,b)" (V(a) - V(b)), "i(Vname)" or "i(Lname)".
    engine: "auto" (LTI where it is the cheaper engine, else transient), "lti", "transient".
    step: a uniform output grid, in seconds (1e-9 or "1n"); None: the LTI engine's grid (linear
        interpolation within 1 mV) or the transient's own steps.
    tstop, tmax: end time and largest step in seconds, overriding .tran.
    method: "trap" or "gear" (transient), overriding .options method.
    reltol: the transient's relative tolerance (1e-9 to 0.1).

Returns:
    {"time": array (s), "<probe>": array (V or A), ...}: the columns of `isolink sim`'s CSV.
    Solver warnings (the CLI's stderr lines) are UserWarnings.)doc";

inline constexpr const char* kSweep = R"doc(Run a sweep on all cores, as `isolink sweep --no-plots`.

Args:
    sweep: a sweep, a path or a dict ({"base": spec path or dict, "sweep": {"cable.length":
        [1, 5, 10]}, "mode", "monte_carlo", "outputs"}).
    out: the folder for results.csv and summary.json (kept for resuming); None: a temporary
        folder, removed afterwards.
    jobs: threads (0: all cores).
    engine: "auto", "lti" or "transient".
    parts: extra part-library folders.

Returns:
    One dict per point, in point order, keyed by results.csv's columns: "point", the swept
    keys, "verdict", "worst_metric", "worst_margin_rel", "margin_vstart_V", "margin_vend_V",
    "margin_width_ns", "margin_edge_ns", "decoded_ok", "fail_reason", "seconds", "error", "path"
    ("edges": the fast path, or "simulated: <why>"), ...
    None for an empty cell, bool for decoded_ok, int for point, float for numbers.)doc";

inline constexpr const char* kPack =
    R"doc(Simulate a whole daisy chain, as `isolink pack` (nothing written).

Every hop (each distinct circuit once), the ring's cable breaks and command timing.

Args:
    pack_spec: a pack spec, a path or a dict ({"bridge", "stack", "hops": [...], "ring", ...}).
    jobs: threads across distinct circuits (0: all cores).
    worst: the worst case over all traffic per hop too (`isolink pack` without --no-worst).
    parts: extra part-library folders.

Returns:
    the pack's report.json: {"verdict", "weakest_hop", "hops": [{"index", "verdict",
    "directions": [...] as run()'s}], "ring_breaks": [...], "timing": {...}, ...}.)doc";

inline constexpr const char* kStress =
    R"doc(What breaks a link in the field, as `isolink stress SPEC --json` (nothing written).

Each scenario (module-ground steps during traffic, IEC 61000-4-2 contact ESD, and the kinds
docs/stress.md lists) runs the link's circuit with the pins' clamp diodes and the spec's TVS
parts; its peaks are checked against the limits of the spec's stress: block.

Args:
    spec: a link spec, a path or a dict.
    only: the scenario kinds to run (["esd"], ["cm_step"], ...; empty: the spec's stress.only,
        else all).
    parts: extra part-library folders.

Returns:
    `isolink stress --json`'s object: {"verdict", "survives", "communicates", "limits": {KEY:
    {"value", "source"}}, "scenarios": [{"id", "kind", "end", "line", "level", "peak_pin_v":
    {NODE: {"max", "min"}}, "diodes", "isolation_caps", "contacts" (hot_plug), "traffic", "survives", "communicates",
    "first_broken", ...}]}, in SI units.)doc";

inline constexpr const char* kCheck = R"doc(Score a differential waveform against receiver rules.

As `isolink check --json` (less its "input").

Args:
    t: times in seconds, increasing (a 1-D array or sequence).
    v: differential voltage in volts at those times.
    rules: "bq7961x", "bq79600", "tone" or a YAML rule file's path.
    expect: the bytes expected, in hex ("80 00 02 15"); a mismatch fails.

Returns:
    {"verdict": "pass"|"fail"|"inconclusive", "reasons", "summary": {"vstart_min" (V),
    "vend_min", "width_min_ns", ..., "worst": {metric: {"value", "limit", "margin"}}},
    "pulses": [...], "decoded": [...], "pass": bool}.)doc";

inline constexpr const char* kLoadSpec =
    R"doc(Read a link spec: every key with its default filled in.

Args:
    spec: a link spec, a path or a dict.

Returns:
    report.json's "spec": {"name", "tx", "rx", "cable", "stimulus", "sim", ...}.)doc";

}  // namespace isolink::python::doc
