// The worst case over all legal daisy-chain traffic (`isolink worst`, the "Worst case over all
// traffic" section of `isolink run`): per direction, the lowest VSTART, the lowest VEND, the
// narrowest and widest pulse and the slowest edge any legal traffic can produce at the receiver,
// the traffic that produces each, and a stimulus block that replays it.
//
//   StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
//   StatusOr<WorstResult> w = worst_case(spec, *parts, {});
//   for (const DirectionWorst& d : w->directions) d.metric("vstart")->value ...
//   std::puts(reports::worst_json(*w).dump(2).c_str());  // reports/worst_report.h
//   return w->pass ? 0 : 1;
//
// Method (the README "Worst case over all traffic" has the argument in full):
// 1. Every link is linear and time-invariant, and the driver moves both lines by the same linear
//    10 ns ramp scaled by the level change (P = 2.5 (1 + L), N = 2.5 (1 - L)), so the receiver's
//    v(t) for any traffic is exactly v_idle + sum_i dL_i E(t - t_i): E is the response to one
//    0 -> +1 level change (edge_response.h: edge_response, sampled until it settles).
// 2. Memory: p(t) = E(t) - E(t - T) is one half bit's response. Half bits older than tau move v
//    by at most B(tau) = sum_k max |p| over [tau + kT, tau + (k + 1) T) (|level| <= 1, at most one
//    half bit per T). The memory M is the smallest tau with B(tau) <= tail_tol (at most
//    max_memory; B(M) is reported either way). The edge response is run until a half bit's
//    response E(t) - E(t - T) stays below settle_tol over the last 10 % of the run; past the run E
//    is taken as constant (a slow residual drift cancels in DC-balanced frames to first order).
// 3. Traffic inside the memory of one byte frame (the "target": any byte, error bit 0 or 1, 512
//    patterns) is the previous byte frame (512 patterns or none) at a gap g >= gap_min (3.8 us,
//    the shortest the devices produce) on a gap_step grid up to M; anything older is at least
//    2 gap_min + 6.5 us before the target and is covered by the bound B (reported).
// 4. Search: every target pattern is scored with the eye checker (eye/check.h, the same metric
//    definitions as `isolink check`) after idle; the target patterns within a slack of the best
//    for each metric (the slack is what the previous byte can change it by: 2 x its bound, in
//    volts or, divided by the slowest crossing slope, in seconds) are then combined with every
//    previous byte and gap, ranked by the first-order change each makes to every pulse's metric,
//    and the best-ranked ones are scored exactly. A byte frame is affine in its 9 free bits, so
//    each predicted change is too: per gap the ranking reads each metric's best previous bytes
//    off the per-bit coefficients rather than trying all 512. With `exhaustive`, every
//    combination is scored (brute force; the tests check the search against it).
//
// Contract:
// - Units: SI (s, V); WorstMetric value, limit and margin in the metric's unit (V for vstart and
//   vend, s for widths and edges); EdgeResponse samples on its grid of dt seconds.
// - Ownership: results own their traffic and records; an EdgeResponse is a value (copy it freely).
//   WorstOptions::progress is called on the calling thread.
// - Errors: a Status, never thrown: options that do not hold (WorstOptions::validate), a spec that
//   does not expand, an edge response that does not settle within max_span or is not finite, an
//   encoding whose frames are not affine in their bits. A failing worst case is pass false.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "analysis/edge_response.h"
#include "base/status.h"
#include "base/waveform.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

// The search's options; the edge response's (dt, edge_engine, reltol, settle_tol, max_span,
// expand, more_probes, progress, ...) are EdgeResponseOptions's (edge_response.h).
struct WorstOptions : EdgeResponseOptions {
  double gap_min = 3.8e-6;    // shortest idle between byte frames (traffic::Timing byte_gap)
  double gap_step = 50e-9;    // gap grid of the previous byte (s)
  double tail_tol = 0.5e-3;   // V: the memory ends where the tail bound falls below this
  double max_memory = 20e-6;  // s: longest memory searched; B there is reported as the bound
  int max_candidates = 24;    // target patterns carried into the history search per metric
  int verify = 6;             // best-ranked histories scored exactly per candidate and metric
  bool exhaustive = false;    // score every target x history combination (brute force)
  // Restrict the patterns searched (tests; empty = all 512). A pattern is byte | error_bit << 8.
  std::vector<int> targets;
  std::vector<int> previous;

