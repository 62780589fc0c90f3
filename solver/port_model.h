// Port model: a circuit with nonlinear elements (diodes) simulated as its linear network, reduced
// to a model seen from the nonlinear elements' ports, with Newton's iteration on the port
// unknowns alone. The fast engine for nonlinear circuits; the full-circuit Newton transient
// (solver/transient.h) is its checked fallback.
//
//   StatusOr<PortModel> m = build_port_model(cards, circuit, probes, tstop, {});
//   if (!m) ... fall back (m.status() says why)
//   PortModelStats stats;
//   StatusOr<Waveform> w = run_port_model(circuit, *m, transient_options, &stats);
//
// Contract:
// - Input: the circuit's cards (the netlist's, in order) and the finalized circuit built from
//   them; probes parsed on that circuit. Units SI. One Waveform row per accepted step with
//   t >= tstart, as the transient engine writes them.
// - Ownership: the model owns its numbers and keeps no reference to the cards or the circuit;
//   run_port_model reads the circuit's nonlinear elements (eval_port) and sources (values), so
//   the circuit must be the one the model was built from. run_port_model takes the circuit
//   non-const to bind the sources' time defaults, as run_transient does.
// - Errors (a Status, never thrown; each is a reason to fall back to the full transient): no
//   nonlinear port; .ic / uic; an inductor opened at DC; the reduced model fails its check
//   against the exact AC solution; the model's DC state differs from the circuit's operating
//   point; Newton on the ports does not converge above the step floor; max_steps.
//
// Method (docs/nonlinear.md, "The port model"):
// 1. The linear network: every element but the nonlinear ports, each port shunted by a constant
//    conductance g_s (PortModelOptions::port_shunt, switch_port_shunt for a switch's port) that
//    the port's own current gives back:
//    the port current is d(v) = i(v) - g_s v + dq(v)/dt, so the circuit is unchanged. The shunt
//    bounds each port's self-impedance by 1 / g_s (a node that only diodes reach, such as the
//    junction of a diode and a zener in series, is otherwise floating), which keeps the model's
//    relative check meaningful at the ports.
// 2. The model (solver/reduced_model.h, Krylov projection checked against the exact AC solution
//    of the linear network at the check frequencies, refined between them): inputs = every
//    time-varying source (its unit excitation) and every port (a unit current drawn from p into n);
//    outputs = every port voltage and every probe but a series ammeter's current (read from its
//    diode's port current, PortModel::PortCurrentProbe). The constant sources (supplies, biases, 0
//    V ammeters) are no inputs: their share of each output is the network's DC solution for them,
//    an offset. Modes x_i' = p_i x_i + sum_k in_ki w_k, outputs y = Re sum_i out_i x_i + D w. The
//    check is the reduced model's, at tol (PortModelOptions::reduced), for every input-output pair:
//    the port impedance matrix, the source-to-port transfers and the probes' transfers.
// 3. Time steps: over a step the sources are linear in t (exact for PULSE and PWL between their
//    corners, which are breakpoints; SIN and EXP within the error control) and the port currents
//    d are linear in t from the last point to the unknown end value (trapezoidal), or constant at
//    the end value on the first step after a breakpoint (backward Euler). Each mode is integrated
//    exactly for such inputs: x1 = e^(ph) x0 + a(h) in.w0 + b(h) in.w1. The end port voltages
//    are then v1 = v_oc + Z_h d1 with Z_h the model's step impedance (np x np, cached per step
//    size), and Newton's iteration (SPICE's pnjlim limiting, the transient's tolerances on an
//    iterate's residual and on the update from it) solves v1 = v_oc + Z_h d(v1) on the np port
//    voltages alone, a dense np x np system. The junction
//    and diffusion charges q(v) are integrated as the transient integrates them, by the same
//    formula as the current's shape (trapezoidal: dq/dt at the end = 2 (q1 - q0) / h - dq/dt at
//    the start; Euler: (q1 - q0) / h): the integral of the charge current over a step is q1 - q0
//    exactly, so charge is conserved.
// 4. Step control: the one StepControl (solver/step_control.h), step sizes on its ladder so the
//    coefficients and Z_h are reused; the larger of two estimates decides: the transient's
//    truncation term (third divided difference) on the port voltages, against trtol (reltol x the
//    largest port voltage's peak + vntol), and on the ports' charges, against trtol (reltol x the
//    charge's peak + chgtol), the Euler start step checked one step late; and the port currents'
//    departure from a straight line over the step (h^2 d'' / 8 through the step's port impedances)
//    against the port voltages' tolerance. The probes are not watched: exact given the port
//    currents, their rows are step 5's. The largest step is TMAX, else (tstop - tstart) / 50 where
//    every source is piecewise linear and no switch is controlled, else TSTEP's bound. Newton's
//    failure retries at 1/8 of the step.
// 5. Rows: one at each step's end, and inside a step (the modes in 2^j equal parts with the
//    step's input; up to 8 parts, which nearly every step needs, each row in one pass over the
//    step's end states with the coefficients of its own fraction of the step, more parts
//    marched) at most TSTEP apart and as many more as
//    keep the probes' linear interpolation between rows within the same tolerance (measured on the
//    rows: the deviation at twice their spacing, quartered). A port current probe is interpolated
//    linearly inside a step; a switch's step has no rows inside.
//
// Guarantee: the linear network's response is exact to the model's check (its transfer within
// tol of each input-output pair's peak at every check frequency; for an input edge, the
// reduced model's time-domain bound tol ln(f_max / f_min) / pi of the edge's amplitude times the
// pair's peak gain), and the time discretisation is the port currents' alone, under the
// transient's truncation control at the same tolerances and step 4's bend estimate. Tested against
// the full transient at reltol 1e-6 (tests/solver/port_model_test.cpp,
// tests/cli/nonlinear_compare_test.cpp).
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
#include "solver/card.h"
#include "solver/circuit.h"
#include "solver/probe.h"
#include "solver/reduced_model.h"
#include "solver/transient.h"

