// LTI engine: the response of a linear, time-invariant circuit to piecewise-linear sources, built
// by superposing each source's ramp response at the exact corner times of its waveform.
//
//   LtiOptions opt{.horizon = 60e-6};                 // the longest delay anything is needed for
//   if (Status s = check_lti(circuit); !s.ok()) ...    // names the element that is not LTI
//   StatusOr<LtiResponses> r = LtiResponses::compute(circuit, probes, opt);
//   std::vector<SourceInput> in = r->netlist_inputs(tstop);  // or any other PWL per source
//   double v = r->value(0, 12.5e-6, in);                     // probe 0 at any time
//   Waveform w = r->waveform(in, {.tstop = 60e-6});          // uniform grid, 1 mV rule
//
// Method. The circuit is C x' + G x = sum_k e_k u_k(t), e_k the unit excitation of time-varying
// source k (Element::stamp_unit). A piecewise-linear u_k is u_k(0) plus a sum of ramps (a slope
// change s_j at each corner t_j: SourceFunction::ramps), so every probe is exactly
//   y(t) = y_dc + sum_k (u_k(0) - u_k,netlist(0)) g_k + sum_k sum_j s_kj R_k(t - t_kj)
// with y_dc the DC operating point of the netlist's own sources at t = 0, g_k the DC gain of
// source k and R_k the response to a unit ramp u_k(t) = max(t, 0) from rest (R_k = 0 for t <= 0).
// No time is snapped to a grid: corners enter at their own times.
//
// R_k is computed once per circuit by one march of all sources together on one KLU symbolic
// analysis: backward Euler for the first step, trapezoidal after, step sizes from a ladder
// hmax / 2^k so every factorization is reused (the circuit is LTI: G and C never change). The
// march's derivative S_k = R_k' (the step response) comes with it; R_k between march points is
// the cubic Hermite interpolant of (R, S), so the output's slope is as accurate as S.
//
// Error control. What the output sees of R's error is its slope: an edge of amplitude A and rise
// tr adds A (R(t) - R(t - tr)) / tr, so an error e(t) in R costs A e'(t). Each step is therefore
// accepted when its truncation error per unit time is small against the step response:
//   |h^3/12 R'''| / h <= step_reltol * peak|S_u| + step_abstol   for every state u
// (node voltages with capacitance, inductor currents; peak over the march so far), R''' from the
// third divided difference of the last four points, as the transient engine does.
//
// Settling. The march runs to `horizon` (the longest lag a caller will ask for; run with the
// simulated span), or stops early once the response has settled: every probe's step response
// has arrived (|S| has exceeded 100 settle_tol: a cable delays it; a probe that no source
// reaches keeps the march going to the horizon), over the trailing half of the march
// [tau/2, tau] it stays within settle_tol of its value at tau,
// |S'(tau)| * (horizon - tau) <= settle_tol, and S(tau) is within settle_tol of the DC gain from a
// DC solve (S taken as chord slopes of R: the trapezoidal derivative alternates by a small +-delta
// that never damps). Beyond the end, R is extended as a straight line with its last chord slope.
// Circuits with nodes tied to ground through 1e-12 S (between isolation caps) settle to DC only
// over hours, so for them the march simply runs to the horizon with large steps on the slow tail.
#pragma once

#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
#include "solver/circuit.h"
#include "solver/elements/source_function.h"
#include "solver/probe.h"
#include "solver/reduced_model.h"

