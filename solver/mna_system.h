// MnaSystem: a finalized circuit's G and C over its MNA pattern, with a KLU solver; shared by the
// transient and LTI engines (solver/transient.cpp, solver/lti.cpp). Internal to solver/.
//
//   MnaSystem sys;
//   if (Status s = sys.build(circuit); !s.ok()) return s;   // stamps G, C; KLU symbolic analysis
//   sys.dc(circuit, x);                                       // DC operating point
//   sys.select_or_factor(circuit, alpha); sys.solve(b);      // (G + alpha C) x = b
// Ownership: the system owns its pattern, G and C (assemble_mna) and the KLU factorizations. It
// keeps pointers to the circuit's source elements (rhs): the circuit must outlive it; the
// methods that report errors take the circuit again, for its unknown names. alpha is in 1/s
// (the integration coefficient of C); right-hand sides and solutions index unknowns, [0] ground.
// Errors: build (KLU's analysis), select_or_factor and factor_dc (a singular matrix, naming the
// unknown), dc and check_finite (a non-finite solution, naming the unknown and the likely cause).
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "solver/circuit.h"
#include "solver/klu_solver.h"
#include "solver/mna.h"
#include "solver/newton.h"

namespace isolink {

// The assembled linear system of a circuit.
struct MnaSystem {
  MnaPattern pattern{0};
  std::vector<double> g, c;  // value arrays (+ trash)
  KluSolver klu;
  int n = 0;  // unknowns without ground
  // The elements with an excitation (sources): the only ones stamp_rhs is called on.
  std::vector<const Element*> sources;
  // C without its zero entries, by rows, for C * v on every step: row r (unknown r + 1) has
  // entries c_start[r] .. c_start[r + 1], columns as unknowns (1..n).
  std::vector<int> c_start, c_col;
  std::vector<double> c_val;
  std::vector<double> a;  // G + alpha C, factorization input

  Status build(const Circuit& circuit) {
    n = circuit.unknown_count();
    MnaMatrices m = assemble_mna(circuit);
    pattern = std::move(m.pattern);
    g = std::move(m.g);
    c = std::move(m.c);
    for (const auto& e : circuit.elements())
      if (e->has_excitation()) sources.push_back(e.get());
    const auto& cp = pattern.col_start();
    const auto& ri = pattern.row_index();
    c_start.assign(n + 1, 0);
    for (int col = 0; col < n; ++col)
      for (int k = cp[col]; k < cp[col + 1]; ++k)
        if (c[k] != 0.0) ++c_start[ri[k] + 1];
    for (int r = 0; r < n; ++r) c_start[r + 1] += c_start[r];
    c_col.assign(c_start[n], 0);
    c_val.assign(c_start[n], 0.0);
    std::vector<int> next(c_start.begin(), c_start.end() - 1);
    for (int col = 0; col < n; ++col)
      for (int k = cp[col]; k < cp[col + 1]; ++k)
        if (c[k] != 0.0) c_col[next[ri[k]]] = col + 1, c_val[next[ri[k]]++] = c[k];
    a.resize(pattern.nonzeros());
    return klu.analyze(pattern);
  }

  // y -= C * v over unknowns 1..n (index 0 ignored).
  void sub_c_times(const double* __restrict v, double* __restrict y) const {
    const int* __restrict cs = c_start.data();
    const int* __restrict cc = c_col.data();
    const double* __restrict cv = c_val.data();
    for (int r = 0; r < n; ++r) {
      double s = 0.0;
      for (int k = cs[r]; k < cs[r + 1]; ++k) s += cv[k] * v[cc[k]];
      y[r + 1] -= s;
    }
  }

  // b = excitation at time t (index 0 = ground, zero).
  void rhs(double t, std::vector<double>& b) const {
    std::fill(b.begin(), b.end(), 0.0);
    for (const Element* e : sources) e->stamp_rhs(t, b.data());
    b[0] = 0.0;
  }

  Status select_or_factor(const Circuit& circuit, double alpha) {
    if (klu.select(alpha)) return Status::Ok();
    for (int k = 0; k < pattern.nonzeros(); ++k) a[k] = g[k] + alpha * c[k];
    return name_singular(circuit, klu, klu.factor(alpha, a.data()));
  }

  // Solves in place: b holds the right-hand side (index 0 ignored), then x.
  Status solve(std::vector<double>& b) {
    Status s = klu.solve(b.data() + 1);
    b[0] = 0.0;
    return s;
  }

