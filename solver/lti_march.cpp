// The LTI engine's march (solver/lti.h, "R_k is computed once per circuit by one march"): the
// unit-ramp responses R_k of every source marched together, with the step control of
// solver/step_control.h and the settling test of lti.h.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "solver/lti.h"
#include "solver/mna_system.h"
#include "solver/step_control.h"

namespace isolink {

namespace {

// The last accepted points of the march, oldest first: times and the full state of each source.
struct MarchHistory {
  std::array<double, 3> times{};
  std::array<std::vector<std::vector<double>>, 3> states;  // [slot][source][unknown]
  int first = 0, count = 0;
  double t(int i) const { return times[(first + i) % 3]; }
  const std::vector<double>& x(int i, size_t k) const { return states[(first + i) % 3][k]; }
  void push(double t1, const std::vector<std::vector<double>>& x1) {
    if (count == 3) first = (first + 1) % 3, --count;
    const int slot = (first + count) % 3;
    times[slot] = t1;
    states[slot] = x1;
    ++count;
  }
};

}  // namespace

// One march, writing into an LtiResponses (tau_, r_, s_, end_slope_, stats_).
class LtiMarch {
 public:
  LtiMarch(LtiResponses& r, const Circuit& circuit, MnaSystem& sys,
           const std::vector<Probe>& probes, const std::vector<std::vector<double>>& unit,
           const LtiOptions& opt);
  Status run();

 private:
  // Solves every source's step of `step` from tau_ into xnew_; returns a0 (the formula's
  // coefficient of x1).
  StatusOr<double> solve_step(double step, bool euler);
  // Truncation error per unit time / tolerance (0 until there are four points).
  double error_ratio(double t1, double step) const;
  void accept(double step, double a0);
  // The settling test of lti.h at march point i (the last).
  bool settled(size_t i) const;
  // S at the march points from R alone, and R's slope beyond the march.
  void finish();

