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
};

struct LinkRun {
  std::vector<DirectionRun> directions;
  bool pass = false;   // every direction passes
  double seconds = 0;  // wall time, all directions
};

struct RunOptions {
  link::ExpandOptions expand;
  std::optional<double> reltol;  // overrides the spec's sim.reltol
  Engine engine = Engine::Auto;  // LTI when the link allows it (every link today)
  // Progress for a display: what runs ("down transient") and the fraction done (0-1).
  std::function<void(const std::string& what, double fraction)> progress;
};

// The probes recorded per direction, in column order.
const std::vector<std::string>& run_probes();

StatusOr<LinkRun> run_link(const link::LinkSpec& spec, const link::PartLibrary& parts,
                           const RunOptions& opt = {});
// run_link for a caller that computes the worst case as well (the sweep): each direction's edge
// response (edge_response with `wopt`) also gives its traffic's v(rxp,rxn), by exact
// superposition on the response's 1 ns grid (run_direction_synthesized), instead of a second
// model of the link and a finer output grid. A direction whose drive is off that grid is
// simulated (run_direction). `edges` receives one response per direction, for worst_case, or
// none when a direction was simulated. A direction with the same circuit key as one before
// (link::circuit_key) takes its response and result (same_as).
StatusOr<LinkRun> run_link_from_edges(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                      const RunOptions& opt, const WorstOptions& wopt,
                                      std::vector<EdgeResponse>& edges);
// Per direction of `run`, the index of the earlier direction it is the same circuit as (its
// same_as), or -1: what worst_case needs to skip its own circuit keys.
std::vector<int> same_circuits(const LinkRun& run);
// One expanded direction simulated and scored: run_link's work per direction (packs expand every
// hop first and simulate each distinct circuit once).
StatusOr<DirectionRun> run_direction(link::ExpandedLink link, const RunOptions& opt = {});

// One expanded direction scored on v(rxp,rxn) synthesized from its edge response (worst.h,
// synthesize_drive: exact superposition on the response's 1 ns grid) instead of simulated: the
// sweep's path when it computes the worst case, whose edge response it shares. The waveform has
// that one column; an error when a level change of the drive is off the grid.
StatusOr<DirectionRun> run_direction_synthesized(link::ExpandedLink link, const EdgeResponse& e);
// Scores dr.sim.wave (column 0, v(rxp,rxn)) with the receiver's rules: dr.rules, data, tones,
// pass. Used by both of the above.
Status score_direction(DirectionRun& dr);

// The probes of every direction, resampled onto one uniform axis, columns "down v(rxp,rxn)", ...
Waveform run_waveforms(const LinkRun& run, double dt);

}  // namespace isolink::analysis
