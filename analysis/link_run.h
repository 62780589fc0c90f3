// One link spec, simulated and scored in each of its directions: the work of `isolink run` and
// of every sweep point.
//
//   StatusOr<PartLibrary> parts = PartLibrary::load(part_dirs);
//   StatusOr<LinkRun> run = run_link(spec, *parts, {});
//   for (const DirectionRun& d : run->directions) ... d.data->pass, d.sim.wave ...
//   return run->pass ? 0 : 1;
// Each direction is its own simulation (the link is half-duplex), by the engine RunOptions::engine
// names (auto: LTI where it is the cheaper engine, else the transient; analysis/simulate.h). Data
// frames are scored with the receiving device's rule set and tones with the tone rules, each over
// its own time windows.
//
// Contract:
// - Units: SI (s, V); margins as eye/metrics.h gives them.
// - Ownership: a LinkRun owns its expanded links, waveforms and checks; the spec and the part
//   library are read, not kept (a run outlives them).
// - Errors: a Status, never thrown: a spec that does not expand (the key's file:line:col), a
//   simulation that fails (analysis/simulate.h), rules that do not validate. A link that fails
//   its rules is a result with pass false, not an error.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/simulate.h"
#include "analysis/worst.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

struct DirectionRun {
  link::ExpandedLink link;
  SimulationResult sim;                   // columns: v(rxp,rxn), v(rxp), v(rxn), v(txp,txn)
  eye::Rules rules;                       // the receiver's data rules
  eye::Rules tone_rules;                  // the tone rules (when tones were sent)
  std::optional<eye::CheckResult> data;   // the data frames' check (when any were sent)
  std::optional<eye::CheckResult> tones;  // the tones' check (when any were sent)
  bool pass = false;
  // The direction whose simulation this is, when both are the same circuit and traffic
  // (link::circuit_key: the same parts at both ends): simulated once. Empty when simulated.
  std::string same_as;
  // run_link_from_edges: empty when v(rxp,rxn) was synthesized from the edge response, else why
  // this direction was simulated instead ("the drive changes level at 1.0003 us (off the 1 ns
  // grid of the edge response)"). Always empty from run_link.
  std::string simulated_why;
};

struct LinkRun {
  std::vector<DirectionRun> directions;
  bool pass = false;   // every direction passes
  double seconds = 0;  // wall time, all directions
};

// The default of RunOptions::record_tol (V).
inline constexpr double kRecordTolerance = 1e-3;

struct RunOptions {
  link::ExpandOptions expand;
  std::optional<double> reltol;  // overrides the spec's sim.reltol
  Engine engine = Engine::Auto;  // LTI when the link allows it (every link today)
  // V: the record each direction keeps (SimulationRequest::record_tol): the LTI engine's rows
  // that linear interpolation needs to stay within this of every engine row (the engine's own
  // rule puts its rows within 1 mV of the exact response, so the kept rows are within
  // 1 mV + record_tol), thinned as the engine makes them: a long record holds the kept rows and
  // one engine window, not every row. 0: every engine row (`isolink run --wave rows`).
  double record_tol = kRecordTolerance;
  int threads = 1;  // SimulationRequest::lti_threads
  // SimulationRequest::record_full_rows: rows kept in full before record_tol applies.
  size_t record_full_rows = SimulationRequest{}.record_full_rows;
  // Progress for a display: what runs ("down transient") and the fraction done (0-1).
  std::function<void(const std::string& what, double fraction)> progress;
};

// The probes recorded per direction, in column order.
const std::vector<std::string>& run_probes();

StatusOr<LinkRun> run_link(const link::LinkSpec& spec, const link::PartLibrary& parts,
                           const RunOptions& opt = {});
// The sweep's fast path synthesizes the traffic on a grid this many times finer than the worst
// case's (WorstOptions::dt, 1 ns): 0.25 ns. Between samples the eye checker interpolates
// linearly, which errs by up to dt^2 / 8 |v''|: on the 1 ns grid up to 3.2 mV and 29 ps against
// the LTI engine's run on the corpus test's links (short cables, sharp ringing), on 0.25 ns
// within 1 mV and 25 ps (tests/analysis/fast_path_test.cpp).
inline constexpr int kSynthesisOversample = 4;

// run_link on the sweep's fast path: each direction's edge response (edge_response with `wopt`,
// sampled kSynthesisOversample times finer than wopt.dt) gives its traffic's waveform by exact
// superposition on that grid (run_direction_synthesized), instead of a model of the link stepped
// through the traffic; the same response, every kSynthesisOversample-th sample (coarsened),
// serves worst_case. The waveform has v(rxp,rxn) and the probes of wopt.more_probes (all of
// run_probes() when the caller needs the pins or the driver: the noise analysis, waveform
// files). A direction is simulated (run_direction) instead, and says why in its simulated_why,
// when its drive changes level off the fine grid or its edge response cannot be computed (it
// has not settled within wopt.max_span, say). `edges`, unless null, receives one response per
// direction on wopt.dt's grid, for worst_case, or none when a direction was simulated (null: no
// coarsened copies are made, a plain sweep's case). A direction with the
// same circuit key as one before (link::circuit_key) takes its response and result (same_as).
StatusOr<LinkRun> run_link_from_edges(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                      const RunOptions& opt, const WorstOptions& wopt,
                                      std::vector<EdgeResponse>* edges);
// "down: why; up: why" over the directions of a run_link_from_edges run that were simulated;
// empty when every direction was synthesized.
std::string simulated_note(const LinkRun& run);
// Per direction of `run`, the index of the earlier direction it is the same circuit as (its
// same_as), or -1: what worst_case needs to skip its own circuit keys.
std::vector<int> same_circuits(const LinkRun& run);
// One expanded direction simulated and scored: run_link's work per direction (packs expand every
// hop first and simulate each distinct circuit once).
StatusOr<DirectionRun> run_direction(link::ExpandedLink link, const RunOptions& opt = {});

// One expanded direction scored on v(rxp,rxn) synthesized from its edge response (edge_response.h,
// synthesize_drive: exact superposition on the response's grid) instead of simulated: the
// sweep's path. The waveform has that column and one per probe of e.more; an error when a level
// change of the drive is off the grid.
StatusOr<DirectionRun> run_direction_synthesized(link::ExpandedLink link, const EdgeResponse& e);
// Scores dr.sim.wave (column 0, v(rxp,rxn)) with the receiver's rules: dr.rules, data, tones,
// pass. Used by both of the above.
Status score_direction(DirectionRun& dr);

// The probes of every direction, resampled onto one uniform axis, columns "down v(rxp,rxn)", ...
Waveform run_waveforms(const LinkRun& run, double dt);

}  // namespace isolink::analysis