namespace isolink {

struct PortModelOptions {
  // The reltol the engine's caller runs it at when the user gave none (analysis/simulate.cpp),
  // the transient's 1e-3; the run is then checked at a tenth of it (transient_check.h, both at
  // once) and the tighter kept when the two agree within 3 mV. On the corpus's nonlinear links
  // the kept run was 0.10-1.06 mV from a converged reference (bench/README.md).
  double default_reltol = 1e-3;
  // S, the conductance across every diode's port in the linear network (given back by the
  // port's current): bounds each port's self-impedance by 1 / port_shunt. Its give-back, -g_s v,
  // is part of the port current the march takes as a straight line over a step: its error grows
  // with g_s (the corpus's 3.4 m TVS link at reltol 1e-4: 0.98, 0.13 and 0.02 mV at 1e-2, 1e-3
  // and 1e-4 S). Too small a shunt loosens the model instead: its check is relative to each
  // pair's peak, which the shunt bounds, and at 1e-4 S one of the 40 corpus links with TVS and
  // clamps failed it (1.1e-4 at 1 kHz, the search stalled) where 1e-3 S passes all 40.
  double port_shunt = 1e-3;
  // S, the same for a switch's port: closed, it carries amperes of inrush through 0.02 ohm, and
  // the model's absolute error at its port, tol / g_s, is then a voltage: 1e-4 S put a 30 V
  // hot plug's peak 14 mV off (tests/solver/port_model_test.cpp), 1e-2 S within 3 mV.
  double switch_port_shunt = 1e-2;
  // The model's check. No edge weighting: the ports' currents can switch faster than any source.
  // 48 check points, refined between them as the reduced model's check is: 128 took 0.15 s of
  // a 12 m link's 0.21 s, the model at full order either way. Up to 150 unknowns the model
  // starts from the full basis (the clamp hops of bench/nonlinear_vs_ngspice.sh, up to 132).
  // Above, the Krylov search comes first: links built from specs reduce to 40-60 % of their
  // unknowns (the corpus's 0.4-5 m TVS links of 176-485 unknowns: orders 99-201 against full,
  // each run 8-40 % faster; a 5 m one 1.35 -> 0.81 s, 234 -> 124 modes), and on a 15 m link's
  // stress circuits (1,100 unknowns) the search passed in 0.4-3.6 s where the full basis took
  // 3.4-16 s, the peaks within 0.4 mV. A lossless ladder of equal sections does not reduce: the
  // 50 m clamp hop (436 unknowns) reaches full order through 23 expansion points in 2.5 s where
  // the full basis takes 0.8 s (500 was the bound before: bench/README.md).
  // Five expansion points a search step, not three: on the corpus's 44-100 m TVS links (order
  // 850-970) each step's model costs O(q^3), and fewer steps took their models 7-16 % faster
  // (019: 5.4 -> 4.4 s), the waveforms within 0.015 mV; 11-32 m links the same within 4 %.
  // Ten in the step after a refinement that failed (ReducedModelOptions::refine_batch).
  // Four moments a point were faster on two of ten long links and slower on eight; with two,
  // link 019's run went past 9 minutes (bench/README.md, "Dense linear algebra").
  ReducedModelOptions reduced = [] {
    ReducedModelOptions r;
    r.tol = 2e-6;
    r.check_points = 48;
    r.full_order_at_most = 150;
    r.difference_scale = true;
    r.stall_tol = 1e-4;
    r.batch = 5;
    r.refine_batch = 10;
    return r;
  }();
  // When the first model fails its check, the other is tried on a network of at most this many
  // unknowns: the full basis after the Krylov search, or the search after the full basis.
  int full_basis_at_most = 1200;
};

// The model and what run_port_model needs to step it.
struct PortModel {
  ReducedModel model;  // inputs: sources, then ports; outputs: probes, then port voltages
  int sources = 0;     // model inputs 0 .. sources - 1
  int ports = 0;       // model inputs sources .. sources + ports - 1; outputs probes ..
  int probes = 0;      // the probes read through the model: its outputs 0 .. probes - 1
  std::vector<std::string> labels;  // every probe's label, in the caller's order (the columns)
  std::vector<int> probe_column;    // per model probe output: its column
  // A probe read from a port instead of the model: the current of a voltage source in series
  // with a diode (a 0 V ammeter: one of its nodes is touched by the two alone) is, by Kirchhoff's
  // current law, sign x the diode's current. Through the model such a probe's transfer from any
  // other source is 0 but for rounding, and its check stalled (a 15 m link's ground step: the
  // full basis 2.5e4 and the Krylov search 1.4e4 off at one ammeter).
  struct PortCurrentProbe {
    int column = 0;
    int port = 0;
    double sign = 1.0;
  };
  std::vector<PortCurrentProbe> port_current_probes;
  std::vector<std::string> source_names;  // the circuit's time-varying sources, in input order
  // The constant sources (DC, or PWL without a corner before the horizon) and their values: no
  // inputs, their share of each output is `offset`.
  std::vector<std::pair<std::string, double>> constant_sources;
  std::vector<double> offset;  // per output (probes, then port voltages): the constant share
  std::vector<std::string> port_elements;  // per port: its element's name
  std::vector<int> port_index;             // per port: the element's port number
  // Per port: its control's number (a switch's), -1 for an uncontrolled port.
  std::vector<int> port_control;
  int controls = 0;
  // Per control: the voltage source across the switch's control nodes and the sign of
  // v(nc+, nc-) in its value. Not a model input (it reaches no other node).
  std::vector<std::pair<std::string, double>> control_sources;
  std::vector<double> port_shunt;  // S, per port: its shunt in the linear network
  double seconds = 0.0;            // building the model (DC solves, the reduction and its check)
};

struct PortModelStats {
  long accepted = 0, rejected = 0;
  long newton_iterations = 0, newton_failures = 0;
  int step_sizes = 0;          // distinct step sizes (coefficient sets computed)
  double dc_mismatch = 0.0;    // V: the model's port voltages at t = 0 against the DC point
  double model_seconds = 0.0;  // building the model
  ReducedModelStats model;     // the check it passed
  int ports = 0, modes = 0;
};

// The model of the circuit's linear network seen from its nonlinear ports and probes (method
// steps 1-2). `cards` are the ones `circuit` was built from, in the same order.
StatusOr<PortModel> build_port_model(const std::vector<Card>& cards, const Circuit& circuit,
                                     const std::vector<Probe>& probes, double horizon,
                                     const PortModelOptions& options);

// The transient of the circuit on the port model (method steps 3-4): DC operating point of the
// full circuit, then exact modal steps with Newton on the ports. `opt` as for run_transient
// (uic and node_ic are refused: errors).
StatusOr<Waveform> run_port_model(Circuit& circuit, const PortModel& model,
                                  const TransientOptions& opt, PortModelStats* stats = nullptr);

// The same on a circuit whose sources are already bound to opt's tstep and tstop
// (Element::bind_time, as run_port_model does first): it only reads the circuit and the model,
// so several runs (other options) may go at once on one circuit and model.
StatusOr<Waveform> run_port_model_bound(const Circuit& circuit, const PortModel& model,
                                        const TransientOptions& opt,
                                        PortModelStats* stats = nullptr);

}  // namespace isolink
