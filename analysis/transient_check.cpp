#include "analysis/transient_check.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <optional>
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
std::pair<double, double> worst_column(const Waveform& coarse, const Waveform& fine,
                                       double agreement_v) {
  std::pair<double, double> worst{0.0, agreement_v};
  for (size_t k = 0; k < fine.columns.size(); ++k) {
    double peak = 0.0;
    for (double v : fine.columns[k]) peak = std::max(peak, std::abs(v));
    const double allowed = std::max(agreement_v, TransientConvergence::kAgreementRel * peak);
    const double dev = max_deviation(coarse, fine, k);
    if (dev / allowed > worst.first / worst.second) worst = {dev, allowed};
  }
  return worst;
}

}  // namespace

namespace {

// The options of the run after one at `opt` (a tenth of the reltol; for the transient half the
// largest step too: the step limit may bind rather than the tolerance); none below kReltolFloor.
std::optional<TransientOptions> tightened(TransientOptions opt, Tighten how) {
  if (!(opt.reltol / 10 >= TransientConvergence::kReltolFloor * (1 - 1e-9))) return std::nullopt;
  opt.reltol /= 10;
  if (how == Tighten::ReltolAndTmax) opt.tmax = opt.effective_tmax() / 2;
  return opt;
}

}  // namespace

Waveform converge_runs(TransientOptions opt, Waveform first, const CheckedRun& run,
                       double agreement_v, TransientConvergence* out, Tighten how) {
  *out = TransientConvergence{};
  out->reltols.push_back(opt.reltol);
  out->tmaxes.push_back(opt.effective_tmax());
  Waveform kept = std::move(first);
  while (std::optional<TransientOptions> next = tightened(opt, how)) {
    opt = *next;
    StatusOr<Waveform> tighter = run(opt);
    if (!tighter) return kept;  // it did not finish (max_steps): the last run stands
    out->reltols.push_back(opt.reltol);
    out->tmaxes.push_back(opt.effective_tmax());
    const auto [dev, allowed] = worst_column(kept, *tighter, agreement_v);
    out->deviations.push_back(dev);
    out->allowed.push_back(allowed);
    kept = std::move(*tighter);
    if (dev <= allowed) {
      out->agreed = true;
      break;
    }
  }
  return kept;
}

StatusOr<Waveform> converge_runs_two_at_once(const TransientOptions& opt, const CheckedRun& run,
                                             double agreement_v, TransientConvergence* out,
                                             Tighten how) {
  const std::optional<TransientOptions> second = tightened(opt, how);
  std::optional<StatusOr<Waveform>> first, ahead;
  if (second)
    tbb::parallel_invoke([&] { first.emplace(run(opt)); }, [&] { ahead.emplace(run(*second)); });
  else
    first.emplace(run(opt));
  if (!*first) return first->status();
  // converge_runs asks for `second` first: it gets the run made ahead; later ones run then.
  return converge_runs(
      opt, std::move(**first),
      [&](const TransientOptions& o) -> StatusOr<Waveform> {
        if (ahead && o.reltol == second->reltol && o.tmax == second->tmax) {
          StatusOr<Waveform> w = std::move(*ahead);
          ahead.reset();
          return w;
        }
        return run(o);
      },
      agreement_v, out, how);
}

StatusOr<Waveform> converge_transient(Circuit& circuit, TransientOptions opt,
                                      const std::vector<Probe>& probes, Waveform first,
                                      TransientStats* stats, TransientConvergence* out) {
  return converge_runs(
      opt, std::move(first),
      [&](const TransientOptions& o) -> StatusOr<Waveform> {
        TransientStats tighter_stats;
        StatusOr<Waveform> w = run_transient(circuit, o, probes, &tighter_stats);
        if (w) *stats = tighter_stats;
        return w;
      },
      TransientConvergence::kAgreementV, out);
}

}  // namespace isolink::analysis
