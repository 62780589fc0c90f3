// The pieces of isolink compare shared by compare.cpp (capture, alignment, verdict) and
// compare_fit.cpp (the fit): the traffic as driver edges, the simulation at arbitrary times, the
// spec with fitted keys set. Internal to analysis/ (compare.h is the interface).
//
// Contract: SI units (s, V); the helpers return a Status for a spec or traffic that does not
// build. LinkModel keeps a reference to the part library (it must outlive the model) and is
// safe to call from several threads (the fit's parallel Jacobian).
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "analysis/compare.h"
#include "analysis/worst.h"

namespace isolink::analysis::compare_detail {

// The driver's level changes, in drive time (s), and each frame's [start, end] in drive time.
struct EdgeList {
  std::vector<double> t;
  std::vector<int> dl;
  std::vector<std::pair<double, double>> frames;
};

// v(t) = v_idle + sum_k dl_k E(t - offset - t_k) at each time of `t` (sorted), E interpolated
// linearly on its grid, 0 before it and its last value after it. Edges a whole number of grid
// steps apart (a frame's half bits) are summed on the grid first and interpolated once.
void synth_at(const EdgeResponse& e, const EdgeList& edges, double offset,
              std::span<const double> t, std::span<double> out);

// The link model with some keys replaced: edge responses by key values. Safe to call from
// several threads at once (the fit's Jacobian evaluates its columns in parallel): each call
// builds its own spec and circuit; the last kKept responses are kept, so the point a Jacobian is
// taken at, and its offset-only columns, cost nothing. What does not change between evaluations
// is reused: the first response's reduced-model expansion points start every later model's
// search (the same link with parts a few percent off needs nearly the same points; the model
// still passes its full check).
class LinkModel {
 public:
  LinkModel(std::string spec_text, std::string spec_path, const link::PartLibrary& parts,
            link::Direction d, const link::ExpandOptions& expand);
  // The edge response with keys[i] = values[i] (empty: the design).
  StatusOr<std::shared_ptr<const EdgeResponse>> response(const std::vector<std::string>& keys,
                                                         const std::vector<double>& values);
  int evaluations() const { return evaluations_.load(); }

 private:
  static constexpr size_t kKept = 16;
  std::string text_, path_;
  const link::PartLibrary& parts_;
  link::Direction dir_;
  WorstOptions wopt_;
  std::mutex mutex_;                  // guards kept_ and start_points_
  std::vector<double> start_points_;  // Hz, the first response's expansion points
  std::deque<std::tuple<std::vector<std::string>, std::vector<double>,
                        std::shared_ptr<const EdgeResponse>>>
      kept_;  // keys, values, response
  std::atomic<int> evaluations_{0};
};

// "ends.x" -> {"tx.x", "rx.x"}, anything else -> {key}.
std::vector<std::string> key_paths(const std::string& key);

// A fitted key's bounds: CompareOptions::bounds, else the defaults: cable.length 0.1..100 m
// (widened to hold the design), inductances 1/10..2x the design value, everything else (R, C)
// 1/10..10x; an error when they do not hold the design value or reach 0.
StatusOr<std::pair<double, double>> fit_bounds(const CompareOptions& opt, const std::string& key,
                                               double design);

// Capture time minus drive time that best lays the simulation on (ts, vs): a squared-error scan
// of integer lags of a 1 ns grid within [offset0 - before, offset0 + after], then a
// golden-section search of the continuous offset within +/-1.5 grid steps of the best lag. Both
// over the first 2 ms of (ts, vs) only: one offset needs no more, and a long record's grid would
// otherwise be a double per nanosecond of it, twice.
double align(const EdgeResponse& e, const EdgeList& edges, std::span<const double> ts,
             std::span<const double> vs, double offset0, double before, double after,
             const Clipping& clip);

// The fit of CompareOptions::fit on the aligned capture: fills r.fit, r.unidentifiable,
// r.correlations, r.search, r.findings, r.offset_after_fit_s (and reasons for keys at their
// bounds or inseparable) and returns the fitted values. Uses r.threshold_rms_v / _max_v to decide
// whether the refinement from the design explains the capture (else the global search runs).
struct FitData {
  std::span<const double> t;  // residual samples (capture time)
  std::span<const double> v;  // capture at t
  const EdgeList* edges = nullptr;
  double offset = 0;                   // aligned offset before the fit
  const Clipping* clipping = nullptr;  // the capture's rails (CompareResult::clipping)
  size_t first_window = 0;             // t[0 .. first_window) is the first residual window
};
Status run_fit(LinkModel& model, const link::LinkSpec& spec, const link::PartLibrary& parts,
               const CompareOptions& opt, const FitData& data, CompareResult& r,
               std::vector<double>& fitted_values);

// One fitted solution: per key log(value / design), the offset, and the fit that found it.
struct FitSolution {
  std::vector<double> x;  // log(value / design) per key
  double offset = 0;      // capture time - drive time (s)
  LsqResult lsq;
};
// Another local minimum (a refinement's solution, from the design or a scan or profile point) that
// explains the capture within its noise of the kept solution: its sum of squares over the m
// residual samples is at most m (noise^2 + q^2 / 12) above the kept one's, so the two simulations
// differ by less than the capture's noise rms.
// Two values of a key further apart than its tolerance band (log(1 + band)) are two different
// answers; closer, the same one.
inline double separation(const DesignValue& d) {
  return std::log1p(std::max(d.tol_low, d.tol_high));
}
struct NearSolution {
  std::vector<double> x;  // log(value / design) per key
  double rms_v = 0;
};
// r.fit, r.findings, r.correlations, r.unidentifiable and the reasons on keys at their bounds or
// inseparable, from the kept solution; a key on which a near solution differs from it by more
// than the key's tolerance band is not separable (FitKey::alternatives, no finding).
void report_fit(const CompareOptions& opt, const std::vector<DesignValue>& design,
                const std::vector<std::pair<double, double>>& bounds, const FitSolution& best,
                const std::vector<NearSolution>& near, CompareResult& r);

// After a fit whose residual stays over the threshold: r.unexplained, where the residual
// (capture minus `sim`, both at data.t) is largest, and the spec keys (not fitted) that move
// the simulation there most when each changes by +10 % from the fitted link.
Status locate_residual(LinkModel& model, const link::LinkSpec& spec, const link::PartLibrary& parts,
                       const CompareOptions& opt, const std::vector<double>& fitted,
                       const FitData& data, std::span<const double> sim, CompareResult& r);

}  // namespace isolink::analysis::compare_detail
