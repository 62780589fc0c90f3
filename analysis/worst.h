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
//    0 -> +1 level change (edge_response; today from a tight transient run until it settles).
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

#include <complex>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

// The receiver's response to one driver edge, on a uniform grid.
struct EdgeResponse {
  double dt = 1e-9;       // sample spacing (s)
  long pre = 0;           // e[pre] is at the corner (the middle of the driver's ramp)
  std::vector<double> e;  // v(rxp,rxn) after a 0 -> +1 level change, minus v_idle (V)
  double v_idle = 0;      // v(rxp,rxn) with the line idle (V)
  double span = 0;        // simulated time after the corner (s)
  double settle = 0;      // max |e - e.back()| over the last 10 % of the span (V)
  double drift = 0;       // max |E(t) - E(t - T)| over the last 10 %: a half bit's residue (V)
  // With WorstOptions::more_probes: the same response of each of those probes (in that order),
  // e minus v_idle of that probe, on the same grid (the spec traffic's other columns).
  struct Column {
    std::string probe;
    std::vector<double> e;
    double v_idle = 0;
  };
  std::vector<Column> more;
  // The reduced model's closed form past the driver's ramp (empty from the transient, and in a
  // coarsened copy): at n >= start samples after the corner, e is
  //   constant[0] + sum_i Re(amplitude[0][i] z_i^(n - start)),  z_i = e^{p_i dt},
  // and more's column c the same with constant[c + 1], amplitude[c + 1] (each minus its v_idle).
  // It is the model the record was sampled from (checked against the record when made), and it
  // goes on past the record's end where at() holds the last sample.
  struct Tail {
    long start = 0;
    std::vector<std::complex<double>> z;                       // per mode
    std::vector<double> constant;                              // per column
    std::vector<std::vector<std::complex<double>>> amplitude;  // [column][mode]
  };
  std::optional<Tail> tail;
  std::string engine;       // what produced it ("reduced model, order 119 ...", "transient ...")
  std::string engine_note;  // edge_engine auto: why the reduced model was not used
  double seconds = 0;       // wall time
  // Hz, the reduced model's expansion points (WorstOptions::reduced_start_points of a
  // neighbouring link); empty from the transient.
  std::vector<double> expansion_points;
  // e at n samples after the corner: 0 before the record, e.back() after it.
  double at(long n) const {
    const long i = n + pre;
    if (i < 0) return 0.0;
    if (i >= static_cast<long>(e.size())) return e.back();
    return e[static_cast<size_t>(i)];
  }
};

struct WorstOptions {
  double dt = 1e-9;          // synthesis grid (s); edges and gaps fall on it
  double gap_min = 3.8e-6;   // shortest idle between byte frames (traffic::Timing byte_gap)
  double gap_step = 50e-9;   // gap grid of the previous byte (s)
  double tail_tol = 0.5e-3;  // V: the memory ends where the tail bound falls below this
  // The edge response's engine: `auto` takes the LTI engine's reduced model (solver/lti.h,
  // checked against the exact AC solution within 2e-5 of the peak from 1 kHz to 3 GHz) and falls
  // back to the transient when the model does not pass; `transient` always runs the transient.
  enum class EdgeEngine { Auto, Transient };
  EdgeEngine edge_engine = EdgeEngine::Auto;
  // Hz: the reduced model's first expansion points (ReducedModelOptions::start_points), e.g. the
  // expansion_points of the same link with other part values (isolink compare's fit); the model
  // passes the same check either way.
  std::vector<double> reduced_start_points;
  // The same per direction (a sweep's point 0, sweep::PointOptions::start_points): an entry for
  // the direction of edge_response replaces reduced_start_points.
  std::map<link::Direction, std::vector<double>> reduced_start_points_by_direction;
  double reltol = 1e-6;       // transient tolerance of the edge response
  double settle_tol = 20e-6;  // V: settled when a half bit's response stays below this
  double max_memory = 20e-6;  // s: longest memory searched; B there is reported as the bound
  double max_span = 400e-6;   // s: longest edge-response run before giving up
  int max_candidates = 24;    // target patterns carried into the history search per metric
  int verify = 6;             // best-ranked histories scored exactly per candidate and metric
  bool exhaustive = false;    // score every target x history combination (brute force)
  // Restrict the patterns searched (tests; empty = all 512). A pattern is byte | error_bit << 8.
  std::vector<int> targets;
  std::vector<int> previous;
  link::ExpandOptions expand;  // driver, load, encoding (its half bit is the T above)
  // Probes recorded besides v(rxp,rxn) (EdgeResponse::more): the sweep's fast path asks for the
  // other columns of a run (v(rxp), v(rxn), v(txp,txn)) when its noise analysis or waveform files
  // need them. The reduced model is then checked on these probes too.
  std::vector<std::string> more_probes;
  // Progress for a display: what runs ("down edge response", "down search") and the fraction
  // of it done (0-1). Empty: none.
  std::function<void(const std::string& what, double fraction)> progress;

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

// The edge response of one direction of the link (the one adapter to the engine).
StatusOr<EdgeResponse> edge_response(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                     link::Direction d, const WorstOptions& opt);

// e on a grid k times coarser: every k-th sample counted from the corner (e.pre a multiple of
// k), settle and drift measured again with opt's half bit; `more` dropped. The response
// edge_response gives with dt = k e.dt, from the same model sampled at the same times (the sweep
// synthesizes its traffic on the fine grid and searches the worst case on the coarse one).
EdgeResponse coarsened(const EdgeResponse& e, int k, const WorstOptions& opt);

// B(tau): the most that half bits older than tau (s) can move v (V). See the method above.
double tail_bound(const EdgeResponse& e, double half_bit, double tau);

// v(rxp,rxn) of traffic by superposition, on [t0, t1] every e.dt (times from the record start).
Waveform synthesize(const EdgeResponse& e, const Traffic& traffic,
                    const traffic::EncodingOptions& enc, double t0, double t1);

// v(rxp,rxn) of a whole drive (a link's own traffic, link::ExpandedLink::drive) by superposition,
// on [0, t_end] every e.dt: exact at the samples for the link whose edge response e is. Every
// level change must fall on the grid (within 1e-6 of a sample); an error names the first that
// does not. The probes of e.more follow as further columns, each superposed the same way.
StatusOr<Waveform> synthesize_drive(const EdgeResponse& e, const traffic::Drive& drive,
                                    double t_end);

// Whether every level change of the drive falls on a grid of step dt (within 1e-6 of a step).
bool on_grid(const traffic::Drive& drive, double dt);

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
