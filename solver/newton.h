// Newton-Raphson on a circuit's nonlinear ports (Element::nonlinear_port_count, element.h step
// 5): the one iteration the DC operating point and the transient share. Internal to solver/.
//
//   NewtonSolver newton;
//   newton.bind(circuit, pattern);               // the ports' unknowns and matrix slots
//   newton.restart(true);                        // DC: the first iterate at the start voltages
//   NewtonResult r = newton.solve(circuit, klu, input, x);   // x: the guess in, the solution out
//   if (!r.error.ok()) ...                       // singular or non-finite: a hard error
//   if (!r.converged) ...                        // the caller steps gmin or the sources (DC), or
//                                                // retries a shorter time step (transient)
// The system solved is  A_lin x + sum_ports [i(v) + a0 q(v) + hq] = rhs, where A_lin (G, or
// G + a0 C in a time step) and rhs (the excitation less the linear history) come from the caller
// and each port adds its current i, and its charge's current through the integration formula
// q' = a0 q + hq (a0 = 0 at DC). Each iteration evaluates every port at the voltage the last
// solve gave, limited as SPICE does (pnjlim), stamps the linearisation (the companion model:
// conductance g + a0 c, equivalent current i + a0 q + hq - (g + a0 c) v) and solves; KLU refactors
// each iteration (KluSolver::factor_once, outside the step-size cache).
//
// Converged (both must hold, and no port was limited in the last evaluation):
//   - the update: |x_new - x_old| <= reltol max(|x_new|, |x_old|) + vntol on node voltages,
//     + abstol on branch currents;
//   - the residual: each port's current at the new voltage, i(v) + a0 q(v), within reltol
//     max(|.|, |.|) + abstol of the linearisation's prediction, which the linear equations
//     satisfy exactly: the nonlinear equations' residual is that difference, port by port.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "solver/circuit.h"
#include "solver/klu_solver.h"
#include "solver/mna.h"

namespace isolink {

struct MnaSystem;

struct NewtonTolerances {
  double reltol = 1e-6;   // relative, on the update and the port currents
  double vntol = 1e-7;    // V, on node voltages
  double abstol = 1e-12;  // A, on branch and port currents
  int max_iterations = 40;
};

struct NewtonInput {
  const double* linear_values = nullptr;          // pattern.nonzeros() values of A_lin
  const std::vector<double>* rhs = nullptr;       // n + 1 entries, [0] ignored
  double a0 = 0.0;                                // 1/s, the charges' integration coefficient
  const double* charge_history = nullptr;         // one hq per port (nullptr: all 0, DC)
  double gshunt = 0.0;                            // S on every node's diagonal (gmin stepping)
  const std::vector<bool>* fixed_rows = nullptr;  // rows x = rhs (held .ic nodes): no port stamps
};

struct NewtonResult {
  bool converged = false;
  int iterations = 0;
  Status error;  // a singular or non-finite system: not helped by a shorter step or stepping
};

class NewtonSolver {
 public:
  void bind(const Circuit& circuit, const MnaPattern& pattern);
  int port_count() const { return static_cast<int>(ports_.size()); }
  // The next solve's first evaluation: at each port's start voltage (true: the DC point's first
  // solve, SPICE's vcrit / off) or at the voltage its first iterate gives (false).
  void restart(bool at_start_voltages);
  // Iterates from x (unknowns, [0] ground) to the solution, in place.
  NewtonResult solve(const Circuit& circuit, KluSolver& klu, const NewtonInput& in,
                     std::vector<double>& x);
  // The charge of port k at the solution (after a converged solve).
  double charge(int k) const { return ports_[k].eval.q; }
  // Which port and node last failed the residual test, for an error message.
  std::string worst_port(const Circuit& circuit) const;
  NewtonTolerances& tolerances() { return tol_; }

 private:
  struct Port {
    const Element* element = nullptr;
    int index = 0;  // the element's port number
    int p = 0, n = 0;
    bool controlled = false;
    int cp = 0, cn = 0;  // a controlled port's control nodes
    Slot pp = 0, nn = 0, pn = 0, np = 0;
    double v = 0;   // the voltage of the last evaluation (limited)
    PortEval eval;  // at v
    bool evaluated = false;
  };
  // Evaluates each port at x and stamps it into values_ and rhs_; true when each port's current
  // agreed with the previous linearisation and none was limited.
  bool load(const std::vector<double>& x, const NewtonInput& in);
  bool update_small(const Circuit& circuit, const std::vector<double>& x_old,
                    const std::vector<double>& x_new, const NewtonTolerances& tol) const;

  std::vector<Port> ports_;
  std::vector<Slot> node_diagonals_;
  std::vector<double> values_, rhs_, previous_;
  NewtonTolerances tol_;
  bool at_start_ = false;
  int worst_ = -1;
};

// The DC operating point of a circuit with nonlinear ports into x (n + 1 entries): Newton's
// iteration from the ports' start voltages; failing that, gmin stepping (a conductance from
// every node to ground, 1e-2 S down to 0 by decades, each solve starting from the last); failing
// that, source stepping (every source scaled from 0 to 1). `held` as MnaSystem::dc. The error,
// when all three fail, names the element and node whose current did not settle and what to try.
Status nonlinear_dc(const Circuit& circuit, const MnaSystem& sys, std::vector<double>& x,
                    const std::vector<std::pair<int, double>>& held);

}  // namespace isolink