namespace isolink {

struct MnaSystem;

struct LtiOptions {
  // How the responses are computed: `march` (above), `reduced` (a reduced model in closed form,
  // solver/reduced_model.h: no march, no settling, any lag at the same cost), or `auto`: the
  // reduced model when it passes its check, else the march (LtiStats::note says why).
  enum class Method { Auto, March, Reduced };
  Method method = Method::Auto;
  ReducedModelOptions reduced;  // its horizon is set from `horizon`
  double horizon = 0.0;         // s, longest lag needed (> 0); the simulated span
  // s, the fastest edge the inputs will have: the reduced model's check weights its error by that
  // edge's spectrum (ReducedModelOptions::edge_time). 0: the shortest linear piece of the
  // circuit's own sources up to the horizon (none when no source moves). Set it when other
  // inputs, with faster edges, will be applied (SourceInput).
  double edge_time = 0.0;
  // Sources whose netlist waveforms move as an earlier source's does, scaled (the same corners,
  // every slope change b times its: a differential driver's two lines, n = vdd - p, b = -1),
  // share one input of the reduced model, driven by the excitation e_leader + b e_tied: half the
  // Krylov vectors and about half the model order for such a pair. The leader's responses then
  // carry the tied source's too (the tied source's ramp_response and step_response are 0), so
  // every input given later must keep the relation (netlist_inputs does): one that breaks it
  // makes value(), values() and waveform() NaN and modal_tail() empty. The march ignores this.
  bool tie_sources = false;
  double step_reltol = 1e-5;   // truncation error per unit time, relative to peak |S|
  double step_abstol = 1e-7;   // same, absolute (V/V for nodes, A/V for branch currents)
  double settle_tol = 1e-6;    // V/V (A/V): early stop, see above
  double first_step = 0.0;     // s; 0 = min(1e-12, horizon * 1e-9)
  double max_step = 0.0;       // s; 0 = horizon / 64
  long max_steps = 5'000'000;  // accepted + rejected march steps before giving up
  // s; 0 = no limit. The march gives up (an error) when the responses have not settled by then:
  // `auto` sets a quarter of the run, since a march over the whole run costs more than the
  // transient (one solve per source and step against one per step).
  double settle_by = 0.0;
  // Called with the lag reached, every 1024 accepted march steps (a progress display).
  std::function<void(double tau)> on_progress;

  // Errors name the field, its value and the rule it breaks.
  Status validate() const;
};

// One time-varying source's waveform as the engine takes it: its value before any corner and its
// slope changes (sorted by time; SourceFunction::ramps gives them for a netlist source).
struct SourceInput {
  double initial = 0.0;
  std::vector<Ramp> ramps;
};

// Corners of a PWL given as points (t_i, v_i), t strictly increasing, constant before t_0 and after
// the last point.
SourceInput pwl_input(const std::vector<double>& t, const std::vector<double>& v);

struct LtiStats {
  long steps = 0;  // accepted march steps
  long rejected = 0;
  int factorizations = 0;      // numeric (march + DC)
  double settled_at = 0.0;     // s, end of the march (the horizon unless it settled before)
  bool settled = false;        // stopped early by the settling criterion
  std::string method;          // "march" or "reduced model"
  std::string note;            // auto: why the reduced model was not used
  double model_seconds = 0.0;  // s, building and checking the reduced model (passed or not)
  double march_seconds = 0.0;  // s, the march (method "march")
  ReducedModelStats model;     // the reduced model's figures (method "reduced model")
};

// Why the circuit cannot take the LTI engine (an element that is not LTI, a source that is not
// piecewise linear), naming the element and its netlist location; Ok when it can.
Status check_lti(const Circuit& circuit);

// Lifetime: an LtiResponses owns its response tables (or reduced model) but points to the
// circuit's source functions (netlist_inputs reads them): the circuit must outlive it, unmoved
// (the elements are held by unique_ptr, so moving the Circuit object itself is fine). All const
// methods are thread-safe.
class LtiResponses {
 public:
  // The DC solves and the march. The circuit must be finalized (and bound to the analysis times:
  // Element::bind_time, as for the transient) and pass check_lti. Errors: invalid options,
  // check_lti's, a singular DC point, the reduced model's failure (Method::Reduced only), the
  // march's (max_steps, settle_by passed, a step below the floor naming the unknown).
  static StatusOr<LtiResponses> compute(const Circuit& circuit, const std::vector<Probe>& probes,
                                        const LtiOptions& options);

  size_t source_count() const { return sources_.size(); }
  const std::string& source_name(size_t k) const { return sources_[k].name; }
  // Index of a source by element name (lower case), -1 if it is not a time-varying source.
  int find_source(const std::string& name) const;
  size_t probe_count() const { return labels_.size(); }
  const std::vector<std::string>& probe_labels() const { return labels_; }

  // The netlist's own waveform of every source, corners up to tstop.
  std::vector<SourceInput> netlist_inputs(double tstop) const;

  // Probe p at time t for the given inputs (one per source, in source order).
  double value(size_t p, double t, const std::vector<SourceInput>& inputs) const;
  // The unit-ramp response of probe p to source k at lag tau (0 for tau <= 0), and its derivative
  // (the unit-step response).
  double ramp_response(size_t k, size_t p, double tau) const;
  double step_response(size_t k, size_t p, double tau) const;
  // DC gain of probe p from source k (DC solve, 1e-12 S ties included).
  double dc_gain(size_t k, size_t p) const { return gain_[k][p]; }

