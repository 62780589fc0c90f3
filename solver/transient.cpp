#include "solver/transient.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

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

StatusOr<Waveform> run_transient(Circuit& circuit, const TransientOptions& opt,
                                 const std::vector<Probe>& probes, TransientStats* stats_out) {
  if (Status s = opt.validate(); !s.ok()) return s;
  TransientStats stats;
  for (const auto& e : circuit.elements()) e->bind_time(opt.tstep, opt.tstop);

  MnaSystem sys;
  if (Status s = sys.build(circuit); !s.ok()) return s;
  const int n = sys.n;
  const double tstop = opt.tstop;
  const double hmax = opt.effective_tmax();
  const double hmin = std::max(1e-18, tstop * 1e-13);
  const double tiny = tstop * 1e-12;  // breakpoints closer than this merge

  // Breakpoints: every source corner, and tstop.
  std::vector<double> bps;
  for (const auto& e : circuit.elements()) e->breakpoints(tstop, bps);
  bps.push_back(tstop);
  std::sort(bps.begin(), bps.end());
  std::vector<double> merged;
  for (double t : bps)
    if (t > tiny && (merged.empty() || t - merged.back() > tiny)) merged.push_back(t);
  bps.swap(merged);
  stats.breakpoints = static_cast<int>(bps.size());

  // Initial state.
  std::vector<double> x(n + 1, 0.0), xdot(n + 1, 0.0), hist_part(n + 1, 0.0), xnew(n + 1);
  for (const auto& [node, v] : opt.node_ic)
    if (node > n) return Status::Error(fmt::format("node_ic: unknown {} is out of range", node));
  // UIC: the charge the capacitors' ic= add beyond C x0, applied on the first step only.
  std::vector<double> uic_dq;
  if (!opt.uic) {
    if (Status s = sys.dc(circuit, x, opt.node_ic); !s.ok())
      return s.with_context("DC operating point");
    ++stats.solves;
    ++stats.factorizations;
  } else {
    for (const auto& [node, v] : opt.node_ic) x[node] = v;
    for (const auto& e : circuit.elements()) e->uic_state(x.data());
    uic_dq.assign(n + 1, 0.0);
    for (const auto& e : circuit.elements()) e->uic_charge(x.data(), uic_dq.data());
    uic_dq[0] = 0.0;
    if (std::all_of(uic_dq.begin(), uic_dq.end(), [](double v) { return v == 0.0; }))
      uic_dq.clear();
  }

  Waveform w;
  for (const auto& p : probes) w.add_column(p.label, {});
  auto record = [&](double t, const std::vector<double>& v) {
    if (t < opt.tstart - tiny) return;
    w.time.push_back(t);
    for (size_t k = 0; k < probes.size(); ++k) w.columns[k].push_back(probes[k].value(v.data()));
  };
  record(0.0, x);

  // Which unknowns the error control watches, and their tolerances (trtol folded in).
  // As SPICE does, only states count: nodes with capacitance (C diagonal) and inductor currents;
  // a node without capacitance is algebraic and follows the states.
  std::vector<int> watched;
  std::vector<double> abs_tol;
  for (int u = 1; u <= n; ++u) {
    const bool has_c = sys.c[sys.pattern.slot(u, u)] != 0.0;
    if ((circuit.unknown_is_node(u) && has_c) || circuit.unknown_is_state(u)) {
      watched.push_back(u);
      abs_tol.push_back(opt.trtol * (circuit.unknown_is_node(u) ? opt.vntol : opt.abstol));
    }
  }
  const double rel_tol = opt.trtol * opt.reltol;
  // The relative part scales with the largest |x| the unknown has had so far (its own, since
  // t = 0), not with its value now: an oscillating current passes through zero twice a period,
  // and a tolerance relative to its value there would hold the step down for nothing (that made
  // the cable's ringing currents set most steps of the 15 m example).
  // inv_tol = 1 / tolerance, recomputed only when a peak grows (rarely, once the signals have
  // had their first full swing), so the error loop has no division.
  std::vector<double> peak(watched.size(), 0.0), inv_tol(watched.size(), 0.0);
  for (size_t k = 0; k < watched.size(); ++k) {
    peak[k] = std::fabs(x[watched[k]]);
    inv_tol[k] = 1.0 / (rel_tol * peak[k] + abs_tol[k]);
  }

  // History since the last breakpoint: up to 3 points, oldest first (fixed storage).
  History hist(n, x);

  // Local truncation error of a second-order method: O(h^3).
  const StepControl control{.hmax = hmax, .hmin = hmin, .error_order = 3};

  double t = 0.0;
  size_t next_bp = 0;
  double h = control.ladder(0.1 * std::min(hmax, bps[0]));
  // The UIC step that puts the capacitors' ic= charge in place is not error-checked: keep it short.
  if (!uic_dq.empty()) h = control.ladder(1e-3 * h);
  double last_regular_h = hmax;
  bool after_bp = true;  // the next step is the first after a breakpoint (or t = 0)
  int worst_unknown = 0;

  while (t < tstop - tiny) {
    if (stats.accepted + stats.rejected >= opt.max_steps)
      return Status::Error(fmt::format("transient gave up at t={:g} s after {} steps (max_steps)",
                                       t, opt.max_steps));
    while (next_bp < bps.size() && bps[next_bp] <= t + tiny) ++next_bp;
    const double bp = next_bp < bps.size() ? bps[next_bp] : tstop;
    double step = std::min(h, hmax);
    bool lands = false;
    if (t + step >= bp - tiny) {
      step = bp - t;
      lands = true;
    } else if (t + 1.5 * step > bp) {
      step = 0.5 * (bp - t);  // avoid a sliver before the breakpoint
    }

    // Integration formula: x1' = a0 x1 + hist; system (G + a0 C) x1 = b1 - C hist.
    const bool euler = after_bp || hist.count < 2;
    const bool gear = !euler && opt.method == IntegrationMethod::Gear2;
    const double inv_step = 1.0 / step;
    double a0;
    if (euler) {
      a0 = inv_step;
      for (int u = 1; u <= n; ++u) hist_part[u] = -x[u] * inv_step;
    } else if (gear) {
      const double h0 = t - hist.t(hist.count - 2);
      const double rho = step / h0;
      a0 = (1 + 2 * rho) / (step * (1 + rho));
      const double a1 = -(1 + rho) * inv_step, a2 = rho * rho / (step * (1 + rho));
      const auto& xm1 = hist.x(hist.count - 2);
      for (int u = 1; u <= n; ++u) hist_part[u] = a1 * x[u] + a2 * xm1[u];
    } else {
      a0 = 2.0 * inv_step;
      for (int u = 1; u <= n; ++u) hist_part[u] = -a0 * x[u] - xdot[u];
    }
    sys.rhs(t + step, xnew);
    sys.sub_c_times(hist_part.data(), xnew.data());
    if (!uic_dq.empty())  // Euler: C x1 / h = C x0 / h + dq / h + ...
      for (int u = 1; u <= n; ++u) xnew[u] += uic_dq[u] * inv_step;
    if (Status s = sys.select_or_factor(circuit, a0); !s.ok())
      return s.with_context(fmt::format("transient at t={:g} s", t + step));
    if (Status s = sys.solve(xnew); !s.ok())
      return s.with_context(fmt::format("t={:g} s", t + step));
    ++stats.solves;
    if (Status s = MnaSystem::check_finite(circuit, xnew, t + step, "transient step"); !s.ok())
      return s;

    // Truncation error h^3 * coef * x''' with x''' = 6 x the third divided difference over the
    // last four points, written as weights on the three successive differences (no division in
    // the loop), against trtol * (reltol * peak |x| + abstol) with the peak up to the last
    // accepted point; ratio = the worst error / tolerance.
    double ratio = 0.0;
    if (hist.count == 3) {
      const double t1 = t + step, t0 = hist.t(2), tm1 = hist.t(1), tm2 = hist.t(0);
      const auto &x0 = hist.x(2), &xm1 = hist.x(1), &xm2 = hist.x(0);
      const double coef = gear ? (2.0 / 9.0) * 6.0 : (1.0 / 12.0) * 6.0;
      const double ia = 1.0 / (t1 - t0), ib = 1.0 / (t0 - tm1), ic = 1.0 / (tm1 - tm2);
      const double ie = 1.0 / (t1 - tm1), iff = 1.0 / (t0 - tm2), ig = 1.0 / (t1 - tm2);
      const double h3 = step * step * step * coef * ig;
      const double w1 = h3 * ie * ia, w2 = -h3 * ib * (ie + iff), w3 = h3 * iff * ic;
      for (size_t k = 0; k < watched.size(); ++k) {
        const int u = watched[k];
        const double r = inv_tol[k] * std::fabs(w1 * (xnew[u] - x0[u]) + w2 * (x0[u] - xm1[u]) +
                                                w3 * (xm1[u] - xm2[u]));
        if (r > ratio) {
          ratio = r;
          worst_unknown = u;
        }
      }
    }

    // The first step after a breakpoint (backward Euler, from a history of one point) is checked
    // one step late: with the second step's point, the second divided difference over the three
    // points gives x'' and the Euler truncation error h1^2 x'' / 2. When it is too large both
    // steps are undone and the first one is retried smaller (the second step, at most twice the
    // first, is then accurate too: its trapezoidal error is third order).
    if (hist.count == 2 && !watched.empty()) {
      const double t0 = hist.t(0), t1 = hist.t(1), t2 = t + step;
      const auto &x0 = hist.x(0), &x1 = hist.x(1);
      const double h1 = t1 - t0;
      const double i21 = 1.0 / (t2 - t1), i10 = 1.0 / h1, i20 = 1.0 / (t2 - t0);
      double ratio1 = 0.0;
      for (size_t k = 0; k < watched.size(); ++k) {
        const int u = watched[k];
        const double dd2 = ((xnew[u] - x1[u]) * i21 - (x1[u] - x0[u]) * i10) * i20;
        const double r = inv_tol[k] * h1 * h1 * std::fabs(dd2);
        if (r > ratio1) ratio1 = r, worst_unknown = u;
      }
      if (ratio1 > 1.0) {
        stats.rejected += 2;
        --stats.accepted;
        // Backward Euler's error is O(h^2).
        const double h_retry = StepControl::shrink_by_order(h1, ratio1, 2, 0.1);
        if (h_retry < hmin)
          return Status::Error(fmt::format(
              "time step too small at t={:g} s (h={:g} s): the truncation error of {} does not "
              "converge",
              t0, h_retry, circuit.unknown_name(worst_unknown)));
        if (!w.time.empty() && w.time.back() == t1) {  // t1 was written out: take it back
          w.time.pop_back();
          for (auto& c : w.columns) c.pop_back();
        }
        t = t0;
        std::copy(x0.begin(), x0.end(), x.begin());
        hist.reset(t0, x);
        after_bp = true;
        h = control.ladder(h_retry);
        continue;
      }
    }

    if (ratio > 1.0) {
      ++stats.rejected;
      h = control.shrink(step, ratio);
      if (h < hmin)
        return Status::Error(fmt::format(
            "time step too small at t={:g} s (h={:g} s): the truncation error of {} does not "
            "converge",
            t, h, circuit.unknown_name(worst_unknown)));
      h = control.ladder(h);
      continue;
    }

    // Accept.
    ++stats.accepted;
    if (opt.on_progress && (stats.accepted & 1023) == 0) opt.on_progress(t);
    for (int u = 1; u <= n; ++u) xdot[u] = a0 * xnew[u] + hist_part[u];
    t = lands ? bp : t + step;
    std::swap(x, xnew);
    hist.push(t, x);
    record(t, x);
    for (size_t k = 0; k < watched.size(); ++k) {
      const double a = std::fabs(x[watched[k]]);
      if (a > peak[k]) peak[k] = a, inv_tol[k] = 1.0 / (rel_tol * a + abs_tol[k]);
    }

    if (!lands) last_regular_h = step;
    h = control.grow(step, ratio);
    after_bp = false;
    if (!uic_dq.empty()) {
      // The UIC step moved the capacitors' charge to their ic=: restart the formula from here,
      // as at a breakpoint (x is consistent from now on).
      uic_dq.clear();
      after_bp = true;
      hist.reset(t, x);
    }
    if (lands) {
      // Restart the formula at the corner: small Euler step, fresh history.
      after_bp = true;
      h = control.ladder(0.1 * std::min(last_regular_h,
                                        (next_bp + 1 < bps.size() ? bps[next_bp + 1] : tstop) - t));
      hist.reset(t, x);
    }
  }

  stats.factorizations += sys.klu.factorizations();
  stats.reuses = sys.klu.reuses();
  if (stats_out) *stats_out = stats;
  return w;
}

}  // namespace isolink
