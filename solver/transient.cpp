#include "solver/transient.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "solver/klu_solver.h"
#include "solver/mna.h"
#include "solver/mna_system.h"
#include "solver/step_control.h"

namespace isolink {

double TransientOptions::effective_tmax() const {
  if (tmax > 0) return tmax;
  return std::min(tstep, (tstop - tstart) / 50.0);
}

Status TransientOptions::validate() const {
  auto bad = [](const char* field, double v, const char* rule) {
    return Status::Error(fmt::format("transient option {} = {:g}: {}", field, v, rule));
  };
  if (!(tstep > 0)) return bad("tstep", tstep, "must be positive");
  if (!(tstart >= 0)) return bad("tstart", tstart, "must not be negative");
  if (!(tstop > tstart)) return bad("tstop", tstop, "must be greater than tstart");
  if (!(tmax >= 0)) return bad("tmax", tmax, "must not be negative");
  if (!(reltol > 0 && reltol < 1)) return bad("reltol", reltol, "must be in (0, 1)");
  if (!(vntol > 0)) return bad("vntol", vntol, "must be positive");
  if (!(abstol > 0)) return bad("abstol", abstol, "must be positive");
  if (!(trtol > 0)) return bad("trtol", trtol, "must be positive");
  if (!(chgtol > 0)) return bad("chgtol", chgtol, "must be positive");
  if (max_steps <= 0) return bad("max_steps", static_cast<double>(max_steps), "must be positive");
  for (const auto& [node, v] : node_ic) {
    if (node <= 0) return bad("node_ic node", node, "must be a node unknown (> 0)");
    if (!std::isfinite(v)) return bad("node_ic value", v, "must be finite");
  }
  return Status::Ok();
}

Status TransientOptions::set_option(const std::string& key, const CardArg& value, bool* known) {
  *known = true;
  auto number = [&](double* field) -> Status {
    if (value.kind != CardArg::Kind::Number)
      return error_at(value.loc, "option " + key + " expects a number");
    // Checked here, where the .options card's position is known (validate() has none).
    const bool ok = key == "reltol" ? value.number > 0 && value.number < 1 : value.number > 0;
    if (!ok || !std::isfinite(value.number))
      return error_at(value.loc, fmt::format("option {} = {:g}: must be {}", key, value.number,
                                             key == "reltol" ? "in (0, 1)" : "positive"));
    *field = value.number;
    return Status::Ok();
  };
  if (key == "reltol") return number(&reltol);
  if (key == "vntol") return number(&vntol);
  if (key == "abstol") return number(&abstol);
  if (key == "trtol") return number(&trtol);
  if (key == "chgtol") return number(&chgtol);
  if (key == "method") {
    if (value.kind == CardArg::Kind::Word && (value.word == "trap" || value.word == "trapezoidal"))
      method = IntegrationMethod::Trapezoidal;
    else if (value.kind == CardArg::Kind::Word && value.word == "gear")
      method = IntegrationMethod::Gear2;
    else
      return error_at(value.loc, "option method expects trap or gear");
    return Status::Ok();
  }
  if (key == "maxord") return Status::Ok();  // Gear-2 is the only Gear order; accepted
  *known = false;
  return Status::Ok();
}

namespace {

// The last accepted points since a breakpoint, oldest first, in rotating fixed storage.
struct History {
  std::array<double, 3> times{};
  std::array<std::vector<double>, 3> states;
  int first = 0, count = 0;

