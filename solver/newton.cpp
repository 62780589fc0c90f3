#include "solver/newton.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "solver/mna_system.h"

namespace isolink {

void NewtonSolver::bind(const Circuit& circuit, const MnaPattern& pattern) {
  ports_.clear();
  node_diagonals_.clear();
  for (const auto& e : circuit.elements())
    for (int k = 0; k < e->nonlinear_port_count(); ++k) {
      const NonlinearPort np = e->nonlinear_port(k);
      Port port;
      port.element = e.get();
      port.index = k;
      port.p = np.p, port.n = np.n;
      port.controlled = np.controlled, port.cp = np.cp, port.cn = np.cn;
      port.pp = pattern.slot(np.p, np.p), port.nn = pattern.slot(np.n, np.n);
      port.pn = pattern.slot(np.p, np.n), port.np = pattern.slot(np.n, np.p);
      ports_.push_back(port);
    }
  for (int u = 1; u < circuit.node_count(); ++u) node_diagonals_.push_back(pattern.slot(u, u));
  values_.assign(pattern.value_count(), 0.0);
  rhs_.assign(circuit.unknown_count() + 1, 0.0);
}

void NewtonSolver::restart(bool at_start_voltages) {
  at_start_ = at_start_voltages;
  for (Port& p : ports_) p.evaluated = false;
}

bool NewtonSolver::load(const std::vector<double>& x, const NewtonInput& in) {
  std::copy(in.linear_values, in.linear_values + values_.size() - 1, values_.begin());
  values_.back() = 0.0;  // the trash slot
  std::copy(in.rhs->begin(), in.rhs->end(), rhs_.begin());
  for (Slot s : node_diagonals_) values_[s] += in.gshunt;
  const double a0 = in.a0;
  const auto fixed = [&](int u) { return in.fixed_rows && (*in.fixed_rows)[u]; };
  bool consistent = !at_start_;
  double worst_excess = 0.0;
  for (std::size_t k = 0; k < ports_.size(); ++k) {
    Port& port = ports_[k];
    const double v_raw = x[port.p] - x[port.n];
    bool limited = false;
    double v = v_raw;
    if (at_start_)
      v = port.element->port_start_voltage(port.index);
    else if (port.evaluated)
      v = port.element->limit_port(port.index, v_raw, port.v, &limited);
    const PortEval e =
        port.controlled ? port.element->eval_controlled_port(port.index, v, x[port.cp] - x[port.cn])
                        : port.element->eval_port(port.index, v);
    if (port.evaluated && !at_start_) {
      // The residual: the port's current at the new voltage against the linearisation's.
      const PortEval& o = port.eval;
      const double predicted = o.i + a0 * o.q + (o.g + a0 * o.c) * (v_raw - port.v);
      const double actual = e.i + a0 * e.q;
      const double tol =
          tol_.reltol * std::max(std::fabs(predicted), std::fabs(actual)) + tol_.abstol;
      const double excess = std::fabs(predicted - actual) / tol;
      if (limited || excess > 1.0) consistent = false;
      if (excess > worst_excess || (limited && worst_ < 0))
        worst_excess = excess, worst_ = static_cast<int>(k);
    } else {
      consistent = false;
    }
    port.v = v, port.eval = e, port.evaluated = true;
    const double hq = in.charge_history ? in.charge_history[k] : 0.0;
    const double geq = e.g + a0 * e.c;
    const double ieq = e.i + a0 * e.q + hq - geq * v;
    if (!fixed(port.p)) {
      values_[port.pp] += geq, values_[port.pn] -= geq;
      rhs_[port.p] -= ieq;
    }
    if (!fixed(port.n)) {
      values_[port.nn] += geq, values_[port.np] -= geq;
      rhs_[port.n] += ieq;
    }
  }
  values_.back() = 0.0;
  rhs_[0] = 0.0;
  at_start_ = false;
  return consistent;
}

bool NewtonSolver::update_small(const Circuit& circuit, const std::vector<double>& x_old,
                                const std::vector<double>& x_new,
                                const NewtonTolerances& tol) const {
  for (std::size_t u = 1; u < x_new.size(); ++u) {
    const double abs = circuit.unknown_is_node(static_cast<int>(u)) ? tol.vntol : tol.abstol;
    const double bound = tol.reltol * std::max(std::fabs(x_new[u]), std::fabs(x_old[u])) + abs;
    if (std::fabs(x_new[u] - x_old[u]) > bound) return false;
  }
  return true;
}

NewtonResult NewtonSolver::solve(const Circuit& circuit, KluSolver& klu, const NewtonInput& in,
                                 std::vector<double>& x) {
  NewtonResult r;
  worst_ = -1;
  previous_ = x;
  for (int it = 1; it <= tol_.max_iterations; ++it) {
    const bool consistent = load(x, in);
    if (it > 1 && consistent && update_small(circuit, previous_, x, tol_)) {
      r.converged = true;
      r.iterations = it - 1;
      return r;
    }
    if (Status s = klu.factor_once(values_.data()); !s.ok()) {
      if (klu.singular_column() >= 0)
        s = Status::Error(fmt::format("singular matrix: {} is not determined by the circuit",
                                      circuit.unknown_name(klu.singular_column() + 1)));
      r.error = s.with_context("Newton iteration");
      return r;
    }
    previous_ = x;
    if (Status s = klu.solve(rhs_.data() + 1); !s.ok()) {
      r.error = s;
      return r;
    }
    rhs_[0] = 0.0;
    bool finite = true;
    for (double v : rhs_) finite = finite && std::isfinite(v);
    r.iterations = it;
    if (!finite) return r;  // not converged: a shorter step or stepping may still get there
    x.swap(rhs_);
  }
  return r;
}

std::string NewtonSolver::worst_port(const Circuit& circuit) const {
  if (worst_ < 0 || worst_ >= static_cast<int>(ports_.size())) return "a nonlinear element";
  const Port& p = ports_[worst_];
  return fmt::format("{} (between {} and {}, at {:.4g} V)", p.element->name(),
                     circuit.unknown_name(p.p), p.n == 0 ? "ground" : circuit.unknown_name(p.n),
                     p.v);
}

namespace {

// One DC problem: the matrix, the excitation and the solver, for the three strategies.
class DcNewton {
 public:
  DcNewton(const Circuit& circuit, const MnaSystem& sys,
           const std::vector<std::pair<int, double>>& held)
      : circuit_(circuit), n_(sys.n) {
    values_ = sys.dc_values(circuit, held, &fixed_);
    b_.assign(n_ + 1, 0.0);
    sys.dc_rhs(circuit, held, b_);
    scaled_ = b_;
    newton_.bind(circuit, sys.pattern);
    newton_.tolerances().max_iterations = 100;
  }
  Status analyze(const MnaSystem& sys) {
    return klu_.analyze(sys.pattern, KluSolver::Ordering::Colamd);
  }