  // Factors G (the DC matrix) into dc_klu. It has its own KluSolver, ordered by COLAMD: at DC the
  // inductor branches have no diagonal and KLU pivots away from a symmetric fill-reducing order
  // (klu_solver.h), so this matrix says nothing about which ordering suits the transient
  // matrices; the transient KluSolver decides on its first (transient) factorization instead. The
  // rows of `held` unknowns and of the inductors the circuit opened at DC
  // (Circuit::dc_open_branches) are replaced by unknown = value; dc() puts the values in the
  // right-hand side.
  Status factor_dc(const Circuit& circuit, KluSolver& dc_klu,
                   const std::vector<std::pair<int, double>>& held = {}) const {
    const std::vector<double> values = dc_values(circuit, held, nullptr);
    if (Status s = dc_klu.analyze(pattern, KluSolver::Ordering::Colamd); !s.ok()) return s;
    return name_singular(circuit, dc_klu, dc_klu.factor(0.0, values.data()));
  }

  // The DC matrix's values: G with the rows of `held` unknowns and of the opened inductors
  // replaced by unknown = value; *replaced (n + 1 flags, when given) marks those rows.
  std::vector<double> dc_values(const Circuit& circuit,
                                const std::vector<std::pair<int, double>>& held,
                                std::vector<bool>* replaced_rows) const {
    std::vector<double> gd = g;
    std::vector<bool> replaced(n + 1, false);
    for (const auto& r : held) replaced[r.first] = true;
    for (int br : circuit.dc_open_branches()) replaced[br] = true;
    const auto& cp = pattern.col_start();
    const auto& ri = pattern.row_index();
    for (int col = 0; col < n; ++col)
      for (int k = cp[col]; k < cp[col + 1]; ++k)
        if (replaced[ri[k] + 1]) gd[k] = ri[k] == col ? 1.0 : 0.0;
    if (replaced_rows) *replaced_rows = std::move(replaced);
    return gd;
  }

  // The DC right-hand side: the excitation at t = 0, `held` unknowns at their values, the opened
  // inductors at 0 A.
  void dc_rhs(const Circuit& circuit, const std::vector<std::pair<int, double>>& held,
              std::vector<double>& x) const {
    rhs(0.0, x);
    for (const auto& [u, v] : held) x[u] = v;
    for (int br : circuit.dc_open_branches()) x[br] = 0.0;
  }

  // The DC operating point into x (n + 1 entries), `held` unknowns at their values, the opened
  // inductors at 0 A; a non-finite solution is an error naming the unknown. With nonlinear
  // elements: Newton's iteration, then gmin stepping, then source stepping (newton.h).
  Status dc(const Circuit& circuit, std::vector<double>& x,
            const std::vector<std::pair<int, double>>& held = {}) const {
    if (has_nonlinear_ports(circuit)) return nonlinear_dc(circuit, *this, x, held);
    KluSolver dc_klu;
    if (Status s = factor_dc(circuit, dc_klu, held); !s.ok()) return s;
    dc_rhs(circuit, held, x);
    Status s = dc_klu.solve(x.data() + 1);
    x[0] = 0.0;
    if (s.ok()) s = check_finite(circuit, x, 0.0, "the DC operating point");
    return s;
  }

  static bool has_nonlinear_ports(const Circuit& circuit) {
    for (const auto& e : circuit.elements())
      if (e->nonlinear_port_count() > 0) return true;
    return false;
  }

  // Exit-worthy error when x has a NaN or infinity, naming the unknown and the likely cause.
  static Status check_finite(const Circuit& circuit, const std::vector<double>& x, double t,
                             const char* where) {
    const std::size_t unknowns = static_cast<std::size_t>(circuit.unknown_count());
    for (std::size_t u = 1; u < x.size() && u <= unknowns; ++u) {
      if (std::isfinite(x[u])) continue;
      const int ui = static_cast<int>(u);
      const char* cause =
          circuit.unknown_is_state(ui) && !circuit.unknown_is_node(ui)
              ? "an inductor whose coupling (K) or value makes the circuit unstable, or element "
                "values many decades apart"
              : "element values many decades apart (a near-singular matrix), or a source "
                "value that is not finite";
      return Status::Error(fmt::format(
          "non-finite value ({}) in the solution at t={:g} s ({}): {}; likely cause: {}", x[u], t,
          where, circuit.unknown_name(ui), cause));
    }
    return Status::Ok();
  }

  static Status name_singular(const Circuit& circuit, const KluSolver& k, Status s) {
    if (!s.ok() && k.singular_column() >= 0)
      return Status::Error(fmt::format("singular matrix: {} is not determined by the circuit",
                                       circuit.unknown_name(k.singular_column() + 1)));
    return s;
  }
};

}  // namespace isolink