  History(int n, const std::vector<double>& x0) {
    for (auto& s : states) s.resize(n + 1);
    reset(0.0, x0);
  }
  double t(int i) const { return times[(first + i) % 3]; }
  const std::vector<double>& x(int i) const { return states[(first + i) % 3]; }
  void reset(double t0, const std::vector<double>& x0) {
    first = 0, count = 1, times[0] = t0;
    states[0] = x0;
  }
  void push(double t1, const std::vector<double>& x1) {
    if (count == 3) first = (first + 1) % 3, --count;
    const int slot = (first + count) % 3;
    times[slot] = t1;
    std::copy(x1.begin(), x1.end(), states[slot].begin());
    ++count;
  }
};

}  // namespace

StatusOr<std::vector<double>> dc_operating_point(const Circuit& circuit) {
  MnaSystem sys;
  if (Status s = sys.build(circuit); !s.ok()) return s;
  std::vector<double> x(sys.n + 1);
  if (Status s = sys.dc(circuit, x); !s.ok()) return s.with_context("DC operating point");
  return x;
}

namespace {

// Every source corner in (tiny, tstop], and tstop, sorted; corners closer than tiny merge.
std::vector<double> merged_breakpoints(const Circuit& circuit, double tstop, double tiny) {
  std::vector<double> bps;
  for (const auto& e : circuit.elements()) e->breakpoints(tstop, bps);
  bps.push_back(tstop);
  std::sort(bps.begin(), bps.end());
  std::vector<double> merged;
  for (double t : bps)
    if (t > tiny && (merged.empty() || t - merged.back() > tiny)) merged.push_back(t);
  return merged;
}

// Which unknowns the error control watches, and 1 / tolerance of each (trtol folded in).
// As SPICE does, only states count: nodes with capacitance (C diagonal) and inductor currents;
// a node without capacitance is algebraic and follows the states.
// The relative part scales with the largest |x| the unknown has had so far (its own, since
// t = 0), not with its value now: an oscillating current passes through zero twice a period,
// and a tolerance relative to its value there would hold the step down for nothing (that made
// the cable's ringing currents set most steps of the 15 m example).
// inv_tol = 1 / tolerance, recomputed only when a peak grows (rarely, once the signals have
// had their first full swing), so the error loop has no division.
struct WatchedStates {
  std::vector<int> unknowns;
  std::vector<double> abs_tol, peak, inv_tol;
  double rel_tol = 0.0;

  // x0: the unknowns, then the nonlinear ports' charges (x0.size() - 1 - sys.n of them).
  WatchedStates(const Circuit& circuit, const MnaSystem& sys, const TransientOptions& opt,
                const std::vector<double>& x0) {
    for (int u = 1; u <= sys.n; ++u) {
      const bool has_c = sys.c[sys.pattern.slot(u, u)] != 0.0;
      if ((circuit.unknown_is_node(u) && has_c) || circuit.unknown_is_state(u)) {
        unknowns.push_back(u);
        abs_tol.push_back(opt.trtol * (circuit.unknown_is_node(u) ? opt.vntol : opt.abstol));
      }
    }
    // The nonlinear charges (junction and diffusion charge): their truncation error is measured
    // on the charge itself, against chgtol as SPICE's.
    for (int u = sys.n + 1; u < static_cast<int>(x0.size()); ++u) {
      unknowns.push_back(u);
      abs_tol.push_back(opt.trtol * opt.chgtol);
    }
    rel_tol = opt.trtol * opt.reltol;
    peak.assign(unknowns.size(), 0.0);
    inv_tol.assign(unknowns.size(), 0.0);
    for (size_t k = 0; k < unknowns.size(); ++k) {
      peak[k] = std::fabs(x0[unknowns[k]]);
      inv_tol[k] = 1.0 / (rel_tol * peak[k] + abs_tol[k]);
    }
  }
  // After an accepted step: the peaks, and the tolerances of those that grew.
  void track(const std::vector<double>& x) {
    for (size_t k = 0; k < unknowns.size(); ++k) {
      const double a = std::fabs(x[unknowns[k]]);
      if (a > peak[k]) peak[k] = a, inv_tol[k] = 1.0 / (rel_tol * a + abs_tol[k]);
    }
  }
};

// One run of the transient engine: the state between steps and the pieces of a step.
class TransientMarch {
 public:
  TransientMarch(const Circuit& circuit, const TransientOptions& opt,
                 const std::vector<Probe>& probes, MnaSystem& sys)
      : circuit_(circuit),
        opt_(opt),
        probes_(probes),
        sys_(sys),
        n_(sys.n),
        tiny_(opt.tstop * 1e-12),  // breakpoints closer than this merge
        // The local truncation error of a second-order method: O(h^3).
        control_{.hmax = opt.effective_tmax(),
                 .hmin = std::max(1e-18, opt.tstop * 1e-13),
                 .error_order = 3},
        ports_(count_ports(circuit)),
        m_(n_ + ports_),
        x_(m_ + 1, 0.0),
        xdot_(m_ + 1, 0.0),
        hist_part_(m_ + 1, 0.0),
        xnew_(m_ + 1) {
    for (const auto& e : circuit.elements())
      for (int k = 0; k < e->nonlinear_port_count(); ++k)
        has_controlled_ = has_controlled_ || e->nonlinear_port(k).controlled;
    if (ports_ > 0) {
      newton_.bind(circuit, sys.pattern);
      newton_.tolerances() = opt.newton;
      newton_x_.assign(n_ + 1, 0.0);
      newton_rhs_.assign(n_ + 1, 0.0);
      a_lin_.assign(sys.pattern.nonzeros(), 0.0);
    }
  }

