// isolink compare's account of a fit (issue 43): each key's value, bound and standard error,
// findings only where a value is a measurement (not a bound, not one of an inseparable pair),
// the keys' correlations, and where a residual the fit does not explain sits, with the spec keys
// that move the waveform there most.
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>

#include "analysis/compare_model.h"
#include "analysis/sweep_spec.h"
#include "netlists/link/cards.h"

namespace isolink::analysis::compare_detail {
namespace {

constexpr double kPlaceHalfWidth = 200e-9;  // the residual's place: +/- this around its peak
constexpr double kSensitivityStep = 0.10;   // a suggested key's change: +10 %

// Keys whose sensitivity is tried when a residual stays unexplained (those the spec gives a
// value, directly or by its board preset or transformer part).
const char* const kCandidateKeys[] = {"cable.length",
                                      "rx.isolation.cap",
                                      "tx.isolation.cap",
                                      "rx.termination",
                                      "tx.termination",
                                      "rx.series_r",
                                      "tx.series_r",
                                      "rx.bypass_c",
                                      "tx.bypass_c",
                                      "rx.isolation.leakage",
                                      "tx.isolation.leakage",
                                      "rx.isolation.inductance",
                                      "tx.isolation.inductance",
                                      "rx.isolation.cable_side_c",
                                      "tx.isolation.cable_side_c",
                                      "rx.isolation.winding_c",
                                      "tx.isolation.winding_c"};

std::string label_of(const std::string& key) {
  std::string s = key;
  if (s.rfind("ends.", 0) == 0) s = "both ends' " + s.substr(5);
  std::replace(s.begin(), s.end(), '.', ' ');
  std::replace(s.begin(), s.end(), '_', ' ');
  return s;
}

std::string advice_of(const std::string& key) {
  const std::string last = key.substr(key.rfind('.') + 1);
  if (last == "cap" || last == "bypass_c" || last == "cable_side_c" || last == "esd")
    return "check the part, its value and its solder joint";
  if (last == "length")
    return "check the cable's length, its type (material, gauge) and the "
           "connectors on the way";
  if (last == "termination" || last == "series_r")
    return "check the resistor's value, its placement and its solder joints";
  if (last == "inductance" || last == "leakage" || last == "dcr" || last == "winding_c")
    return "check the transformer's part number, its orientation and its solder joints";
  return "check the part and its assembly";
}

std::string si_of(const std::string& key, double v) {
  return link::format_si(v, config::unit_symbol(sweep::key_unit(key_paths(key).front())));
}

bool outside_band(const FitKey& k, const DesignValue& d) {
  const double rel = k.value / k.initial - 1;
  return rel < -d.tol_low || rel > d.tol_high;
}

// Reasons for pairs of keys that cannot be separated; their keys in `inseparable`.
void report_correlations(const std::vector<DesignValue>& design, CompareResult& r,
                         std::set<size_t>& inseparable) {
  for (size_t i = 0; i < r.fit.size(); ++i)
    for (size_t j = i + 1; j < r.fit.size(); ++j) {
      const KeyCorrelation* c = nullptr;
      for (const KeyCorrelation& x : r.correlations)
        if (x.a == r.fit[i].key && x.b == r.fit[j].key) c = &x;
      if (!c || c->separable() || !r.fit[i].identifiable || !r.fit[j].identifiable) continue;
      inseparable.insert(i);
      inseparable.insert(j);
      const FitKey &a = r.fit[i], &b = r.fit[j];
      const bool off = outside_band(a, design[i]) || outside_band(b, design[j]);
      const std::string text = fmt::format(
          "{} ({}) and {} ({}) are correlated ({:+.3f}): this capture fixes a combination of "
          "the two, not each, so neither value is a measurement{}; fit one with the other held, "
          "or compare a capture that tells them apart",
          label_of(a.key), si_of(a.key, a.value), label_of(b.key), si_of(b.key, b.value), c->r,
          off ? ", and the combination is not the design's" : "");
      if (off)
        r.reasons.push_back(text);
      else
        r.notes.push_back(text);
    }
}

// Within the design's band on every key.
bool design_like(const std::vector<DesignValue>& design, const std::vector<double>& x) {
  for (size_t j = 0; j < x.size(); ++j) {
    const double rel = std::exp(x[j]) - 1;
    if (rel < -design[j].tol_low || rel > design[j].tol_high) return false;
  }
  return true;
}

// Keys on which a near solution differs from the kept one by more than their band: their
// alternatives, identifiable false, and a reason (a note when the design itself is one of the
// answers) naming the other answer that fits best.
void report_near(const std::vector<DesignValue>& design, const FitSolution& best,
                 const std::vector<NearSolution>& near, CompareResult& r) {
  std::vector<size_t> keys;
  const NearSolution* closest = nullptr;
  for (size_t j = 0; j < r.fit.size(); ++j) {
    FitKey& k = r.fit[j];
    for (const NearSolution& s : near) {
      if (std::abs(s.x[j] - best.x[j]) <= separation(design[j])) continue;
      const double v = design[j].value * std::exp(s.x[j]);
      bool have = false;  // one value per answer: those within the band of another are one
      for (double a : k.alternatives)
        have = have || std::abs(std::log(v / a)) <= separation(design[j]);
      if (!have) k.alternatives.push_back(v);
      if (!closest || s.rms_v < closest->rms_v) closest = &s;
    }
    if (k.alternatives.empty()) continue;
    std::sort(k.alternatives.begin(), k.alternatives.end());
    k.identifiable = false;
    keys.push_back(j);
  }
  if (keys.empty() || !closest) return;
  std::string names, kept, other;
  for (size_t j : keys) names += (names.empty() ? "" : ", ") + label_of(r.fit[j].key);
  for (size_t j = 0; j < r.fit.size(); ++j) {
    kept += fmt::format("{}{} {}", kept.empty() ? "" : ", ", label_of(r.fit[j].key),
                        si_of(r.fit[j].key, r.fit[j].value));
    other += fmt::format("{}{} {}", other.empty() ? "" : ", ", label_of(r.fit[j].key),
                         si_of(r.fit[j].key, design[j].value * std::exp(closest->x[j])));
  }
  bool design_among = design_like(design, best.x);
  for (const NearSolution& s : near) design_among = design_among || design_like(design, s.x);
  const std::string text = fmt::format(
      "{} {} not separable from this capture: {} ({:.1f} mV rms) and {} ({:.1f} mV rms) both "
      "explain it within its noise ({:.1f} mV rms), so {} a measurement{}; fit fewer keys, hold "
      "the others at known values, or compare a capture that tells them apart",
      names, keys.size() > 1 ? "are" : "is", kept, r.search.chosen_rms_v * 1e3, other,
      closest->rms_v * 1e3, r.noise_rms_v * 1e3,
      keys.size() > 1 ? "none of their values is" : "its value is not",
      design_among ? "" : ", and none of the answers is the design");
  if (design_among)
    r.notes.push_back(text);
  else
    r.reasons.push_back(text);
}

// With three keys or more, each key's multiple correlation with the others (their estimates'
// correlation matrix P, keys only, the offset marginalised: r_j^2 = 1 - 1 / (P^-1)_jj). A key over
// the pairwise limit whose pairs all stay under it is inseparable from the others together.
void report_group_correlations(const std::vector<DesignValue>& design, const LsqResult& fit,
                               CompareResult& r, std::set<size_t>& inseparable) {
  const size_t nk = r.fit.size(), n = nk + 1;
  if (nk < 3 || fit.correlation.size() != n * n) return;
  Eigen::MatrixXd P(nk, nk);
  for (size_t i = 0; i < nk; ++i)
    for (size_t j = 0; j < nk; ++j)
      P(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = fit.correlation[i * n + j];
  Eigen::FullPivLU<Eigen::MatrixXd> lu(P);
  if (!lu.isInvertible()) return;  // rank deficient: the identifiability test has said so
  const Eigen::MatrixXd Pi = lu.inverse();
  for (size_t j = 0; j < nk; ++j) {
    const double d = Pi(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(j));
    if (!(d >= 1) || !std::isfinite(d)) continue;
    FitKey& k = r.fit[j];
    k.multiple_correlation = std::sqrt(1 - 1 / d);
    if (k.multiple_correlation <= KeyCorrelation::kInseparable || !k.identifiable ||
        inseparable.count(j))
      continue;
    inseparable.insert(j);
    k.identifiable = false;
    std::string others;
    for (size_t i = 0; i < nk; ++i)
      if (i != j) others += (others.empty() ? "" : " and ") + label_of(r.fit[i].key);
    const std::string text = fmt::format(
        "{} ({}) is correlated with {} together ({:.3f}, no pair alone over {:.2f}): this "
        "capture fixes a combination of them, not {} alone, so its value is not a "
        "measurement{}; fit fewer keys, or hold the others at known values",
        label_of(k.key), si_of(k.key, k.value), others, k.multiple_correlation,
        KeyCorrelation::kInseparable, label_of(k.key),
        outside_band(k, design[j]) ? ", and it is not the design's" : "");
    if (outside_band(k, design[j]))
      r.reasons.push_back(text);
    else
      r.notes.push_back(text);
  }
}

}  // namespace

void report_fit(const CompareOptions& opt, const std::vector<DesignValue>& design,
                const std::vector<std::pair<double, double>>& bounds, const FitSolution& best,
                const std::vector<NearSolution>& near, CompareResult& r) {
  const size_t nk = opt.fit.size(), n = nk + 1;
  const LsqResult& fit = best.lsq;
  std::vector<std::string> unident;
  for (size_t j = 0; j < nk; ++j) {
    FitKey k;
    k.key = opt.fit[j];
    k.initial = design[j].value;
    k.value = design[j].value * std::exp(best.x[j]);
    std::tie(k.low, k.high) = bounds[j];
    k.stderr_value = k.value * fit.stderr_x[j];
    k.tolerance = std::max(design[j].tol_low, design[j].tol_high);
    k.tolerance_from = design[j].tolerance_from;
    k.identifiable = fit.identifiable[j];
    if (k.value <= k.low * 1.01) k.at_bound = "low";
    if (k.value >= k.high / 1.01) k.at_bound = "high";
    if (!k.identifiable) unident.push_back(k.key);  // the Jacobian's rank; near answers below
    r.fit.push_back(k);
  }
  for (size_t i = 0; i < nk; ++i)
    for (size_t j = i + 1; j < nk; ++j)
      r.correlations.push_back({opt.fit[i], opt.fit[j], fit.correlation[i * n + j]});
  std::set<size_t> inseparable;
  report_correlations(design, r, inseparable);  // on the Jacobian's identifiability alone
  report_group_correlations(design, fit, r, inseparable);
  report_near(design, best, near, r);
  for (size_t j = 0; j < nk; ++j) {
    const FitKey& k = r.fit[j];
    if (!k.at_bound.empty()) {
      const bool low = k.at_bound == "low";
      const std::string text = fmt::format(
          "{} is at its {} bound, {} (the data want {} than it allows; widen --bounds): the "
          "bound, not the part's value",
          label_of(k.key), low ? "lower" : "upper", si_of(k.key, k.value), low ? "less" : "more");
      if (outside_band(k, design[j]))
        r.reasons.push_back(text);
      else
        r.notes.push_back(text);
      continue;
    }
    if (!k.identifiable || inseparable.count(j) || !outside_band(k, design[j])) continue;
    const double rel = k.value / k.initial - 1;
    r.findings.push_back(
        {k.key, k.initial, k.value, rel,
         fmt::format("{} behaves like {} against {} in the design ({:+.0f} %): {}", label_of(k.key),
                     si_of(k.key, k.value), si_of(k.key, k.initial), rel * 100, advice_of(k.key))});
  }
  if (!unident.empty()) {
    std::string keys;
    for (const std::string& k : unident) keys += (keys.empty() ? "" : ", ") + k;
    r.unidentifiable.push_back(fmt::format(
        "{} {} not separately identifiable from this capture (the fit's Jacobian is rank "
        "deficient): only a combination is determined (two isolation caps in series show only "
        "their series value); fit one of them, or hold the others at the design",
        keys, unident.size() > 1 ? "are" : "is"));
  }
}

Status locate_residual(LinkModel& model, const link::LinkSpec& spec, const link::PartLibrary& parts,
                       const CompareOptions& opt, const std::vector<double>& fitted,
                       const FitData& data, std::span<const double> sim, CompareResult& r) {
  const std::span<const double> t = data.t, v = data.v;
  if (t.empty() || !r.offset_after_fit_s) return Status::Ok();
  ResidualPlace pl;
  size_t at = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double d = data.clipping->difference(v[i], sim[i]);
    if (std::abs(d) > std::abs(pl.residual_v)) {
      pl.residual_v = d;
      at = i;
    }
  }
  pl.time = t[at];
  for (size_t w = 0; w < r.windows.size(); ++w)
    if (pl.time >= r.windows[w].first && pl.time <= r.windows[w].second) pl.window = w;
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < r.check.pulses.size(); ++k) {
    const eye::PulseMetrics& p = r.check.pulses[k];
    const double d = pl.time < p.a ? p.a - pl.time : pl.time > p.b ? pl.time - p.b : 0.0;
    if (d < nearest && d < 1e-6) {
      nearest = d;
      pl.pulse = k;
    }
  }
  const auto lo = std::lower_bound(t.begin(), t.end(), pl.time - kPlaceHalfWidth);
  const auto hi = std::upper_bound(t.begin(), t.end(), pl.time + kPlaceHalfWidth);
  const std::span<const double> tw(lo, hi);
  const size_t i0 = static_cast<size_t>(lo - t.begin());
  double sse = 0;
  for (size_t i = 0; i < tw.size(); ++i) {
    const double d = data.clipping->difference(v[i0 + i], sim[i0 + i]);
    sse += d * d;
  }
  pl.window_rms_v = tw.empty() ? 0.0 : std::sqrt(sse / static_cast<double>(tw.size()));
  // The candidates: keys with a design value, not fitted (nor covered by a fitted ends.X).
  std::vector<std::pair<std::string, double>> cands;
  for (const char* c : kCandidateKeys) {
    bool fitted_key = false;
    for (const std::string& k : opt.fit)
      for (const std::string& path : key_paths(k)) fitted_key = fitted_key || path == c;
    StatusOr<DesignValue> d = design_value(spec, parts, c);
    if (!fitted_key && d) cands.push_back({c, d->value});
  }
  std::vector<ResidualPlace::Suggestion> sug(cands.size());
  std::vector<Status> errors(cands.size());
  tbb::task_arena arena(opt.threads > 0 ? opt.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(size_t{0}, cands.size(), [&](size_t k) {
      std::vector<std::string> keys = opt.fit;
      std::vector<double> values = fitted;
      keys.push_back(cands[k].first);
      values.push_back(cands[k].second * (1 + kSensitivityStep));
      StatusOr<std::shared_ptr<const EdgeResponse>> e = model.response(keys, values);
      if (!e) {
        errors[k] = e.status();
        return;
      }
      std::vector<double> moved(tw.size());
      synth_at(**e, *data.edges, *r.offset_after_fit_s, tw, moved);
      double s2 = 0;
      for (size_t i = 0; i < tw.size(); ++i)
        s2 += (moved[i] - sim[i0 + i]) * (moved[i] - sim[i0 + i]);
      sug[k] = {cands[k].first, tw.empty() ? 0.0 : std::sqrt(s2 / static_cast<double>(tw.size()))};
    });
  });
  for (const Status& s : errors)
    if (!s.ok()) r.notes.push_back("a key's sensitivity was not computed: " + s.message());
  std::erase_if(sug, [](const ResidualPlace::Suggestion& s) {
    return s.key.empty() || !std::isfinite(s.sensitivity_v) || !(s.sensitivity_v > 0);
  });
  std::sort(sug.begin(), sug.end(),
            [](const auto& a, const auto& b) { return a.sensitivity_v > b.sensitivity_v; });
  if (sug.size() > 4) sug.resize(4);
  pl.suggested = std::move(sug);
  r.unexplained = std::move(pl);
  return Status::Ok();
}

}  // namespace isolink::analysis::compare_detail