  LtiResponses& r_;
  const Circuit& circuit_;
  MnaSystem& sys_;
  const std::vector<Probe>& probes_;
  const std::vector<std::vector<double>>& unit_;
  const LtiOptions& opt_;
  const int n_;
  const size_t nk_, np_;
  const double horizon_;
  StepControl control_;
  // Watched states (as the transient's error control), per source their peak |S| and
  // 1 / tolerance (recomputed when a peak grows).
  std::vector<int> watched_;
  std::vector<std::vector<double>> peak_, inv_tol_;
  std::vector<std::vector<double>> x_, xdot_, xnew_, hist_part_;  // [source][unknown]
  MarchHistory hist_;
  double tau_ = 0.0;
  mutable int worst_unknown_ = 0;
  // Largest |chord slope| of each probe's response so far: no settling before it has arrived.
  std::vector<std::vector<double>> probe_peak_;
};

LtiMarch::LtiMarch(LtiResponses& r, const Circuit& circuit, MnaSystem& sys,
                   const std::vector<Probe>& probes, const std::vector<std::vector<double>>& unit,
                   const LtiOptions& opt)
    : r_(r),
      circuit_(circuit),
      sys_(sys),
      probes_(probes),
      unit_(unit),
      opt_(opt),
      n_(sys.n),
      nk_(unit.size()),
      np_(probes.size()),
      horizon_(opt.horizon) {
  const double hmax = opt.max_step > 0 ? std::min(opt.max_step, horizon_) : horizon_ / 64;
  const double hmin = std::max(1e-18, horizon_ * 1e-14);
  // The truncation error per unit time is O(h^2).
  control_ = StepControl{.hmax = hmax, .hmin = hmin, .error_order = 2};
  for (int u = 1; u <= n_; ++u) {
    const bool has_c = sys.c[sys.pattern.slot(u, u)] != 0.0;
    if ((circuit.unknown_is_node(u) && has_c) || circuit.unknown_is_state(u)) watched_.push_back(u);
  }
  peak_.assign(nk_, std::vector<double>(watched_.size(), 0.0));
  inv_tol_.assign(nk_, std::vector<double>(watched_.size(), 1.0 / opt.step_abstol));
  x_.assign(nk_, std::vector<double>(n_ + 1, 0.0));
  xdot_ = x_, xnew_ = x_, hist_part_ = x_;
  for (auto& s : hist_.states) s = x_;
  hist_.push(0.0, x_);
  probe_peak_.assign(nk_, std::vector<double>(np_, 0.0));
}

StatusOr<double> LtiMarch::solve_step(double step, bool euler) {
  const double a0 = euler ? 1.0 / step : 2.0 / step;
  if (Status s = sys_.select_or_factor(circuit_, a0); !s.ok())
    return s.with_context(fmt::format("LTI march at {:g} s", tau_ + step));
  const double t1 = tau_ + step;
  for (size_t k = 0; k < nk_; ++k) {
    auto& hp = hist_part_[k];
    for (int u = 1; u <= n_; ++u) hp[u] = euler ? -x_[k][u] / step : -a0 * x_[k][u] - xdot_[k][u];
    auto& b = xnew_[k];
    for (int u = 0; u <= n_; ++u) b[u] = unit_[k][u] * t1;  // unit ramp: u(t) = t
    sys_.sub_c_times(hp.data(), b.data());
    if (Status s = sys_.solve(b); !s.ok()) return s;
  }
  return a0;
}

// Truncation error per unit time against step_reltol * peak|S| + step_abstol.
double LtiMarch::error_ratio(double t1, double step) const {
  if (hist_.count != 3) return 0.0;
  double ratio = 0.0;
  const double t0 = hist_.t(2), tm1 = hist_.t(1), tm2 = hist_.t(0);
  const double ia = 1.0 / (t1 - t0), ib = 1.0 / (t0 - tm1), ic = 1.0 / (tm1 - tm2);
  const double ie = 1.0 / (t1 - tm1), iff = 1.0 / (t0 - tm2), ig = 1.0 / (t1 - tm2);
  const double h2 = step * step * 0.5 * ig;  // h^3 * (1/12) * 6 / h
  const double w1 = h2 * ie * ia, w2 = -h2 * ib * (ie + iff), w3 = h2 * iff * ic;
  for (size_t k = 0; k < nk_; ++k) {
    const auto &x0 = hist_.x(2, k), &xm1 = hist_.x(1, k), &xm2 = hist_.x(0, k);
    const auto& xn = xnew_[k];
    for (size_t w = 0; w < watched_.size(); ++w) {
      const int u = watched_[w];
      const double e = inv_tol_[k][w] * std::fabs(w1 * (xn[u] - x0[u]) + w2 * (x0[u] - xm1[u]) +
                                                  w3 * (xm1[u] - xm2[u]));
      if (e > ratio) ratio = e, worst_unknown_ = u;
    }
  }
  return ratio;
}

void LtiMarch::accept(double step, double a0) {
  for (size_t k = 0; k < nk_; ++k) {
    for (int u = 1; u <= n_; ++u) xdot_[k][u] = a0 * xnew_[k][u] + hist_part_[k][u];
    std::swap(x_[k], xnew_[k]);
    for (size_t w = 0; w < watched_.size(); ++w) {
      const double a = std::fabs(xdot_[k][watched_[w]]);
      if (a > peak_[k][w])
        peak_[k][w] = a, inv_tol_[k][w] = 1.0 / (opt_.step_reltol * a + opt_.step_abstol);
    }
  }
  hist_.push(tau_, x_);
  r_.tau_.push_back(tau_);
  for (size_t k = 0; k < nk_; ++k)
    for (size_t p = 0; p < np_; ++p) {
      auto &R = r_.r_[k][p], &S = r_.s_[k][p];
      R.push_back(probes_[p].value(x_[k].data()));
      S.push_back(probes_[p].value(xdot_[k].data()));
      const double chord = (R.back() - R[R.size() - 2]) / step;
      probe_peak_[k][p] = std::max(probe_peak_[k][p], std::fabs(chord));
    }
}

bool LtiMarch::settled(size_t i) const {
  const std::vector<double>& taus = r_.tau_;
  const size_t from =
      static_cast<size_t>(std::lower_bound(taus.begin(), taus.end(), 0.5 * tau_) - taus.begin());
  // On chord slopes (R_j - R_j-1) / h_j, the mean of S over each step: the trapezoidal rule's
  // derivative S carries a +-delta alternation that never damps, its chords do not.
  auto chord = [&](const std::vector<double>& R, size_t j) {
    return (R[j] - R[j - 1]) / (taus[j] - taus[j - 1]);
  };
  for (size_t k = 0; k < nk_; ++k)
    for (size_t p = 0; p < np_; ++p) {
      const auto& R = r_.r_[k][p];
      const double last = chord(R, i);
      const double slope = (last - chord(R, i - 1)) / (0.5 * (taus[i] - taus[i - 2]));
      if (probe_peak_[k][p] < 100 * opt_.settle_tol ||
          std::fabs(slope) * (horizon_ - tau_) > opt_.settle_tol ||
          std::fabs(last - r_.gain_[k][p]) > opt_.settle_tol)
        return false;
      for (size_t j = std::max<size_t>(from, 1); j < i; ++j)
        if (std::fabs(chord(R, j) - last) > opt_.settle_tol) return false;
    }
  return true;
}

// S at the march points from R alone: the slope at tau_i of the parabola through the points
// i-1, i, i+1 (second order on any spacing; one-sided at the ends). Not the trapezoidal
// derivative xdot: its error from the first (Euler) step alternates in sign and never damps,
// and the Hermite interpolant would carry it into the output. Beyond the march R continues
// with the last chord slope (see the settle check).
void LtiMarch::finish() {
  const std::vector<double>& taus = r_.tau_;
  const size_t m = taus.size();
  for (size_t k = 0; k < nk_; ++k)
    for (size_t p = 0; p < np_; ++p) {
      const auto& R = r_.r_[k][p];
      auto& S = r_.s_[k][p];
      auto chord = [&](size_t j) { return (R[j] - R[j - 1]) / (taus[j] - taus[j - 1]); };
      for (size_t i = 1; i + 1 < m; ++i) {
        const double hp = taus[i] - taus[i - 1], hn = taus[i + 1] - taus[i];
        S[i] = (hn * chord(i) + hp * chord(i + 1)) / (hp + hn);
      }
      if (m >= 3) {
        const double h1 = taus[1], h2 = taus[2] - taus[1];
        S[0] = chord(1) - h1 * (chord(2) - chord(1)) / (h1 + h2);
        const double hl = taus[m - 1] - taus[m - 2], hq = taus[m - 2] - taus[m - 3];
        S[m - 1] = chord(m - 1) + hl * (chord(m - 1) - chord(m - 2)) / (hl + hq);
      }
    }
  const size_t e = m - 1;
  r_.end_slope_.assign(nk_, std::vector<double>(np_, 0.0));
  for (size_t k = 0; k < nk_; ++k)
    for (size_t p = 0; p < np_; ++p)
      r_.end_slope_[k][p] = (r_.r_[k][p][e] - r_.r_[k][p][e - 1]) / (taus[e] - taus[e - 1]);
}

Status LtiMarch::run() {
  const double h0 = opt_.first_step > 0 ? opt_.first_step : std::min(1e-12, horizon_ * 1e-9);
  LtiStats& stats = r_.stats_;
  double h = control_.ladder(h0);
  size_t next_check = 16;  // settle checks at geometrically spaced march points and times
  double next_check_tau = 0.0;
  while (tau_ < horizon_ * (1 - 1e-12)) {
    if (stats.steps + stats.rejected >= opt_.max_steps)
      return Status::Error(fmt::format("LTI march gave up at {:g} s after {} steps (max_steps)",
                                       tau_, opt_.max_steps));
    if (opt_.settle_by > 0 && tau_ > opt_.settle_by)
      return Status::Error(
          fmt::format("the responses have not settled by {:g} s (settle_by)", opt_.settle_by));
    const double step = std::min(h, horizon_ - tau_);
    StatusOr<double> a0 = solve_step(step, hist_.count < 2);
    if (!a0) return a0.status();
    const double t1 = tau_ + step;
    const double ratio = error_ratio(t1, step);
    if (ratio > 1.0) {
      ++stats.rejected;
      h = control_.shrink(step, ratio);
      if (h < control_.hmin)
        return Status::Error(fmt::format(
            "LTI march: step too small at {:g} s (h={:g} s): the truncation error of {} does not "
            "converge",
            tau_, h, circuit_.unknown_name(worst_unknown_)));
      h = control_.ladder(h);
      continue;
    }
    ++stats.steps;
    tau_ = t1;
    if (opt_.on_progress && (stats.steps & 1023) == 0) opt_.on_progress(tau_);
    accept(step, *a0);
    h = control_.grow(step, ratio);
    // Settling (see lti.h), checked whenever the step count or the time has grown by 10 %.
    const size_t i = r_.tau_.size() - 1;
    if (i >= next_check || (i >= 16 && tau_ >= next_check_tau)) {
      next_check = static_cast<size_t>(static_cast<double>(i) * 1.1) + 1;
      next_check_tau = tau_ * 1.1;
      if (settled(i)) {
        stats.settled = true;
        break;
      }
    }
  }
  stats.settled_at = tau_;
  finish();
  return Status::Ok();
}

Status LtiResponses::march(const Circuit& circuit, MnaSystem& sys, const std::vector<Probe>& probes,
                           const std::vector<std::vector<double>>& unit, const LtiOptions& opt) {
  stats_.method = "march";
  const auto started = std::chrono::steady_clock::now();
  const size_t nk = sources_.size(), np = probes.size();
  tau_.push_back(0.0);
  r_.assign(nk, std::vector<std::vector<double>>(np, std::vector<double>{0.0}));
  s_.assign(nk, std::vector<std::vector<double>>(np, std::vector<double>{0.0}));
  if (nk == 0) return Status::Ok();
  if (Status s = LtiMarch(*this, circuit, sys, probes, unit, opt).run(); !s.ok()) return s;
  stats_.factorizations += sys.klu.factorizations();
  stats_.march_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return Status::Ok();
}

}  // namespace isolink