  StatusOr<Waveform> run(TransientStats& stats);

 private:
  Status initial_state();
  // The integration formula for a step of `step` from t_: x1' = a0 x1 + hist_part_; returns a0.
  double formula(double step, bool euler, bool gear, const History& hist);
  // Solves (G + a0 C) x1 = b1 - C hist_part_ (+ the UIC charge) into xnew_; with nonlinear
  // ports by Newton's iteration, *converged = false when it did not converge (the caller
  // retries a shorter step).
  Status solve_step(double step, double a0, bool* converged);
  Status newton_step(double t1, double a0, bool* converged);
  // The ports' charges at x_ (after the operating point) into x_'s charge entries.
  void initial_charges();
  Status newton_failed(double t, double h) const;
  // Truncation error / tolerance of the step (0 until there are four points); the worst unknown
  // into worst_unknown_.
  double truncation_ratio(double step, bool gear, const History& hist);
  // True when a controlled port (a switch) changed state between x_ and xnew_.
  bool control_changed() const;
  // The backward-Euler first step after a breakpoint, judged one step late (see run()).
  double euler_start_ratio(double step, const History& hist);
  Status too_small(double t, double h) const;
  void record(double t, const std::vector<double>& v);

  static int count_ports(const Circuit& circuit) {
    int p = 0;
    for (const auto& e : circuit.elements()) p += e->nonlinear_port_count();
    return p;
  }