  struct GridOptions {
    double tstart = 0.0;
    double tstop = 0.0;  // > tstart
    double step = 0.0;   // s, the grid; 0 = chosen by the rule below
    // The rule for step = 0: the largest step (tstop - tstart) / 2^m, m >= the one giving 20 ns or
    // less (or span / 65536 on runs longer than 1.3 ms: the grid is sized from the run), at which
    // every grid probe's value at each cell's midpoint is within interp_tol / 2 of the linear
    // interpolation of its ends. For a quadratic piece the midpoint is where linear interpolation
    // errs most; for a single kink inside a cell the worst error is at most twice the midpoint's,
    // so linear interpolation between rows stays within interp_tol. Cells that hold a source corner
    // are left out of the test, and every corner inside the span is a row of its own (so the grid
    // is uniform plus the corners, and a probe on a driven node is exact). That is the march's
    // grid. The reduced model's refines locally instead: the first level as above (20 ns, or
    // span / 65536), then only the cells whose midpoint fails are halved, again and again, so
    // rows gather after the corners where a fast response bends and stay coarse elsewhere.
    double interp_tol = 1e-3;       // V for voltage probes (A/1000 for currents: 1 uA)
    std::vector<bool> grid_probes;  // which probes the rule looks at (empty = all)
    // The rule stops refining here (a warning says so). The reduced model's windows (below)
    // each stop at their share of it by length; with on_rows, each window at all of it.
    long max_rows = 4'000'000;
    // s: the reduced model refines the grid window by window, each window's rows by the rule
    // above on their own and the modes' state carried from the last window's end, so the work is
    // the rows' and the corners' and the memory one window's. Windows are whole cells of the
    // first level (at least one); 0: the whole span in one. The rows are the same whatever the
    // window (a window's ends are rows of the first level anyway) but where max_rows stops it.
    double window = 50e-6;
    // Threads refining windows side by side (the rows are the same for any number).
    int threads = 1;
    // When set (the reduced model, step = 0), each window's rows are handed here as soon as they
    // are made, in time order (time, then [probe][row]; a window's first row, the last one's end,
    // is not repeated), and waveform() returns the probe names with no rows: a caller that keeps
    // only some rows (a thinned record) holds one window at a time.
    std::function<void(const std::vector<double>& time,
                       const std::vector<std::vector<double>>& rows)>
        on_rows;
    // 0: no limit. Otherwise the most probe evaluations one grid level's superposition may take:
    // before each level the rule predicts them (probes x sum over ramps of the rows inside the
    // march window), and after each it predicts the level that will meet interp_tol (the error
    // of a smooth response falls as step^2); over the limit it stops with
    // GridInfo::over_budget and an empty waveform (`auto` then runs the transient, cheaper there).
    double max_evaluations = 0.0;
  };
  struct GridInfo {
    long corners = 0;  // ramps superposed
    long rows = 0;
    // s, the grid's step; with the reduced model and no given step, the finest step of the
    // locally refined grid (rows are at most coarse_step apart, coarse_step / 2^m where the
    // response bends)
    double step = 0.0;
    double coarse_step = 0.0;  // s, the refined grid's first level (0: a uniform grid)
    std::string warning;       // set when the rule hit max_rows before meeting interp_tol
    bool over_budget = false;  // stopped by max_evaluations: the waveform is empty
    double evaluations = 0.0;  // predicted probe evaluations of the levels computed (or refused)
  };
  // The probes on a uniform grid from tstart to tstop (tstop included when the step divides it),
  // plus a row at every source corner when the rule chooses the step.
  // Thread-safe (const): sweeps may evaluate many inputs on one LtiResponses.
  Waveform waveform(const std::vector<SourceInput>& inputs, const GridOptions& grid,
                    GridInfo* info = nullptr) const;

  // Every probe at the given times (ascending), for the given inputs: out[p][j]. With the reduced
  // model one pass over the times and corners (closed-form steps between them), so any number of
  // times costs O(times + corners) per mode.
  std::vector<std::vector<double>> values(const std::vector<SourceInput>& inputs,
                                          const std::vector<double>& times) const;

  // The probes from t0 on in closed form, when t0 is at or after every input's last corner and
  // every slope is back to zero there (a step, a ramp that has ended): probe p at t >= t0 is
  // constant[p] + sum_i Re(amplitude[p][i] e^{poles[i] (t - t0)}), the same modal sums values()
  // steps through. Empty when the slopes do not end by t0, or without the reduced model.
  struct ModalTail {
    double t0 = 0.0;
    std::vector<std::complex<double>> poles;                   // 1/s, every mode of the model
    std::vector<double> constant;                              // per probe: where it settles
    std::vector<std::vector<std::complex<double>>> amplitude;  // [probe][mode], at t0
  };
  std::optional<ModalTail> modal_tail(const std::vector<SourceInput>& inputs, double t0) const;

