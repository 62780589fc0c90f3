// The pieces of isolink compare shared by compare.cpp (capture, alignment, verdict) and
// compare_fit.cpp (the fit): the traffic as driver edges, the simulation at arbitrary times, the
// spec with fitted keys set. Internal to analysis/ (compare.h is the interface).
//
// Contract: SI units (s, V); the helpers return a Status for a spec or traffic that does not
// build. LinkModel keeps a reference to the part library (it must outlive the model) and is
// safe to call from several threads (the fit's parallel Jacobian).
#pragma once

#include <atomic>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
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
  std::deque<std::pair<std::vector<double>, std::shared_ptr<const EdgeResponse>>> kept_;
  std::atomic<int> evaluations_{0};
};

// "ends.x" -> {"tx.x", "rx.x"}, anything else -> {key}.
std::vector<std::string> key_paths(const std::string& key);

// A fitted key's bounds: CompareOptions::bounds, else 0.2x..5x the design value; an error when
// they do not hold the design value or reach 0.
StatusOr<std::pair<double, double>> fit_bounds(const CompareOptions& opt, const std::string& key,
                                               double design);

// The fit of CompareOptions::fit on the aligned capture: fills r.fit, r.unidentifiable,
// r.findings, r.offset_after_fit_s and returns the simulation at `t` after the fit.
struct FitData {
  std::span<const double> t;  // residual samples (capture time)
  std::span<const double> v;  // capture at t
  const EdgeList* edges = nullptr;
  double offset = 0;                   // aligned offset before the fit
  const Clipping* clipping = nullptr;  // the capture's rails (CompareResult::clipping)
};
Status run_fit(LinkModel& model, const link::LinkSpec& spec, const link::PartLibrary& parts,
               const CompareOptions& opt, const FitData& data, CompareResult& r,
               std::vector<double>& fitted_values);

}  // namespace isolink::analysis::compare_detail
