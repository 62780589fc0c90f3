// isolink compare: a scope capture of a receiver against the link spec's simulation of the same
// traffic, the residual between them, and the part values that explain it (issue 29).
//
//   CompareInput in{.files = {"scope.csv"}, .spec_path = "link.yaml"};
//   in.cols.p = "CH1"; in.cols.n = "CH2";
//   CompareOptions opt;  opt.fit = {"rx.isolation.cap"};
//   StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
//   StatusOr<CompareResult> r = compare_capture(in, *parts, opt);
//   if (!r) { fputs(r.status().message().c_str(), stderr); return 2; }   // bad input
//   std::puts(reports::compare_json(*r).dump(2).c_str());   // reports/compare_report.h
//   return r->verdict == "match" ? 0 : 1;
//
// Contract:
// - Units: SI throughout (s, V, F, H, ohm, m). Times of the result are capture times (the
//   capture's own axis); `offset_s` is capture time minus the model's drive time, so a simulated
//   sample at drive time t sits at capture time t + offset_s.
// - Errors: a Status (file:line:col or file: error: ...) for bad input only: an unreadable capture
//   or spec, an unknown or non-numeric fit key, bounds that do not hold the design value, a
//   --frames script that does not build. A capture without daisy-chain pulses is not an error but
//   the verdict "inconclusive"; a capture that differs from the design is "mismatch".
// - Ownership: the result owns everything it holds (waveforms for the plots included); nothing
//   refers back to the input.
// - Numbers in the result are finite (a non-finite simulation is an error).
// Method (analysis/README.md, section Compare, has the argument):
// 1. The capture is read by eye::read_capture (every layout of `isolink check`) and checked with
//    the receiver's rules; its decoded frames (byte, error bit, preamble start) are the traffic.
//    With none decoded, the spec's stimulus (or CompareOptions::frames) is the traffic.
// 2. The link is linear: the receiver's v(t) is v_idle + sum_k dL_k E(t - t_k), E the edge
//    response (edge_response.h, the LTI engine's reduced model), evaluated at the capture's own
//    sample times (E interpolated linearly on its 1 ns grid), so edges fall at any time.
// 3. Alignment: a squared-error scan of integer lags on a 1 ns grid, then a golden-section
//    search of the continuous offset; no amplitude scaling.
// 4. Fit: Ceres Solver (Levenberg-Marquardt, bounds) over log(value / design) of each key and
//    the offset, Jacobian by forward differences while iterating and central ones at the solution
//    (1 % steps; its points evaluated in parallel); standard errors from J^T J at the solution
//    scaled by the residual variance; rank deficiency reported per key.
// 5. Global search (issue 43): when the refinement from the design leaves a residual over what
//    the noise explains, or a key on its bound, a space-filling scan of the bounds (a log grid
//    of 24 points for one key, a Halton sequence of 32 n (n - 1) points for n keys; each point's
//    offset aligned again), then the same refinement from the best few distinct points; with
//    more than one key, profiles from the best solution (each key alone over a 32-point log
//    grid, the others held) and refinements from their best points, while that finds a better
//    answer; the lowest residual wins. Default bounds: R and C 1/10..10x the design, L 1/10..2x,
//    cable.length 0.1..100 m. The scan always runs (unless global_search is off): a residual
//    within the match threshold does not show that no other valley explains the capture better.
// 6. Honesty: a key within 1 % of a bound is "at its bound", never a finding; keys whose
//    correlation (from the fit's covariance) is over 0.95 are reported as a pair that cannot be
//    separated, never as two findings; so are keys on which another point of the bounds (a scan
//    point or a refinement's solution) explains the capture within its noise of the kept one
//    and differs by more than the key's tolerance band (distinct minima: not separable, never a
//    finding); a residual still over the threshold is located (window, pulse, time) with the
//    spec keys that move that part of the waveform most.
#pragma once

#include <cmath>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
#include "eye/check.h"
#include "eye/waveform_csv.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

struct CompareInput {
  std::vector<std::string> files;  // the capture: one file, or P then N
  eye::CsvColumns cols;            // --p / --n / --diff / --time, as `isolink check`
  std::string spec_path;           // the link spec (YAML)
};