  const LtiStats& stats() const { return stats_; }
  bool reduced() const { return model_.has_value(); }

 private:
  // The output grid's view of the modes: at each time, the largest |p_i| among the modes whose
  // transient share (the part of the state that still decays, times max over probes of
  // probe_weight |out_pi|) is over threshold: the time scale the grid must resolve there.
  struct ModeRates {
    std::vector<double> probe_weight;  // per probe: 0 (not looked at), 1 (V) or 1e3 (A)
    double threshold = 0.0;
    std::vector<double> rate;  // per time, 1/s
  };
  // Reduced model: adds the ramps' response (without the base) at times[0..count) into out[p][j].
  // uniform_dt > 0 says that most consecutive times are that far apart (its step is cached).
  void modal_add(const std::vector<SourceInput>& inputs, const std::vector<double>& times,
                 double uniform_dt, std::vector<std::vector<double>>& out,
                 ModeRates* rates = nullptr) const;
  Waveform modal_waveform(const std::vector<SourceInput>& inputs, const GridOptions& grid,
                          const std::vector<double>& base, GridInfo& gi) const;

  struct Source {
    std::string name;
    // The circuit's own source function (Element::source_function): the circuit must outlive
    // this LtiResponses (netlist_inputs reads it).
    const SourceFunction* function = nullptr;
    double initial = 0.0;  // the netlist's value at t = 0
    // LtiOptions::tie_sources: the earlier source whose model input carries this one (its
    // slopes `tie_factor` times the leader's), -1 when it has an input of its own.
    int tied_to = -1;
    double tie_factor = 0.0;
  };
  friend class LtiMarch;   // lti_march.cpp: fills tau_, r_, s_, end_slope_
  friend class MarchGrid;  // lti.cpp: waveform() on the march's responses
  // Per probe: the DC point moved by the inputs' initial values through the DC gains.
  std::vector<double> base_values(const std::vector<SourceInput>& inputs) const;
  // compute's pieces: the time-varying sources and their unit excitations (per source, n + 1
  // entries); the DC point and gains; the reduced model (true: built and kept; false: failed
  // under Method::Auto, the reason in stats_.note); the march.
  std::vector<std::vector<double>> collect_sources(const Circuit& circuit, int n);
  // LtiOptions::tie_sources: fills tie_ from the netlist waveforms up to tstop.
  void find_ties(double tstop);
  // False when an input breaks a tie (tie_sources): the model cannot evaluate it.
  bool follows_ties(const std::vector<SourceInput>& inputs) const;
  // Per source: 1 when tied to an earlier one.
  std::vector<char> tied_sources() const {
    std::vector<char> t;
    for (const Source& s : sources_) t.push_back(s.tied_to >= 0);
    return t;
  }
  Status solve_dc(const Circuit& circuit, const MnaSystem& sys, const std::vector<Probe>& probes,
                  const std::vector<std::vector<double>>& unit,
                  std::vector<std::vector<double>>& dc_solutions);
  StatusOr<bool> try_reduced_model(const Circuit& circuit, const std::vector<Probe>& probes,
                                   const std::vector<std::vector<double>>& unit,
                                   const std::vector<std::vector<double>>& dc_solutions,
                                   const LtiOptions& opt);
  Status march(const Circuit& circuit, MnaSystem& sys, const std::vector<Probe>& probes,
               const std::vector<std::vector<double>>& unit, const LtiOptions& opt);
  // Adds sum of the inputs' ramps into out[p][i] for t_i = t0 + i dt, i < count.
  void superpose(const std::vector<SourceInput>& inputs, double t0, double dt, long count,
                 std::vector<std::vector<double>>& out) const;
  // Hermite interpolation of the march at tau in [tau_[i], tau_[i+1]] for source k, probe p.
  double hermite(size_t k, size_t p, size_t i, double tau) const;

  std::vector<Source> sources_;
  std::vector<std::string> labels_;
  std::vector<bool> is_current_;                         // per probe: i(...) probes
  std::vector<double> y_dc_;                             // per probe
  std::vector<std::vector<double>> gain_;                // [k][p]
  std::vector<double> tau_;                              // march times, tau_[0] = 0
  std::vector<std::vector<std::vector<double>>> r_, s_;  // [k][p][i]: R and S at tau_[i]
  std::vector<std::vector<double>> end_slope_;           // [k][p]: R's slope beyond the march
  std::optional<ReducedModel> model_;                    // set: responses from the model
  LtiStats stats_;
};

}  // namespace isolink
