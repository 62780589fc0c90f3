// The edge response: the receiver's response to one driver edge, on a uniform grid, and the
// superposition that makes the receiver's waveform of any drive from it. The worst-case search
// (worst.h), the sweep's fast path (link_run.h, run_link_from_edges) and compare's fit
// (compare_model.h) stand on it.
//
//   EdgeResponseOptions opt;  // a WorstOptions is one too
//   StatusOr<EdgeResponse> e = edge_response(spec, parts, link::Direction::kDown, opt);
//   StatusOr<link::ExpandedLink> ex = link::expand_link(spec, parts, link::Direction::kDown, {});
//   if (on_grid(ex->drive, e->dt)) StatusOr<Waveform> w = synthesize_drive(*e, ex->drive, t_end);
//
// Method: every link is linear and time-invariant, and the driver moves both lines by the same
// linear 10 ns ramp scaled by the level change (P = 2.5 (1 + L), N = 2.5 (1 - L)), so the
// receiver's v(t) for any drive is exactly v_idle + sum_i dL_i E(t - t_i): E is the response to
// one 0 -> +1 level change. edge_response drives the link with that one edge and samples E from
// the LTI engine's reduced model in closed form (EdgeEngine::Auto; the transient when the model
// does not pass its check) on records of 40 us, doubled until a half bit's response
// E(t) - E(t - T) stays below settle_tol over the last 10 % of the record; past the record E is
// taken as constant, or continued by the model's closed form (EdgeResponse::tail).
//
// Contract:
// - Units: SI (s, V); EdgeResponse samples on its grid of dt seconds.
// - Ownership: an EdgeResponse is a value (copy it freely). EdgeResponseOptions::progress is
//   called on the calling thread.
// - Errors: a Status, never thrown: a spec that does not expand, an edge response that does not
//   settle within max_span or is not finite, a drive whose level changes fall off the grid.
#pragma once

#include <complex>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
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
  // With EdgeResponseOptions::more_probes: the same response of each of those probes (in that
  // order), e minus v_idle of that probe, on the same grid (the spec traffic's other columns).
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
  // Hz, the reduced model's expansion points (EdgeResponseOptions::reduced_start_points of a
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

// How edge_response makes it (WorstOptions adds the search's options to these).
struct EdgeResponseOptions {
  double dt = 1e-9;  // synthesis grid (s); edges and gaps fall on it
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
  double reltol = 1e-6;        // transient tolerance of the edge response
  double settle_tol = 20e-6;   // V: settled when a half bit's response stays below this
  double max_span = 400e-6;    // s: longest edge-response run before giving up
  link::ExpandOptions expand;  // driver, load, encoding (its half bit is the T above)
  // Probes recorded besides v(rxp,rxn) (EdgeResponse::more): the sweep's fast path asks for the
  // other columns of a run (v(rxp), v(rxn), v(txp,txn)) when its noise analysis or waveform files
  // need them. The reduced model is then checked on these probes too.
  std::vector<std::string> more_probes;
  // Progress for a display: what runs ("down edge response", "down search") and the fraction
  // of it done (0-1). Empty: none.
  std::function<void(const std::string& what, double fraction)> progress;
};

// The edge response of one direction of the link (the one adapter to the engine).
StatusOr<EdgeResponse> edge_response(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                     link::Direction d, const EdgeResponseOptions& opt);

// e on a grid k times coarser: every k-th sample counted from the corner (e.pre a multiple of
// k), settle and drift measured again with opt's half bit; `more` dropped. The response
// edge_response gives with dt = k e.dt, from the same model sampled at the same times (the sweep
// synthesizes its traffic on the fine grid and searches the worst case on the coarse one).
EdgeResponse coarsened(const EdgeResponse& e, int k, const EdgeResponseOptions& opt);

// v(rxp,rxn) of a whole drive (a link's own traffic, link::ExpandedLink::drive) by superposition,
// on [0, t_end] every e.dt: exact at the samples for the link whose edge response e is. Every
// level change must fall on the grid (within 1e-6 of a sample); an error names the first that
// does not. The probes of e.more follow as further columns, each superposed the same way.
StatusOr<Waveform> synthesize_drive(const EdgeResponse& e, const traffic::Drive& drive,
                                    double t_end);

// Whether every level change of the drive falls on a grid of step dt (within 1e-6 of a step).
bool on_grid(const traffic::Drive& drive, double dt);

// v[i] += sum dL E(origin + i - n_edge) for i in [0, v.size()), (n_edge, dL) in edges: the record
// of E (resp, its corner at resp[pre]) where it overlaps, its last value after it (a running sum,
// so long records cost what E's length does). The superposition's inner loop, which the
// worst-case search's synthesis (worst.h, synthesize) shares.
void add_response(const std::vector<double>& resp, long pre,
                  const std::vector<std::pair<long, int>>& edges, long origin,
                  std::vector<double>& v);

}  // namespace isolink::analysis