struct CompareOptions {
  link::Direction direction = link::Direction::kDown;  // which receiver was probed
  // A stimulus script (netlists/traffic/stimulus.h) used when nothing in the capture decodes;
  // empty: the spec's own stimulus.
  std::string frames;
  std::vector<std::string> fit;  // keys, dotted paths as in sweeps
  // key -> [low, high], SI. Default (fit_bounds in compare_model.h): resistors and capacitors
  // 1/10..10x the design value (a wrong multiplier digit), inductances 1/10..2x (a wrong part, a
  // saturated core), cable.length 0.1..100 m (widened to hold the design).
  std::map<std::string, std::pair<double, double>> bounds;
  // Scan the bounds after the refinement from the design (always: a residual within the match
  // threshold does not rule out a better valley); false: the refinement from the design only.
  bool global_search = true;
  int scan_points = 0;            // points of that scan; 0: 24 for one key, 32 n (n - 1) for n keys
  double model_floor_rel = 0.01;  // model floor of the verdict, a fraction of the peak |v|
  int max_iterations = 30;        // Levenberg-Marquardt iterations
  int threads = 0;                // the fit's Jacobian columns evaluated at once (0: all cores)
  link::ExpandOptions expand;     // driver, load, encoding
};

struct Residual {
  double rms_v = 0;
  double max_v = 0;
  size_t samples = 0;  // capture samples it is taken over
  size_t clipped = 0;  // of those, not counted: the capture on a rail the design exceeds
};

// A scope clips at the ends of its vertical range: the record then sits on one value, noise-free,
// for longer than it stays on any other value. Where the capture is on such a rail and the design
// goes beyond it, the capture cannot show the difference, and it is not counted (residual 0 at
// that sample); everywhere else, the rail included where the design stays inside it, it is.
struct Clipping {
  std::optional<double> high_v, low_v;  // the rails found (V)
  size_t samples = 0;                   // capture samples on a rail (whole record)
  // capture - simulation at one sample, 0 where the capture is on a rail the design exceeds.
  double difference(double capture, double sim) const {
    if (high_v && capture >= *high_v && sim > capture) return 0.0;
    if (low_v && capture <= *low_v && sim < capture) return 0.0;
    return capture - sim;
  }
};

// One metric of one pulse, measured on the capture and on the simulation at the same pulse.
struct MetricPair {
  std::string metric;  // vstart | vend | width | edge
  size_t pulse = 0;    // index in the capture's pulses
  double time = 0;     // the pulse's start crossing (capture time, s)
  double measured = 0, simulated = 0;
};
// Per metric over the pulses: how far the simulation is from the capture.
struct MetricSummary {
  std::string metric;
  size_t pulses = 0;
  double mean_diff = 0;     // mean of simulated - measured (V or s)
  double max_abs_diff = 0;  // largest |simulated - measured|
  double at_time = 0;       // the pulse where it is largest (capture time)
};

struct FitKey {
  std::string key;
  double value = 0, initial = 0, low = 0, high = 0;
  double stderr_value = 0;  // standard error (SI), from J^T J at the solution
  double tolerance = 0.10;  // the design's band, relative (part or default)
  std::string tolerance_from;
  // false: only a combination with other keys is determined, either locally (the Jacobian is
  // rank deficient) or globally (`alternatives` is not empty).
  bool identifiable = true;
  // Other values of this key, at other points of the bounds that explain the capture within its
  // noise as well as the kept one (distinct minima: more than the tolerance band away), SI. Not
  // empty: the value is not a measurement, no finding is made on it (issue 43).
  std::vector<double> alternatives;
  // With three keys or more: the correlation of this key's estimate with the best combination of
  // the other keys' (from the fit's covariance; 0 with fewer keys). Over
  // KeyCorrelation::kInseparable the capture fixes a combination of the keys, not this one,
  // even when no single pair passes it: identifiable false, no finding (issue 43).
  double multiple_correlation = 0;
  // "low" / "high" when the value is within 1 % of that bound: the data want a value the bounds
  // do not allow, so `value` is the bound, not a measurement (no finding is made on it).
  std::string at_bound;
};

// The correlation of two fitted keys' estimates, from the fit's covariance (the offset's
// uncertainty included). Over kInseparable, the capture determines a combination of the two,
// not each: no finding is made on either, and a reason says so.
struct KeyCorrelation {
  static constexpr double kInseparable = 0.95;
  std::string a, b;
  double r = 0;
  bool separable() const { return std::abs(r) <= kInseparable; }
};

// Where a residual the fitted keys do not explain is largest, and the spec keys that move the
// waveform there most.
struct ResidualPlace {
  size_t window = 0;            // index in CompareResult::windows (the frame)
  std::optional<size_t> pulse;  // the capture's pulse nearest to it (index in check.pulses)
  double time = 0;              // capture time of the largest |capture - simulation|
  double residual_v = 0;        // capture - simulation there
  double window_rms_v = 0;      // rms of the residual within +/-200 ns of it
  struct Suggestion {
    std::string key;
    double sensitivity_v = 0;  // rms change there when the key moves by +10 % (V)
  };
  std::vector<Suggestion> suggested;  // largest sensitivity first (at most 4)
};