  const Circuit& circuit_;
  bool has_controlled_ = false;  // a switch: control_changed() is checked on every step
  const TransientOptions& opt_;
  const std::vector<Probe>& probes_;
  MnaSystem& sys_;
  const int n_;
  const double tiny_;
  const StepControl control_;
  TransientStats stats_;
  // The nonlinear ports' count; the state vectors hold the unknowns 0..n_, then one charge per
  // port (n_ + 1 .. m_), integrated by the same formula and watched by the same error control.
  const int ports_;
  const int m_;
  std::vector<double> x_, xdot_, hist_part_, xnew_;
  NewtonSolver newton_;
  std::vector<double> newton_x_, newton_rhs_, a_lin_;
  double a_lin_alpha_ = -1.0;  // the a0 that a_lin_ = G + a0 C was computed for
  // UIC: the charge the capacitors' ic= add beyond C x0, applied on the first step only.
  std::vector<double> uic_dq_;
  std::optional<WatchedStates> watched_;  // set once the initial state is known
  double t_ = 0.0;
  int worst_unknown_ = 0;
  Waveform w_;
};

Status TransientMarch::initial_state() {
  for (const auto& [node, v] : opt_.node_ic)
    if (node > n_) return Status::Error(fmt::format("node_ic: unknown {} is out of range", node));
  if (!opt_.uic) {
    if (Status s = sys_.dc(circuit_, x_, opt_.node_ic); !s.ok())
      return s.with_context("DC operating point");
    ++stats_.solves;
    ++stats_.factorizations;
    initial_charges();
    return Status::Ok();
  }
  for (const auto& [node, v] : opt_.node_ic) x_[node] = v;
  for (const auto& e : circuit_.elements()) e->uic_state(x_.data());
  uic_dq_.assign(n_ + 1, 0.0);
  for (const auto& e : circuit_.elements()) e->uic_charge(x_.data(), uic_dq_.data());
  uic_dq_[0] = 0.0;
  if (std::all_of(uic_dq_.begin(), uic_dq_.end(), [](double v) { return v == 0.0; }))
    uic_dq_.clear();
  initial_charges();
  return Status::Ok();
}

void TransientMarch::initial_charges() {
  int k = 0;
  for (const auto& e : circuit_.elements())
    for (int j = 0; j < e->nonlinear_port_count(); ++j, ++k) {
      const NonlinearPort p = e->nonlinear_port(j);
      const double v = x_[p.p] - x_[p.n];
      x_[n_ + 1 + k] = p.controlled ? e->eval_controlled_port(j, v, x_[p.cp] - x_[p.cn]).q
                                    : e->eval_port(j, v).q;
    }
}

void TransientMarch::record(double t, const std::vector<double>& v) {
  if (t < opt_.tstart - tiny_) return;
  w_.time.push_back(t);
  for (size_t k = 0; k < probes_.size(); ++k) w_.columns[k].push_back(probes_[k].value(v.data()));
}

double TransientMarch::formula(double step, bool euler, bool gear, const History& hist) {
  const int n = m_;  // the unknowns and the ports' charges alike
  const double inv_step = 1.0 / step;
  double a0 = 0.0;
  if (euler) {
    a0 = inv_step;
    for (int u = 1; u <= n; ++u) hist_part_[u] = -x_[u] * inv_step;
  } else if (gear) {
    const double h0 = t_ - hist.t(hist.count - 2);
    const double rho = step / h0;
    a0 = (1 + 2 * rho) / (step * (1 + rho));
    const double a1 = -(1 + rho) * inv_step, a2 = rho * rho / (step * (1 + rho));
    const auto& xm1 = hist.x(hist.count - 2);
    for (int u = 1; u <= n; ++u) hist_part_[u] = a1 * x_[u] + a2 * xm1[u];
  } else {
    a0 = 2.0 * inv_step;
    for (int u = 1; u <= n; ++u) hist_part_[u] = -a0 * x_[u] - xdot_[u];
  }
  return a0;
}

Status TransientMarch::solve_step(double step, double a0, bool* converged) {
  const double t1 = t_ + step;
  *converged = true;
  if (ports_ > 0) return newton_step(t1, a0, converged);
  sys_.rhs(t1, xnew_);
  sys_.sub_c_times(hist_part_.data(), xnew_.data());
  if (!uic_dq_.empty()) {  // Euler: C x1 / h = C x0 / h + dq / h + ...
    const double inv_step = 1.0 / step;
    for (int u = 1; u <= n_; ++u) xnew_[u] += uic_dq_[u] * inv_step;
  }
  if (Status s = sys_.select_or_factor(circuit_, a0); !s.ok())
    return s.with_context(fmt::format("transient at t={:g} s", t1));
  if (Status s = sys_.solve(xnew_); !s.ok()) return s.with_context(fmt::format("t={:g} s", t1));
  ++stats_.solves;
  return MnaSystem::check_finite(circuit_, xnew_, t1, "transient step");
}

Status TransientMarch::newton_step(double t1, double a0, bool* converged) {
  std::vector<double>& rhs = newton_rhs_;
  sys_.rhs(t1, rhs);
  sys_.sub_c_times(hist_part_.data(), rhs.data());
  if (!uic_dq_.empty()) {
    const double inv_step = 1.0 / (t1 - t_);
    for (int u = 1; u <= n_; ++u) rhs[u] += uic_dq_[u] * inv_step;
  }
  if (a0 != a_lin_alpha_) {
    for (std::size_t k = 0; k < a_lin_.size(); ++k) a_lin_[k] = sys_.g[k] + a0 * sys_.c[k];
    a_lin_alpha_ = a0;
  }
  // The first iterate: the last accepted point, moved along its slope (a predictor).
  const double step = t1 - t_;
  for (int u = 0; u <= n_; ++u) newton_x_[u] = x_[u] + step * xdot_[u];
  NewtonInput in;
  in.linear_values = a_lin_.data();
  in.rhs = &rhs;
  in.a0 = a0;
  in.charge_history = hist_part_.data() + n_ + 1;
  NewtonResult r = newton_.solve(circuit_, sys_.klu, in, newton_x_);
  stats_.newton_iterations += r.iterations;
  stats_.solves += r.iterations;
  if (!r.error.ok()) return r.error.with_context(fmt::format("transient at t={:g} s", t1));
  *converged = r.converged;
  if (!r.converged) {
    ++stats_.newton_failures;
    return Status::Ok();
  }
  std::copy(newton_x_.begin(), newton_x_.end(), xnew_.begin());
  for (int k = 0; k < ports_; ++k) xnew_[n_ + 1 + k] = newton_.charge(k);
  return Status::Ok();
}

Status TransientMarch::newton_failed(double t, double h) const {
  return Status::Error(fmt::format(
      "time step too small at t={:g} s (h={:g} s): Newton's iteration does not converge at {}; "
      "try a smaller .tran TMAX, a series resistance (RS) in the diode's model, or a resistor "
      "where an ideal source drives the diode directly",
      t, h, newton_.worst_port(circuit_)));
}

// Truncation error h^3 * coef * x''' with x''' = 6 x the third divided difference over the
// last four points, written as weights on the three successive differences (no division in
// the loop), against trtol * (reltol * peak |x| + abstol) with the peak up to the last
// accepted point; ratio = the worst error / tolerance.
double TransientMarch::truncation_ratio(double step, bool gear, const History& hist) {
  if (hist.count != 3) return 0.0;
  const WatchedStates& ws = *watched_;
  const double t1 = t_ + step, t0 = hist.t(2), tm1 = hist.t(1), tm2 = hist.t(0);
  const auto &x0 = hist.x(2), &xm1 = hist.x(1), &xm2 = hist.x(0);
  const double coef = gear ? (2.0 / 9.0) * 6.0 : (1.0 / 12.0) * 6.0;
  const double ia = 1.0 / (t1 - t0), ib = 1.0 / (t0 - tm1), ic = 1.0 / (tm1 - tm2);
  const double ie = 1.0 / (t1 - tm1), iff = 1.0 / (t0 - tm2), ig = 1.0 / (t1 - tm2);
  const double h3 = step * step * step * coef * ig;
  const double w1 = h3 * ie * ia, w2 = -h3 * ib * (ie + iff), w3 = h3 * iff * ic;
  double ratio = 0.0;
  for (size_t k = 0; k < ws.unknowns.size(); ++k) {
    const int u = ws.unknowns[k];
    const double r = ws.inv_tol[k] * std::fabs(w1 * (xnew_[u] - x0[u]) + w2 * (x0[u] - xm1[u]) +
                                               w3 * (xm1[u] - xm2[u]));
    if (r > ratio) {
      ratio = r;
      worst_unknown_ = u;
    }
  }
  return ratio;
}

// With the second step's point, the second divided difference over the three points gives x''
// and the first step's Euler truncation error h1^2 x'' / 2.
double TransientMarch::euler_start_ratio(double step, const History& hist) {
  const WatchedStates& ws = *watched_;
  const double t0 = hist.t(0), t1 = hist.t(1), t2 = t_ + step;
  const auto &x0 = hist.x(0), &x1 = hist.x(1);
  const double h1 = t1 - t0;
  const double i21 = 1.0 / (t2 - t1), i10 = 1.0 / h1, i20 = 1.0 / (t2 - t0);
  double ratio1 = 0.0;
  for (size_t k = 0; k < ws.unknowns.size(); ++k) {
    const int u = ws.unknowns[k];
    const double dd2 = ((xnew_[u] - x1[u]) * i21 - (x1[u] - x0[u]) * i10) * i20;
    const double r = ws.inv_tol[k] * h1 * h1 * std::fabs(dd2);
    if (r > ratio1) ratio1 = r, worst_unknown_ = u;
  }
  return ratio1;
}

Status TransientMarch::too_small(double t, double h) const {
  return Status::Error(
      fmt::format("time step too small at t={:g} s (h={:g} s): the truncation error of {} does "
                  "not converge",
                  t, h, circuit_.unknown_name(worst_unknown_)));
}

bool TransientMarch::control_changed() const {
  for (const auto& e : circuit_.elements())
    for (int k = 0; k < e->nonlinear_port_count(); ++k) {
      const NonlinearPort p = e->nonlinear_port(k);
      if (p.controlled && e->control_state(k, x_[p.cp] - x_[p.cn]) !=
                              e->control_state(k, xnew_[p.cp] - xnew_[p.cn]))
        return true;
    }
  return false;
}

StatusOr<Waveform> TransientMarch::run(TransientStats& stats_out) {
  const double tstop = opt_.tstop, tiny = tiny_, hmax = control_.hmax, hmin = control_.hmin;
  const std::vector<double> bps = merged_breakpoints(circuit_, tstop, tiny);
  stats_.breakpoints = static_cast<int>(bps.size());
  if (Status s = initial_state(); !s.ok()) return s;
  for (const auto& p : probes_) w_.add_column(p.label, {});
  record(0.0, x_);
  watched_.emplace(circuit_, sys_, opt_, x_);

  // History since the last breakpoint: up to 3 points, oldest first (fixed storage).
  History hist(m_, x_);
  size_t next_bp = 0;
  double h = control_.ladder(0.1 * std::min(hmax, bps[0]));
  // The UIC step that puts the capacitors' ic= charge in place is not error-checked: keep it short.
  if (!uic_dq_.empty()) h = control_.ladder(1e-3 * h);
  double last_regular_h = hmax;
  bool after_bp = true;  // the next step is the first after a breakpoint (or t = 0)

  while (t_ < tstop - tiny) {
    if (stats_.accepted + stats_.rejected >= opt_.max_steps)
      return Status::Error(fmt::format("transient gave up at t={:g} s after {} steps (max_steps)",
                                       t_, opt_.max_steps));
    while (next_bp < bps.size() && bps[next_bp] <= t_ + tiny) ++next_bp;
    const double bp = next_bp < bps.size() ? bps[next_bp] : tstop;
    double step = std::min(h, hmax);
    bool lands = false;
    if (t_ + step >= bp - tiny) {
      step = bp - t_;
      lands = true;
    } else if (t_ + 1.5 * step > bp) {
      step = 0.5 * (bp - t_);  // avoid a sliver before the breakpoint
    }

    const bool euler = after_bp || hist.count < 2;
    const bool gear = !euler && opt_.method == IntegrationMethod::Gear2;
    const double a0 = formula(step, euler, gear, hist);
    bool converged = true;
    if (Status s = solve_step(step, a0, &converged); !s.ok()) return s;
    if (!converged) {  // Newton did not converge: an eighth of the step, as SPICE
      ++stats_.rejected;
      h = step / 8;
      if (h < hmin) return newton_failed(t_, h);
      h = control_.ladder(h);
      continue;
    }
    // A switch that changed state in this step: its end is a corner of the solution, taken as a
    // breakpoint (no error check across it, the formula restarted after it).
    const bool event = has_controlled_ && control_changed();
    if (event) ++stats_.breakpoints;
    const double ratio = event ? 0.0 : truncation_ratio(step, gear, hist);

    // The first step after a breakpoint (backward Euler, from a history of one point) is checked
    // one step late, with the second step's point. When its error is too large both steps are
    // undone and the first one is retried smaller (the second step, at most twice the first, is
    // then accurate too: its trapezoidal error is third order).
    if (!event && hist.count == 2 && !watched_->unknowns.empty()) {
      const double ratio1 = euler_start_ratio(step, hist);
      if (ratio1 > 1.0) {
        stats_.rejected += 2;
        --stats_.accepted;
        const double t0 = hist.t(0), t1 = hist.t(1);
        // Backward Euler's local error is O(h^2).
        const double h_retry = StepControl::shrink_by_order(t1 - t0, ratio1, 2, 0.1);
        if (h_retry < hmin) return too_small(t0, h_retry);
        if (!w_.time.empty() && w_.time.back() == t1) {  // t1 was written out: take it back
          w_.time.pop_back();
          for (auto& c : w_.columns) c.pop_back();
        }
        t_ = t0;
        std::copy(hist.x(0).begin(), hist.x(0).end(), x_.begin());
        hist.reset(t0, x_);
        after_bp = true;
        h = control_.ladder(h_retry);
        continue;
      }
    }

    if (ratio > 1.0) {
      ++stats_.rejected;
      h = control_.shrink(step, ratio);
      if (h < hmin) return too_small(t_, h);
      h = control_.ladder(h);
      continue;
    }

    // Accept.
    ++stats_.accepted;
    if (opt_.on_progress && (stats_.accepted & 1023) == 0) opt_.on_progress(t_);
    for (int u = 1; u <= m_; ++u) xdot_[u] = a0 * xnew_[u] + hist_part_[u];
    t_ = lands ? bp : t_ + step;
    std::swap(x_, xnew_);
    hist.push(t_, x_);
    record(t_, x_);
    watched_->track(x_);

    if (!lands) last_regular_h = step;
    h = control_.grow(step, ratio);
    after_bp = false;
    if (!uic_dq_.empty()) {
      // The UIC step moved the capacitors' charge to their ic=: restart the formula from here,
      // as at a breakpoint (x is consistent from now on).
      uic_dq_.clear();
      after_bp = true;
      hist.reset(t_, x_);
    }
    if (event && !lands) {
      after_bp = true;
      h = control_.ladder(0.1 * std::min(last_regular_h, bp - t_));
      hist.reset(t_, x_);
    }
    if (lands) {
      // Restart the formula at the corner: small Euler step, fresh history.
      after_bp = true;
      const double next = next_bp + 1 < bps.size() ? bps[next_bp + 1] : tstop;
      h = control_.ladder(0.1 * std::min(last_regular_h, next - t_));
      hist.reset(t_, x_);
    }
  }

  stats_.factorizations += sys_.klu.factorizations();
  stats_.reuses = sys_.klu.reuses();
  stats_out = stats_;
  return std::move(w_);
}

}  // namespace

StatusOr<Waveform> run_transient(Circuit& circuit, const TransientOptions& opt,
                                 const std::vector<Probe>& probes, TransientStats* stats_out) {
  if (Status s = opt.validate(); !s.ok()) return s;
  for (const auto& e : circuit.elements()) e->bind_time(opt.tstep, opt.tstop);
  MnaSystem sys;
  if (Status s = sys.build(circuit); !s.ok()) return s;
  TransientStats stats;
  StatusOr<Waveform> w = TransientMarch(circuit, opt, probes, sys).run(stats);
  if (w.ok() && stats_out) *stats_out = stats;
  return w;
}

}  // namespace isolink
