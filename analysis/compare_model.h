// The pieces of isolink compare shared by compare.cpp (capture, alignment, verdict) and
// compare_fit.cpp (the fit): the traffic as driver edges, the simulation at arbitrary times, the
// spec with fitted keys set. Internal to analysis/ (compare.h is the interface).
#pragma once

#include <map>
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
// linearly on its grid, 0 before it and its last value after it.
void synth_at(const EdgeResponse& e, const EdgeList& edges, double offset,
              std::span<const double> t, std::span<double> out);

// The link model with some keys replaced: edge responses by key values, the last one cached.
class LinkModel {
 public:
  LinkModel(std::string spec_text, std::string spec_path, const link::PartLibrary& parts,
            link::Direction d, const link::ExpandOptions& expand);
  // The edge response with keys[i] = values[i] (empty: the design).
  StatusOr<const EdgeResponse*> response(const std::vector<std::string>& keys,
                                         const std::vector<double>& values);
  int evaluations() const { return evaluations_; }

 private:
  std::string text_, path_;
  const link::PartLibrary& parts_;
  link::Direction dir_;
  WorstOptions wopt_;
  std::vector<double> cached_values_;
  bool cached_ = false;
  EdgeResponse cached_response_;
  int evaluations_ = 0;
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
  double offset = 0;  // aligned offset before the fit
};
Status run_fit(LinkModel& model, const link::LinkSpec& spec, const link::PartLibrary& parts,
               const CompareOptions& opt, const FitData& data, CompareResult& r,
               std::vector<double>& fitted_values);

}  // namespace isolink::analysis::compare_detail
