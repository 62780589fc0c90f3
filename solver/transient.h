// Transient analysis of a circuit: DC operating point, then trapezoidal or Gear-2 steps
// under local-truncation-error control, with breakpoints at every source corner.
//
//   TransientOptions opt{.tstep = 1e-9, .tstop = 20e-6};
//   if (Status s = opt.validate(); !s.ok()) ...          // before any work
//   TransientStats stats;
//   StatusOr<Waveform> w = run_transient(circuit, opt, probes, &stats);
// One Waveform row per accepted step with t >= tstart (time in s; v(...) in V, i(...) in A).
//
// Contract: the circuit must be finalized. run_transient takes it non-const because it binds
// the sources' time defaults to this run (Element::bind_time: ngspice's PULSE TR defaults to
// TSTEP); it keeps no reference to it afterwards. Errors: an invalid option (validate()), a
// node_ic unknown out of range, a DC point that is singular or not finite (naming the unknown), a
// singular or non-finite step, a step below the floor (naming the unknown whose truncation
// error does not converge), max_steps reached. `stats` is written on success only.
//
// Method, in short (details in the README "Solver" section):
//   C x' + G x = b(t). G and C are stamped once; each step solves (G + alpha C) x1 = rhs with a
//   KLU factorization cached by alpha, so a step size that comes back costs one solve.
//   Backward Euler takes the first step after every breakpoint; then trapezoidal
//   (x1' = 2 (x1 - x0) / h - x0') or variable-step BDF2. The error estimate is the trapezoidal /
//   BDF2 truncation term from the third divided difference of node voltages and inductor
//   currents, against trtol * (reltol * peak |x| + vntol|abstol), peak = the unknown's largest
//   |x| so far; steps come from a ladder tmax / 2^k so factorizations are reused.
//   Nonlinear elements (diodes): each step is Newton's iteration (solver/newton.h) on the same
//   formula, the elements' charges integrated as states of their own (charge-conserving) and
//   watched by the error control against chgtol; a step whose Newton does not converge is retried
//   at 1/8 of its size. The DC operating point is Newton's too, then gmin stepping, then source
//   stepping (newton.h: nonlinear_dc).
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "base/waveform.h"
#include "solver/card.h"
#include "solver/circuit.h"
#include "solver/newton.h"
#include "solver/probe.h"

namespace isolink {

enum class IntegrationMethod { Trapezoidal, Gear2 };

struct TransientOptions {
  double tstep = 0.0;   // s, output/step hint (> 0)
  double tstop = 0.0;   // s, end time (> tstart)
  double tstart = 0.0;  // s, first time written out
  double tmax = 0.0;    // s, largest step; 0 = min(tstep, (tstop - tstart) / 50) as ngspice
  IntegrationMethod method = IntegrationMethod::Trapezoidal;
  double reltol = 1e-3;   // relative tolerance of the truncation error
  double vntol = 1e-6;    // V, absolute tolerance on node voltages
  double abstol = 1e-12;  // A, absolute tolerance on inductor currents
  double chgtol = 1e-14;  // C, absolute tolerance on the nonlinear elements' charges
  // Newton's iteration on the nonlinear elements (diodes): its own tolerances, tighter than the
  // truncation error's (the iteration converges quadratically, so the last one is cheap).
  NewtonTolerances newton;
  // Multiplies the truncation tolerance. The tolerance is relative to each unknown's peak |x| so
  // far (not to its value now, as ngspice), hence a default well below ngspice's 7; see the
  // README "Solver" section and bench/README.md for the accuracy and speed at this default.
  double trtol = 0.1;
  // Skip the DC operating point: start from node_ic (other nodes 0 V), the inductors' ic=
  // (else 0 A) and the capacitors' ic= (else the voltage the nodes give), as ngspice's UIC.
  bool uic = false;
  // .ic: (node unknown, volts). Without uic each node is held at its value while the DC
  // operating point is solved, then released; with uic it is the node's voltage at t = 0.
  std::vector<std::pair<int, double>> node_ic;
  long max_steps = 20'000'000;  // accepted + rejected steps before giving up
  // Called with the time reached, every 1024 accepted steps (a progress display; empty: none).
  std::function<void(double t)> on_progress;

  double effective_tmax() const;
  // Errors name the field, its value and the rule it breaks.
  Status validate() const;
  // Applies one ".options key=value"; *known = false for options isolink does not use.
  Status set_option(const std::string& key, const CardArg& value, bool* known);
};

struct TransientStats {
  long accepted = 0;
  long rejected = 0;
  int factorizations = 0;
  int reuses = 0;
  long solves = 0;
  int breakpoints = 0;
  long newton_iterations = 0;  // with nonlinear elements: iterations over all steps
  long newton_failures = 0;    // steps retried shorter because Newton did not converge
};

// DC operating point: the full unknown vector (index 0 = ground; V and A). Reads the circuit
// only. Errors name the node (singular matrix, non-finite value).
StatusOr<std::vector<double>> dc_operating_point(const Circuit& circuit);

StatusOr<Waveform> run_transient(Circuit& circuit, const TransientOptions& options,
                                 const std::vector<Probe>& probes, TransientStats* stats = nullptr);

}  // namespace isolink