  Status validate() const;  // names the field, its value and the rule
};

// A byte frame as sent.
struct ByteFrame {
  uint8_t byte = 0;
  int error_bit = 0;
};

// Byte frames with the idle before each (gaps[0]: idle before the first; nothing earlier).
struct Traffic {
  std::vector<ByteFrame> frames;
  std::vector<double> gaps;  // s, one per frame
  // Start of frame i's preamble (s), the first frame starting at gaps[0].
  double frame_start(size_t i, double byte_duration) const;
};

// One metric's worst value.
struct WorstMetric {
  std::string name;       // vstart | vend | width_min | width_max | edge
  double value = 0;       // V or s
  double limit = 0;       // V or s
  double margin = 0;      // distance to the limit, positive = inside
  double bound = 0;       // how much worse older traffic could make it (V or s), >= 0
  Traffic traffic;        // the traffic that produces it (the last frame holds the pulse)
  double pulse_time = 0;  // the worst pulse's start crossing a, from the record's start (s)
  int pulse_sign = 0;     // +1 / -1
  std::string role;       // its place in the frame ("bit 3", "postamble", ...)
  double record = 0;      // length of the replayed record (s)
};

struct DirectionWorst {
  link::Direction direction = link::Direction::kDown;
  std::string description;  // "down: bq79600 -> bq7961x"
  std::string receiver;     // device
  eye::Rules rules;         // the receiver's data rules
  EdgeResponse edge;
  double memory = 0;          // s
  double gap_min = 0;         // s, shortest gap searched (the range runs to idle)
  double gap_max = 0;         // s, longest gap on the grid; longer ones count as idle
  double older_bound = 0;     // V: traffic older than the previous byte moves v by at most this
  double previous_bound = 0;  // V: the previous byte moves v by at most this
  long scored = 0;            // waveforms scored with the eye checker
  long ranked = 0;            // histories ranked by first-order change
  double seconds = 0;
  // The direction whose result this is when the link is the same circuit both ways (the same
  // parts at both ends): computed once. Empty when computed for this direction.
  std::string same_as;
  std::vector<WorstMetric> metrics;  // vstart, vend, width_min, width_max, edge
  bool pass = true;                  // every scored waveform passes and every margin >= 0
  std::vector<std::string> reasons;  // why not (the first failing traffic per reason)
  const WorstMetric* metric(const std::string& name) const;
};

struct WorstResult {
  std::vector<DirectionWorst> directions;
  bool pass = true;
  double seconds = 0;
};

// B(tau): the most that half bits older than tau (s) can move v (V). See the method above.
double tail_bound(const EdgeResponse& e, double half_bit, double tau);

// v(rxp,rxn) of traffic by superposition, on [t0, t1] every e.dt (times from the record start).
Waveform synthesize(const EdgeResponse& e, const Traffic& traffic,
                    const traffic::EncodingOptions& enc, double t0, double t1);

// The worst case of every direction in spec.stimulus.directions; `edges`, when given, are their
// edge responses (one per direction, in order, from edge_response with the same options).
// `same`, when given, says per direction which earlier direction is the same circuit (its index,
// or -1), as a run of the same spec found it (same_circuits of link_run.h); otherwise each
// direction's link::circuit_key is compared here.
StatusOr<WorstResult> worst_case(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                 const WorstOptions& opt = {}, std::vector<EdgeResponse> edges = {},
                                 std::vector<int> same = {});
// One direction, from its edge response (tests build their own).
StatusOr<DirectionWorst> worst_case_direction(const EdgeResponse& e, const eye::Rules& rules,
                                              const WorstOptions& opt);

// The traffic as a StimulusSpec (frames "raw HH nocrc [err]", gaps, the direction).
link::StimulusSpec reproduce_spec(const WorstMetric& m, link::Direction d);

}  // namespace isolink::analysis
