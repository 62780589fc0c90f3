// Netlist -> Circuit -> waveform (LTI or transient engine): the path shared by `isolink sim` and
// `isolink run`.
//
//   SimulationRequest req{.probes = {"v(rxp,rxn)"}};
//   StatusOr<SimulationResult> r = simulate_netlist(netlist, req);
//   for (auto& w : r->warnings) print(w);
//
// Contract:
// - Units: SI (s, V, A); probes as in the netlist ("v(a,b)", "i(Vname)").
// - Ownership: the result owns its waveform and texts; the netlist is read, not kept.
// - Errors: a Status, never thrown: a card or .ic that does not build (file:line:col), a probe
//   that names nothing, a run over kMemoryLimitBytes or kMaxGridRows (at the .tran card: its rows
//   or its sources' corners), a
//   forced `lti` the circuit does not allow, an engine that fails. simulate_netlist puts the
//   netlist's and the circuit's warnings before the message.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/transient_check.h"
#include "base/waveform.h"
#include "netlists/spice_reader.h"
#include "solver/lti.h"
#include "solver/port_model.h"
#include "solver/transient.h"

namespace isolink::analysis {

// auto: for a circuit with nonlinear elements (diodes), the port model (solver/port_model.h)
// when it builds and passes its check, else the transient (self-checked); for a linear one, the
// LTI engine when the circuit allows it (check_lti: every element LTI, every source DC, PULSE or
// PWL, no .tran uic) and it is the cheaper engine (responses settled within a quarter of the
// run, kAutoLtiMaxSteps, kAutoLtiBudget), else the transient; lti: the LTI engine or an error
// naming the element; port: the port model or an error saying why not; transient: always the
// transient.
enum class Engine { Auto, Lti, PortModel, Transient };
// Every engine, in the order the choices are listed (parse_engine, the CLI's --engine, Python).
inline constexpr std::array<Engine, 4> kEngines = {Engine::Auto, Engine::Lti, Engine::PortModel,
                                                   Engine::Transient};
const char* engine_name(Engine e);
// What the engine does, in a few words for --engine's help ("LTI where ...").
const char* engine_summary(Engine e);
// "auto", "lti", "transient" -> Engine; an error names the value and the choices.
StatusOr<Engine> parse_engine(const std::string& text);

// auto runs the LTI output only while each grid level's probe evaluations stay under this many
// times (march steps x unknowns). Measured 2026-11-30: a probe evaluation costs about 10 ns and a
// transient step about 8 ns per unknown, and the transient takes 1-4 times the march's steps; 4
// keeps the exact engine wherever the two cost about the same (xfmr_link_15m: 1.2 s LTI, 1.1 s
// transient) and leaves it where it is far slower (cap_2m with its traffic: 9.8 s against 0.7 s,
// its responses never settling within the run).
inline constexpr double kAutoLtiBudget = 4.0;
inline constexpr long kAutoLtiMaxSteps = 400'000;

// The most output rows a --step grid may ask for.
inline constexpr size_t kMaxGridRows = 10'000'000;

// The memory one run may take (issue 28): what grows with the run is bounded by it, and a run
// whose least need is over it is refused before the engine starts, with a diagnostic at the
// .tran card naming the limit. What is counted (8 bytes a value; `columns` = time + probes):
// - the transient engine: one row per accepted step, at least span / TMAX rows, at most
//   max_steps (lowered so that twice the rows, a vector's growth, fit);
// - a --step grid: span / step rows;
// - the LTI output grid: at most GridOptions::max_rows rows, lowered so that four copies of
//   them fit (rows, midpoints, the next pass);
// - the LTI march: 1 + 2 x sources x probes values a step, max_steps lowered so twice that fits;
// - the reduced model's basis: at most 384 MB (solver/reduced_model.cpp, kMaxBasisBytes);
// - the sources' corners, counted before either engine lists them: about 4 rows a corner plus
//   kCornerListBytes (below).
inline constexpr double kMemoryLimitBytes = 1024.0 * 1024.0 * 1024.0;
// A source corner's memory besides its rows: its entries in the engines' lists of corners (the
// transient's sorted breakpoints, the LTI engine's corner times and ramps). With 4 rows a corner
// (the transient steps onto each corner and once more just after it, two rows, which a vector's
// growth can double; the LTI grid has a row at each corner and refines after it, with the
// midpoints and the next pass beside it), an RC under PULSE(0 1 0 1n 1n 1u 2u) recording one
// probe is estimated at 112 bytes a corner; measured on the LTI engine, peak memory: 10 million
// corners 1.16e9 bytes (estimate 1.12e9), 2 million 3.6e8 (2.2e8: more rows where it bends).
inline constexpr double kCornerListBytes = 48;

struct SimulationRequest {
  std::vector<std::string> probes;           // v(a), v(a,b), i(name)
  std::optional<double> tstop, tstep, tmax;  // override the netlist's .tran
  std::optional<IntegrationMethod> method;   // override .options method
  std::optional<double> reltol;              // override .options reltol (transient engine)
  Engine engine = Engine::Auto;
  // The LTI engine's method (solver/lti.h): auto = the reduced model when it passes its check.
  LtiOptions::Method lti_method = LtiOptions::Method::Auto;
  // LTI output grid: step (0 = the 1 mV rule, LtiResponses::GridOptions) and the probes the rule
  // looks at (empty = all). The transient ignores both (its rows are its steps).
  double grid_step = 0.0;
  std::vector<bool> grid_probes;
  // LTI engine, reduced model, on the 1 mV rule (grid_step 0): keep only the engine's rows that
  // linear interpolation between kept rows needs to stay within record_tol (V; A/1000 for
  // current probes) of every engine row on every probe, thinned window by window as the engine
  // makes them (analysis/link_run_wave.h thin_rows; each window's ends kept), so the run holds
  // the kept rows and one window. Rows are thinned only once the record holds record_full_rows
  // (a short record keeps every row, as with 0). 0: every engine row. SimulationResult::record_tol
  // and a note in warnings say when it applied; grid.rows counts the engine's rows, wave the
  // kept ones.
  double record_tol = 0.0;
  size_t record_full_rows = 2'000'000;
  // Threads the LTI engine's output grid may use (solver/lti.h GridOptions::threads; the rows do
  // not depend on it). A sweep running points side by side leaves it at 1.
  int lti_threads = 1;
  // Progress of the engine for a display: its phase ("transient", "LTI responses") and the
  // fraction of it done (0-1), every 1024 engine steps. Empty: none.
  std::function<void(const char* phase, double fraction)> progress;
};

struct SimulationResult {
  Waveform wave;
  Engine engine = Engine::Transient;  // the engine that produced the waveform (not auto)
  std::string engine_note;            // why auto chose the transient, when it did
  TransientStats stats;               // transient engine
  LtiStats lti;                       // LTI engine
  PortModelStats port;                // port model engine
  LtiResponses::GridInfo grid;        // LTI engine: the output grid
  // The rows of `wave` are the engine's rows thinned within this (SimulationRequest::record_tol)
  // from some time on (the note in warnings says when), 0 when they are all of them.
  double record_tol = 0.0;
  std::vector<std::string> warnings;  // formatted, for stderr
  int nodes = 0, unknowns = 0, elements = 0;
  double seconds = 0.0;  // wall time of the engine
  // auto: wall time spent on the LTI engine before it gave way to the transient (part of
  // `seconds`); 0 when it did not.
  double lti_attempt_seconds = 0.0;
  double reltol = 0.0, trtol = 0.0;  // the transient's tolerances (engine transient)
  // auto's transient fallback: the runs at ever tighter reltol until two agree
  // (transient_check.h); reltol above is the kept run's. Empty otherwise.
  std::optional<TransientConvergence> convergence;
};

// The accuracy the engine that produced `r` promises, one sentence with its figures, for the
// run's statistics (issue 28: `auto` never trades accuracy silently): the reduced model's bound
// per edge from its check, the march's and the transient's error control and what they gave
// against converged references (docs/solver.md).
std::string engine_accuracy(const SimulationResult& r);

StatusOr<SimulationResult> simulate_netlist(const Netlist& netlist, const SimulationRequest& req);

}  // namespace isolink::analysis
