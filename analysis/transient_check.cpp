#include "analysis/transient_check.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace isolink::analysis {

double max_deviation(const Waveform& coarse, const Waveform& fine, size_t k) {
  double worst = 0.0;
  if (coarse.time.empty() || k >= coarse.columns.size() || k >= fine.columns.size()) return 0.0;
  for (size_t i = 0; i < fine.time.size(); ++i)
    worst = std::max(worst, std::abs(fine.columns[k][i] - coarse.value_at(k, fine.time[i])));
  return worst;
}

namespace {

// The column whose deviation is nearest its allowance (or furthest past it): {deviation, allowed}.
std::pair<double, double> worst_column(const Waveform& coarse, const Waveform& fine) {
  std::pair<double, double> worst{0.0, TransientConvergence::kAgreementV};
  for (size_t k = 0; k < fine.columns.size(); ++k) {
    double peak = 0.0;
    for (double v : fine.columns[k]) peak = std::max(peak, std::abs(v));
    const double allowed =
        std::max(TransientConvergence::kAgreementV, TransientConvergence::kAgreementRel * peak);
    const double dev = max_deviation(coarse, fine, k);
    if (dev / allowed > worst.first / worst.second) worst = {dev, allowed};
  }
  return worst;
}

}  // namespace

StatusOr<Waveform> converge_transient(Circuit& circuit, TransientOptions opt,
                                      const std::vector<Probe>& probes, Waveform first,
                                      TransientStats* stats, TransientConvergence* out) {
  *out = TransientConvergence{};
  out->reltols.push_back(opt.reltol);
  out->tmaxes.push_back(opt.effective_tmax());
  Waveform kept = std::move(first);
  while (opt.reltol / 10 >= TransientConvergence::kReltolFloor * (1 - 1e-9)) {
    opt.reltol /= 10;
    opt.tmax = opt.effective_tmax() / 2;  // the step limit may bind rather than the tolerance
    TransientStats tighter_stats;
    StatusOr<Waveform> tighter = run_transient(circuit, opt, probes, &tighter_stats);
    if (!tighter) return kept;  // it did not finish (max_steps): the last run stands
    out->reltols.push_back(opt.reltol);
    out->tmaxes.push_back(opt.tmax);
    const auto [dev, allowed] = worst_column(kept, *tighter);
    out->deviations.push_back(dev);
    out->allowed.push_back(allowed);
    kept = std::move(*tighter);
    *stats = tighter_stats;
    if (dev <= allowed) {
      out->agreed = true;
      break;
    }
  }
  return kept;
}

}  // namespace isolink::analysis