// What the global search did.
struct SearchSummary {
  bool scanned = false;
  int near = 0;             // points of the bounds found within the noise of the kept solution
  std::string why;          // why it scanned, or why not
  int points = 0;           // scan points evaluated
  int failed = 0;           // scan points whose model did not build (left out)
  int starts = 0;           // refinements run from scan points
  double local_rms_v = 0;   // the refinement from the design's residual rms
  double chosen_rms_v = 0;  // the kept solution's
  bool from_scan = false;   // the kept solution started from a scan point
};

struct Finding {
  std::string key;
  double design = 0, fitted = 0, change_rel = 0;
  std::string text;
};

// A generic bounded least-squares fit (the link fit is one use; tests fit closed forms).
struct LsqParam {
  double initial = 0, low = 0, high = 0;
  double step = 0.01;  // central-difference step in the parameter's own units
};
struct LsqResult {
  std::vector<double> x;
  std::vector<double> stderr_x;  // sqrt(diag(sigma^2 (J^T J)^+)), sigma^2 = SSE / (m - n)
  double sse = 0;                // sum of squared residuals at x
  int iterations = 0;
  int evaluations = 0;              // residual evaluations, derivatives included
  std::string report;               // Ceres' brief report
  std::vector<bool> identifiable;   // per parameter
  std::vector<double> singular;     // of J with columns scaled to unit norm, decreasing
  std::vector<double> correlation;  // n x n, row-major, from sigma^2 (J^T J)^+ (0 where unknown)
  double max_abs_residual = 0;      // largest |r_i| at x
};
// Residuals at x; an error stops the fit. Called from several threads at once (the Jacobian's
// n + 1 points, 2n + 1 at the solution, are evaluated in parallel, `threads` at most, 0: all
// cores): it must write only r.
using ResidualFn = std::function<Status(std::span<const double> x, std::vector<double>& r)>;
StatusOr<LsqResult> fit_least_squares(const ResidualFn& f, size_t residuals,
                                      const std::vector<LsqParam>& params, int max_iterations,
                                      int threads = 0);

struct CompareResult {
  std::string verdict;  // match | mismatch | inconclusive
  std::string direction;
  std::string receiver_rules;
  std::string traffic_from;          // "capture: 7 frames decoded", "spec stimulus", "--frames"
  std::vector<std::string> reasons;  // why not match
  std::vector<std::string> notes;
  double offset_s = 0;  // capture time - drive time, before the fit
  Residual residual;    // before the fit
  std::optional<double> offset_after_fit_s;
  std::optional<Residual> residual_after_fit;
  double noise_rms_v = 0;      // the capture's noise (idle segments, detrended)
  double quant_step_v = 0;     // its quantisation step (0: none found)
  double model_floor_v = 0;    // model_floor_rel x peak |v| of the simulation
  double threshold_rms_v = 0;  // 3 noise + q / sqrt(12) + floor
  double threshold_max_v = 0;  // 6 noise + q + 5 floor
  Clipping clipping;           // the capture's rails, if it clips
  std::vector<FitKey> fit;
  std::vector<std::string> unidentifiable;   // sentences about rank deficiency
  std::vector<KeyCorrelation> correlations;  // every pair of fitted keys
  SearchSummary search;
  std::optional<ResidualPlace> unexplained;  // after a fit whose residual is over the threshold
  std::vector<Finding> findings;
  std::vector<MetricSummary> metrics;  // before the fit
  std::vector<MetricSummary> metrics_after_fit;
  std::vector<std::pair<double, double>> windows;  // residual windows (capture time)
  // For the plots: the capture and the simulation at its samples (full record).
  std::vector<double> time, capture, sim, sim_after_fit;
  std::vector<size_t> worst_frames;  // window indices, worst residual first (at most 3)
  eye::CheckResult check;            // the capture's own check (its commands: check.commands)
  eye::CaptureInfo input;
  int evaluations = 0;
  double seconds = 0;
};

StatusOr<CompareResult> compare_capture(const CompareInput& in, const link::PartLibrary& parts,
                                        const CompareOptions& opt = {});

// The design value of a numeric key: the spec's, else the board preset's (series_r, bypass_c,
// termination), else the transformer part's; with its tolerance band (relative) and where that
// comes from. An error when the key is not a numeric link-spec key with a value.
struct DesignValue {
  double value = 0;
  double tol_low = 0.10, tol_high = 0.10;  // relative band below / above
  std::string tolerance_from;
};
StatusOr<DesignValue> design_value(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                   const std::string& key);

}  // namespace isolink::analysis