  // Newton at conductance gshunt to ground and sources scaled by `scale`, from x (in place);
  // from the ports' start voltages when `start`.
  NewtonResult attempt(double gshunt, double scale, std::vector<double>& x, bool start) {
    for (int u = 0; u <= n_; ++u) scaled_[u] = b_[u] * scale;
    newton_.restart(start);
    NewtonInput in;
    in.linear_values = values_.data();
    in.rhs = &scaled_;
    in.gshunt = gshunt;
    in.fixed_rows = &fixed_;
    return newton_.solve(circuit_, klu_, in, x);
  }

  // gmin stepping: from 1e-2 S down by decades (by less after a failure), then without.
  bool gmin_stepping(std::vector<double>& x, Status* error) {
    std::vector<double> xg(n_ + 1, 0.0), xt;
    NewtonResult r = attempt(1e-2, 1.0, xg, true);
    if (!r.error.ok()) *error = r.error;
    if (!r.converged) return false;
    double gshunt = 1e-2, factor = 10.0;
    while (gshunt > 1e-13) {
      const double next = gshunt / factor < 1e-13 ? 0.0 : gshunt / factor;
      xt = xg;
      r = attempt(next, 1.0, xt, false);
      if (!r.error.ok()) *error = r.error;
      if (r.converged) {
        xg.swap(xt);
        gshunt = next;
        if (next == 0.0) break;
        factor = std::min(10.0, factor * factor);
      } else {
        factor = std::sqrt(factor);
        if (factor < 1.00005) return false;
      }
    }
    if (gshunt != 0.0) {
      r = attempt(0.0, 1.0, xg, false);
      if (!r.converged) return false;
    }
    x.swap(xg);
    return true;
  }

  // Source stepping: every source from 0 to its value, the step doubled after a success and
  // quartered after a failure.
  bool source_stepping(std::vector<double>& x, Status* error) {
    std::vector<double> xs(n_ + 1, 0.0), xt;
    NewtonResult r = attempt(0.0, 0.0, xs, true);
    if (!r.converged) return false;
    double scale = 0.0, step = 0.05;
    while (scale < 1.0) {
      const double next = std::min(1.0, scale + step);
      xt = xs;
      r = attempt(0.0, next, xt, false);
      if (!r.error.ok()) *error = r.error;
      if (r.converged) {
        xs.swap(xt);
        scale = next;
        step = std::min(0.25, step * 2);
      } else {
        step /= 4;
        if (step < 1e-7) return false;
      }
    }
    x.swap(xs);
    return true;
  }

  std::string worst_port() const { return newton_.worst_port(circuit_); }

 private:
  const Circuit& circuit_;
  int n_;
  std::vector<double> values_, b_, scaled_;
  std::vector<bool> fixed_;
  NewtonSolver newton_;
  KluSolver klu_;
};

}  // namespace

Status nonlinear_dc(const Circuit& circuit, const MnaSystem& sys, std::vector<double>& x,
                    const std::vector<std::pair<int, double>>& held) {
  DcNewton dc(circuit, sys, held);
  if (Status s = dc.analyze(sys); !s.ok()) return s;
  std::vector<double> xn(sys.n + 1, 0.0);
  NewtonResult r = dc.attempt(0.0, 1.0, xn, true);
  Status error = r.error;
  bool ok = r.converged;
  if (!ok) ok = dc.gmin_stepping(xn, &error);
  if (!ok) ok = dc.source_stepping(xn, &error);
  if (!ok) {
    if (!error.ok()) return error;
    return Status::Error(fmt::format(
        "did not converge (Newton's iteration, then gmin stepping, then source stepping): the "
        "current of {} did not settle; check the diode's model (is, n, rs) and that the circuit "
        "has a DC path around it, or give the nodes a starting voltage with .ic",
        dc.worst_port()));
  }
  std::copy(xn.begin(), xn.end(), x.begin());
  return MnaSystem::check_finite(circuit, x, 0.0, "the DC operating point");
}

}  // namespace isolink
