#include "solver/port_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include "base/wide_simd.h"
#include "solver/dense_lapack.h"
#include "solver/elements/source_function.h"
#include "solver/mna.h"
#include "solver/mna_system.h"
#include "solver/step_control.h"

namespace isolink {

namespace {

using Cplx = std::complex<double>;

// The name of unknown `u` among an element's nodes ("0" for ground).
std::string node_name_of(const Element& e, int u) {
  if (u == 0) return "0";
  for (size_t j = 0; j < e.nodes().size() && j < e.node_names().size(); ++j)
    if (e.nodes()[j] == u) return e.node_names()[j];
  return "";
}

struct PortRef {
  const Element* element = nullptr;
  int index = 0;
  int p = 0, n = 0;
  bool controlled = false;
  int cp = 0, cn = 0;
};

std::vector<PortRef> collect_ports(const Circuit& circuit) {
  std::vector<PortRef> ports;
  for (const auto& e : circuit.elements())
    for (int k = 0; k < e->nonlinear_port_count(); ++k) {
      const NonlinearPort np = e->nonlinear_port(k);
      ports.push_back({e.get(), k, np.p, np.n, np.controlled, np.cp, np.cn});
    }
  return ports;
}

// A switch's control: the voltage source across its control nodes, read directly instead of
// through the model (exact), and left out of the model's inputs: its nodes are touched by
// nothing else (the switches' controls draw no current), so it reaches no other output.
struct ControlSource {
  const Element* source = nullptr;
  double sign = 1.0;  // v(cp, cn) = sign * the source's value
};

// Per node: the elements that can carry current into it (a switch's control terminals draw
// none and are left out), counted on the circuit itself (the linear network adds the shunts).
using NodeTouches = std::map<int, int>;
NodeTouches current_touches(const Circuit& circuit) {
  NodeTouches touched;
  for (const auto& e : circuit.elements()) {
    bool is_switch = false;
    for (int k = 0; k < e->nonlinear_port_count(); ++k)
      is_switch = is_switch || e->nonlinear_port(k).controlled;
    for (size_t j = 0; j < e->nodes().size(); ++j)
      if (!(is_switch && j >= 2)) ++touched[e->nodes()[j]];
  }
  return touched;
}

int touches(const NodeTouches& t, int node) {
  const auto it = t.find(node);
  return it == t.end() ? 0 : it->second;
}

StatusOr<std::vector<ControlSource>> control_sources(const Circuit& net,
                                                     const std::vector<PortRef>& ports,
                                                     const NodeTouches& touched) {
  std::vector<ControlSource> out;
  for (const PortRef& pr : ports) {
    if (!pr.controlled) continue;
    const Element* found = nullptr;
    double sign = 1.0;
    for (const auto& e : net.elements()) {
      if (!e->has_excitation() || e->branch_count() != 1 || e->nodes().size() != 2) continue;
      const int a = e->nodes()[0], b = e->nodes()[1];
      if ((a == pr.cp && b == pr.cn) || (a == pr.cn && b == pr.cp)) {
        found = e.get();
        sign = a == pr.cp ? 1.0 : -1.0;
        break;
      }
    }
    const auto alone = [&](int u) { return u == 0 || touches(touched, u) == 1; };
    if (found == nullptr || !found->source_function() || !alone(pr.cp) || !alone(pr.cn))
      return Status::Error(fmt::format(
          "{} is a voltage-controlled switch whose control is not a voltage source of its own "
          "(one across its control nodes, connected to nothing else): the port model reads such "
          "a source's value; the full transient runs any other control",
          pr.element->name()));
    out.push_back({found, sign});
  }
  return out;
}

// A source whose value never changes over [0, horizon]: DC, or a PWL without a corner there.
bool is_constant(const SourceFunction& f, double horizon) {
  using Kind = SourceFunction::Kind;
  if (f.kind() == Kind::Dc) return true;
  return f.kind() == Kind::Pwl && f.piecewise_linear() && f.ramps(horizon).empty();
}

// Probe `p` when it is the current of a voltage source in series with a port's element: one of
// the source's nodes is touched by the two alone, and the element's current enters at one
// terminal and leaves at the other (a diode: its port from the anode, or the internal node
// behind its series resistance, to the cathode; a switch: its port across its two switched
// terminals, its control terminals drawing nothing). The source's current is then the port's,
// with the sign returned (PortModel::PortCurrentProbe).
std::optional<std::pair<int, double>> series_port_current(const Circuit& circuit,
                                                          const std::vector<PortRef>& ports,
                                                          const NodeTouches& touched,
                                                          const Probe& p) {
  if (p.b != 0 || p.a == 0 || circuit.unknown_is_node(p.a)) return std::nullopt;
  const Element* source = nullptr;
  for (const auto& e : circuit.elements())
    if (e->has_excitation() && e->branch_count() == 1 && e->branches()[0] == p.a &&
        e->nodes().size() == 2)
      source = e.get();
  if (source == nullptr) return std::nullopt;
  for (size_t m = 0; m < ports.size(); ++m) {
    const PortRef& pr = ports[m];
    const Element& el = *pr.element;
    const size_t terminals = el.nodes().size() - el.internal_node_names().size();
    const bool two_terminals = !pr.controlled && terminals == 2;
    const bool a_switch = pr.controlled && terminals == 4 && pr.p == el.nodes()[0] &&
                          pr.cp == el.nodes()[2] && pr.cn == el.nodes()[3];
    if (el.nonlinear_port_count() != 1 || !(two_terminals || a_switch) || pr.n != el.nodes()[1] ||
        el.nodes()[0] == el.nodes()[1])
      continue;
    for (int side = 0; side < 2; ++side) {
      const int u = source->nodes()[side];
      if (u == 0 || touches(touched, u) != 2 || (u != el.nodes()[0] && u != el.nodes()[1]))
        continue;
      // The source's current flows from its first node through it to its second; the port's
      // from the element's first terminal through it to its second.
      const double into_element = u == el.nodes()[0] ? 1.0 : -1.0;
      return std::make_pair(static_cast<int>(m), side == 1 ? into_element : -into_element);
    }
  }
  return std::nullopt;
}

// The linear network of method step 1: the cards again, each port m shunted by gs[m].
StatusOr<std::unique_ptr<Circuit>> linear_network(const std::vector<Card>& cards,
                                                  const Circuit& circuit,
                                                  const std::vector<PortRef>& ports,
                                                  const std::vector<double>& gs) {
  auto lin = std::make_unique<Circuit>();
  for (const Card& card : cards)
    if (Status s = lin->add(card); !s.ok()) return s;
  for (size_t m = 0; m < ports.size(); ++m) {
    const PortRef& pr = ports[m];
    std::string p = node_name_of(*pr.element, pr.p), n = node_name_of(*pr.element, pr.n);
    if ((pr.p != 0 && p.empty()) || (pr.n != 0 && n.empty()))
      return Status::Error("port model: a port's nodes are not the element's own");
    // The shunt is an ordinary resistor card (solver/elements/resistor.cpp).
    Card shunt;
    shunt.letter = 'r';
    shunt.name = fmt::format("port#{}#{}", pr.element->name(), m);
    shunt.nodes = {std::move(p), std::move(n)};
    shunt.node_locs.resize(2);
    CardArg r;
    r.number = 1.0 / gs[m];
    shunt.args = {r};
    if (Status s = lin->add(shunt); !s.ok()) return s;
  }
  if (Status s = lin->finalize(); !s.ok()) return s;
  if (lin->unknown_count() != circuit.unknown_count())
    return Status::Error("port model: the linear network's unknowns differ from the circuit's");
  return lin;
}

}  // namespace

StatusOr<PortModel> build_port_model(const std::vector<Card>& cards, const Circuit& circuit,
                                     const std::vector<Probe>& probes, double horizon,
                                     const PortModelOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const std::vector<PortRef> ports = collect_ports(circuit);
  if (ports.empty()) return Status::Error("the circuit has no nonlinear element: no ports");
  if (!circuit.dc_open_branches().empty())
    return Status::Error(
        "an inductor closes a loop of voltage sources and inductors and is opened for the DC "
        "point: the port model needs the linear network's DC solution");
  for (const auto& [field, value] : {std::pair{"port_shunt", options.port_shunt},
                                     std::pair{"switch_port_shunt", options.switch_port_shunt}})
    if (!(value > 0) || !std::isfinite(value))
      return Status::Error(fmt::format("port model: {} = {:g}: must be positive", field, value));
  PortModel pm;
  for (const PortRef& pr : ports)
    pm.port_shunt.push_back(pr.controlled ? options.switch_port_shunt : options.port_shunt);
  StatusOr<std::unique_ptr<Circuit>> lin = linear_network(cards, circuit, ports, pm.port_shunt);
  if (!lin) return lin.status();
  const Circuit& net = **lin;
  std::vector<std::vector<double>> unit;
  const int n = net.unknown_count();
  // The constant sources (supplies, biases, the 0 V ammeters) are no inputs: their share of
  // every output is the linear network's DC solution for them alone, a constant offset (the
  // modes carry the rest). As inputs they added Krylov vectors and source-to-port pairs to the
  // check; on a stress circuit of a 15 m link (11 of 14 sources constant) the search stalled at
  // 3.4e-5 with no new direction (order 344).
  const NodeTouches touched = current_touches(circuit);
  StatusOr<std::vector<ControlSource>> controls = control_sources(net, ports, touched);
  if (!controls) return controls.status();
  for (size_t m = 0; m < ports.size(); ++m)
    pm.port_control.push_back(ports[m].controlled ? pm.controls++ : -1);
  std::vector<double> constant(n + 1, 0.0);
  for (const auto& e : net.elements()) {
    if (!e->has_excitation()) continue;
    const auto control = std::find_if(controls->begin(), controls->end(),
                                      [&](const ControlSource& c) { return c.source == e.get(); });
    // Read directly (control_sources), and no input unless a probe reads its nodes.
    if (control != controls->end() &&
        std::none_of(probes.begin(), probes.end(), [&](const Probe& p) {
          for (int u : e->nodes())
            if (u != 0 && (p.a == u || p.b == u)) return true;
          return false;
        }))
      continue;
    const SourceFunction* f = e->source_function();
    if (!f)
      return error_at(e->loc(), "port model: source '" + e->name() + "' has no time function");
    if (is_constant(*f, horizon)) {
      std::vector<double> u(n + 1, 0.0);
      e->stamp_unit(u.data());
      for (int i = 1; i <= n; ++i) constant[i] += f->dc_value() * u[i];
      pm.constant_sources.push_back({e->name(), f->dc_value()});
      continue;
    }
    pm.source_names.push_back(e->name());
    unit.emplace_back(n + 1, 0.0);
    e->stamp_unit(unit.back().data());
    unit.back()[0] = 0.0;
  }
  for (const ControlSource& c : *controls) pm.control_sources.push_back({c.source->name(), c.sign});
  pm.sources = static_cast<int>(unit.size());
  std::vector<Probe> outputs;
  for (size_t c = 0; c < probes.size(); ++c) {
    pm.labels.push_back(probes[c].label);
    if (auto port = series_port_current(circuit, ports, touched, probes[c])) {
      pm.port_current_probes.push_back({static_cast<int>(c), port->first, port->second});
      continue;
    }
    const Probe& p = probes[c];
    outputs.push_back(p);
    pm.probe_column.push_back(static_cast<int>(c));
  }
  pm.probes = static_cast<int>(outputs.size());
  for (const PortRef& pr : ports) {
    unit.emplace_back(n + 1, 0.0);
    unit.back()[pr.p] -= 1.0;  // the port's current leaves p through the element into n
    unit.back()[pr.n] += 1.0;
    unit.back()[0] = 0.0;
    pm.port_elements.push_back(pr.element->name());
    pm.port_index.push_back(pr.index);
    outputs.push_back({"port(" + pr.element->name() + ")", pr.p, pr.n});
  }
  pm.ports = static_cast<int>(ports.size());

  MnaSystem sys;
  if (Status s = sys.build(net); !s.ok()) return s;
  KluSolver dc_klu;
  if (Status s = sys.factor_dc(net, dc_klu); !s.ok())
    return s.with_context("port model: the linear network's DC solution");
  std::vector<std::vector<double>> dc = unit;
  for (auto& x : dc) {
    if (Status s = dc_klu.solve(x.data() + 1); !s.ok()) return s;
    x[0] = 0.0;
  }
  if (Status s = dc_klu.solve(constant.data() + 1); !s.ok()) return s;
  constant[0] = 0.0;
  for (const Probe& o : outputs) pm.offset.push_back(constant[o.a] - constant[o.b]);
  ReducedModelOptions ro = options.reduced;
  ro.horizon = horizon;
  ro.edge_time = 0.0;
  StatusOr<ReducedModel> model = reduce_circuit(net, unit, dc, outputs, ro);
  if (!model && n <= options.full_basis_at_most) {
    // The Krylov search can stall where the full basis passes (a 15 m link's hot-plug circuit,
    // 1,100 unknowns: at 1.3e-4), and the full basis's modal form can fail where the search
    // passes (eigenvectors too ill-conditioned: its ground-step circuit, 1,098 unknowns, 39 at
    // 62 kHz after 15 s): the one is tried when the other fails.
    ReducedModelOptions other = ro;
    other.full_order_at_most = n <= ro.full_order_at_most ? 0 : options.full_basis_at_most;
    StatusOr<ReducedModel> second = reduce_circuit(net, unit, dc, outputs, other);
    const bool full_first = n <= ro.full_order_at_most;
    if (!second)
      return Status::Error(fmt::format(
          "port model: {}: {}; {}: {}", full_first ? "the full basis" : "the Krylov search",
          model.status().message(), full_first ? "the Krylov search" : "the full basis",
          second.status().message()));
    model = std::move(second);
  }
  if (!model) return model.status().with_context("port model");
  for (const Cplx& p : model->poles)
    if (!(std::abs(p) > 0))
      return Status::Error("port model: a mode with a pole at 0 (no DC steady state)");
  pm.model = std::move(*model);
  pm.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return pm;
}

namespace {

// Exact integration coefficients of the modes over a step h (method step 3): for an input
// linear in t from w0 to w1, x1 = e x0 + a w0 + b w1; for an input constant at w1, x1 = e x0 +
// be w1. With z = p h: e = e^z, be = h (e^z - 1) / z, b = h (e^z - 1 - z) / z^2, a = be - b.
// Complex coefficients are held as real and imaginary arrays (the march's products vectorise).
// The modes' own (mode_coefs) serve the rows inside a step too (method step 5: its sub-steps).
struct ModeCoefs {
  Eigen::ArrayXd er, ei, ar, ai, br, bi, ber, bei;
};
struct StepCoefs : ModeCoefs {
  Eigen::MatrixXd z_trap, z_euler;  // port voltages per unit of end port current
  // The probes at the points that split the step into n = 2, 4 or 8 equal parts, in one pass each
  // (PortMarch::folded_rows): for the point at f = k / n and probe p, the probe's output row
  // times the coefficients of a step of f h, e, a + (1 - f) b and f b, in columns
  // 3 (ny (k - 1) + p) + 0, 1, 2 (real and imaginary parts), made on the first use. fold_r[j]
  // for n = 2^(j + 1).
  std::array<Eigen::MatrixXd, 3> fold_r, fold_i;
};

void phi12(Cplx z, Cplx* phi1, Cplx* phi2) {
  if (std::abs(z) < 0.05) {  // series: the closed forms cancel there
    *phi1 = 1.0 + z * (0.5 + z * (1.0 / 6 + z * (1.0 / 24 + z * (1.0 / 120 + z / 720.0))));
    *phi2 = 0.5 + z * (1.0 / 6 + z * (1.0 / 24 + z * (1.0 / 120 + z * (1.0 / 720 + z / 5040.0))));
    return;
  }
  const Cplx ez = std::exp(z);
  *phi1 = (ez - 1.0) / z;
  *phi2 = (ez - 1.0 - z) / (z * z);
}

// The marching state at one accepted time point.
struct PortState {
  double t = 0;
  Eigen::ArrayXd xr, xi;              // modes (real and imaginary parts)
  Eigen::ArrayXd sur, sui, sdr, sdi;  // in.u and in.d at t (per mode)
  std::vector<double> u;              // sources at t
  std::vector<double> v, d, q, jq;    // per port: voltage, current, charge, charge current
  std::vector<double> vc;             // per control: its voltage
  std::vector<double> y;              // probes
  std::vector<double> watched;        // v, q: what the error control watches
  void fill_watched() {
    watched.clear();
    watched.insert(watched.end(), v.begin(), v.end());
    watched.insert(watched.end(), q.begin(), q.end());
  }
};

ModeCoefs mode_coefs(const std::vector<Cplx>& poles, double h) {
  const int q = static_cast<int>(poles.size());
  ModeCoefs c;
  for (auto* v : {&c.er, &c.ei, &c.ar, &c.ai, &c.br, &c.bi, &c.ber, &c.bei}) v->resize(q);
  for (int i = 0; i < q; ++i) {
    const Cplx z = poles[i] * h;
    Cplx p1, p2;
    phi12(z, &p1, &p2);
    const Cplx e = std::exp(z), be = h * p1, b = h * p2, a = be - b;
    c.er[i] = e.real(), c.ei[i] = e.imag();
    c.ar[i] = a.real(), c.ai[i] = a.imag();
    c.br[i] = b.real(), c.bi[i] = b.imag();
    c.ber[i] = be.real(), c.bei[i] = be.imag();
  }
  return c;
}

// The largest step (method step 4): the user's TMAX; else, where every source is piecewise
// linear (its corners breakpoints, so the modes take it exactly) and no switch is controlled,
// (tstop - tstart) / 50, the accuracy left to the error control and the rows to method step 5;
// else TSTEP's bound, as the transient's.
double largest_step(const Circuit& circuit, const PortModel& pm, const TransientOptions& opt) {
  if (opt.tmax > 0 || pm.controls > 0) return opt.effective_tmax();
  for (const std::string& name : pm.source_names)
    if (!circuit.find_element(name)->source_function()->piecewise_linear())
      return opt.effective_tmax();
  return (opt.tstop - opt.tstart) / 50.0;
}

class PortMarch {
 public:
  PortMarch(const Circuit& circuit, const PortModel& pm, const TransientOptions& opt);
  StatusOr<Waveform> run(PortModelStats* stats);

 private:
  Status initial_state();
  // The step's coefficients, cached per step size (folded_rows adds its own to the entry).
  StepCoefs& coefs(double h);
  // Port m at voltage v, its control (a switch's) at vc[port_control[m]].
  PortEval eval(int m, double v, const std::vector<double>& vc) const {
    const int c = pm_.port_control[m];
    return c < 0 ? port_el_[m]->eval_port(pm_.port_index[m], v)
                 : port_el_[m]->eval_controlled_port(pm_.port_index[m], v, vc[c]);
  }
  // The control voltages at t (their sources' values).
  void controls_at(double t, std::vector<double>& vc) const;
  // Whether a switch changed state from cur() to s1 (its end is then a corner, as a breakpoint).
  bool control_changed(const PortState& s1) const;
  // One step of h from cur() into next_state(); *converged false when Newton did not converge.
  Status advance(double h, bool euler, bool* converged);
  bool newton(const StepCoefs& c, double h, bool euler, const std::vector<double>& v_oc,
              std::vector<double>& v);
  double truncation_ratio(const PortState& s1) const;
  // The port currents' departure from a straight line over the step of h to s1, through the
  // step's port impedances, against the port voltages' tolerances, as an order-3 ratio.
  double current_shape_ratio(const PortState& s1, double h);
  // The rows strictly inside the accepted step of h from s0 to s1 (method step 5).
  Status record_inside(const PortState& s0, const PortState& s1, double h, bool euler);
  const ModeCoefs& inner_coefs(double delta);
  // The probes (model outputs) at the n - 1 points inside the step that split it into n equal
  // parts, marched from s0 with the step's input (linear in t), into rows_ (n - 1 rows of ny_).
  void probes_inside(const PortState& s0, const PortState& s1, double h, bool euler, int n);
  // probes_inside for n = 2, 4 or 8 (the rows most steps need) without marching the modes: at
  // f = k / n the modes are x(f h) = e x0 + a w0 + b w(f h), w(f h) = (1 - f) w0 + f w1, with
  // the coefficients of a step of f h, so each probe's modal part is three products of the
  // states at the step's ends with the probe's row folded into them (StepCoefs::fold_r).
  void folded_rows(const PortState& s0, const PortState& s1, double h, bool euler, int n);
  // probes_inside where n allows the folded rows, else the march.
  void rows_inside(const PortState& s0, const PortState& s1, double h, bool euler, int n) {
    if (n <= kMaxFoldedParts)
      folded_rows(s0, s1, h, euler, n);
    else
      probes_inside(s0, s1, h, euler, n);
  }
  static constexpr int kMaxFoldedParts = 8;
  // StepCoefs::fold_r / fold_i for n parts of a step of h, into c.
  void make_fold(StepCoefs& c, double h, int n) const;
  // Adds to y (ny_ values) what a row at f h inside the step from s0 to s1 has besides its
  // modes: the constant offset, the sources' direct share at that instant and the port
  // currents' at their values on the line between the step's ends (an Euler step's modes take
  // the end value over the step; the instant's own current is nearer the line).
  void add_direct_share(const PortState& s0, const PortState& s1, double f, double* y);
  // Max over the probes and the inner points of |y_k - (y_k-1 + y_k+1) / 2| over the probe's
  // row tolerance: the deviation of the rows' linear interpolation at twice their spacing.
  double inner_deviation(const PortState& s0, const PortState& s1, int n) const;
  double euler_start_ratio(const PortState& s1) const;
  void update_tolerances(const PortState& s);
  // Port m's element current in state s: the current d the model takes plus the shunt's
  // give-back g_s v.
  double element_current(const PortState& s, int m) const {
    return s.d[m] + pm_.port_shunt[m] * s.v[m];
  }
  void record(const PortState& s);
  Status newton_failed(double t, double h) const;

  const Circuit& circuit_;
  const PortModel& pm_;
  const ReducedModel& m_;
  const TransientOptions& opt_;
  const int q_, ns_, np_, ny_, nc_;
  const double tiny_;
  const StepControl control_;
  std::vector<const SourceFunction*> sources_;
  std::vector<const SourceFunction*> controls_;  // per control: its source
  std::vector<double> control_sign_;
  std::vector<const Element*> port_el_;
  std::map<double, StepCoefs> cache_;
  double last_h_ = -1.0;  // coefs()'s last step size and its entry
  StepCoefs* last_coefs_ = nullptr;
  std::map<double, ModeCoefs> inner_cache_;
  // The march's points in four slots, reused without copies: the points since the last
  // breakpoint (hist(0) the oldest, the last the current point) and the step's end in the making.
  // (Copied into a separate history each step, they were 3 % of a 5 m link's march.)
  std::array<PortState, 4> states_;
  std::array<int, 3> hist_at_{0, 1, 2};
  int hist_count_ = 1;
  int next_at_ = 3;
  PortState& cur() { return states_[hist_at_[hist_count_ - 1]]; }
  const PortState& cur() const { return states_[hist_at_[hist_count_ - 1]]; }
  PortState& next_state() { return states_[next_at_]; }
  const PortState& hist(int k) const { return states_[hist_at_[k]]; }
  // The step's end becomes the current point, the oldest point dropped when three are kept.
  void accept_next_state();
  // The current point alone in the history (a breakpoint or a switch's event: the formula
  // restarts).
  void restart_history() {
    hist_at_[0] = hist_at_[hist_count_ - 1];
    hist_count_ = 1;
  }
  std::vector<double> peak_, inv_tol_, abs_tol_;
  std::vector<double> probe_peak_, probe_abs_tol_;  // per model probe
  std::vector<double> rows_;                        // scratch of probes_inside
  PortModelStats stats_;
  Waveform w_;
  int worst_port_ = 0;
  // Newton's scratch.
  Eigen::MatrixXd jac_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd f_, dv_;
  std::vector<double> dd_, v_oc_, v_, bend_;
  // The model as real matrices (complex ones split): inputs (sources, then ports) and outputs
  // (probes, then port voltages) by column, each a contiguous array over the modes.
  Eigen::MatrixXd in_re_, in_im_;    // modes x inputs
  Eigen::MatrixXd out_re_, out_im_;  // modes x outputs
  Eigen::MatrixXd direct_;           // outputs x inputs
  Eigen::VectorXd offset_;           // per output
  Eigen::ArrayXd scratch_r_, scratch_i_;
  Eigen::ArrayXd in_xr_, in_xi_, in_wr_, in_wi_, in_nr_, in_ni_;  // probes_inside's march
  Eigen::ArrayXd in_dwr_, in_dwi_;
  std::vector<double> inner_u_, inner_d_;
  // Output o's modal part, Re sum_i out_i x_i (the march's hot products written out here, not as
  // Eigen's matrix-vector products, which are compiled once for the baseline: inlined into the
  // ISOLINK_WIDE_SIMD callers they use their four lanes).
  double modal_output(int o, const Eigen::ArrayXd& xr, const Eigen::ArrayXd& xi) const {
    return out_re_.col(o).dot(xr.matrix()) - out_im_.col(o).dot(xi.matrix());
  }
  // re + j im = the inputs from..from + count - 1 weighted by w.
  void weighted_inputs(int from, int count, const double* w, Eigen::ArrayXd& re,
                       Eigen::ArrayXd& im) const;
  // in.u and in.d of state s (its u and d).
  void modal_inputs(const PortState& s, Eigen::ArrayXd& sur, Eigen::ArrayXd& sui,
                    Eigen::ArrayXd& sdr, Eigen::ArrayXd& sdi) const;
};

PortMarch::PortMarch(const Circuit& circuit, const PortModel& pm, const TransientOptions& opt)
    : circuit_(circuit),
      pm_(pm),
      m_(pm.model),
      opt_(opt),
      q_(static_cast<int>(pm.model.poles.size())),
      ns_(pm.sources),
      np_(pm.ports),
      ny_(pm.probes),
      nc_(pm.controls),
      tiny_(opt.tstop * 1e-12),
      control_{.hmax = largest_step(circuit, pm, opt),
               .hmin = std::max(1e-18, opt.tstop * 1e-13),
               .error_order = 3} {
  for (const std::string& name : pm.source_names)
    sources_.push_back(circuit.find_element(name)->source_function());
  for (const std::string& name : pm.port_elements) port_el_.push_back(circuit.find_element(name));
  for (const auto& [name, sign] : pm.control_sources) {
    controls_.push_back(circuit.find_element(name)->source_function());
    control_sign_.push_back(sign);
  }
  const int nin = ns_ + np_, nout = ny_ + np_;
  in_re_.resize(q_, nin), in_im_.resize(q_, nin);
  for (int k = 0; k < nin; ++k)
    for (int i = 0; i < q_; ++i)
      in_re_(i, k) = m_.input[k][i].real(), in_im_(i, k) = m_.input[k][i].imag();
  out_re_.resize(q_, nout), out_im_.resize(q_, nout);
  for (int o = 0; o < nout; ++o)
    for (int i = 0; i < q_; ++i)
      out_re_(i, o) = m_.output[o][i].real(), out_im_(i, o) = m_.output[o][i].imag();
  direct_.resize(nout, nin);
  for (int k = 0; k < nin; ++k)
    for (int o = 0; o < nout; ++o) direct_(o, k) = m_.direct[k][o];
  offset_ = Eigen::Map<const Eigen::VectorXd>(pm.offset.data(), nout);
  jac_.resize(np_, np_);
  lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(np_);
  v_oc_.assign(np_, 0.0);
  v_.assign(np_, 0.0);
  f_.resize(np_);
  dv_.resize(np_);
  dd_.assign(np_, 0.0);
  bend_.assign(np_, 0.0);
  // Absolute tolerances of the watched values (port voltages, charges) and of the probes' rows.
  for (int m = 0; m < np_; ++m) abs_tol_.push_back(opt.vntol);
  for (int m = 0; m < np_; ++m) abs_tol_.push_back(opt.chgtol);
  for (int p = 0; p < ny_; ++p)
    probe_abs_tol_.push_back(pm.labels[pm.probe_column[p]].rfind("i(", 0) == 0 ? opt.abstol
                                                                               : opt.vntol);
  probe_peak_.assign(ny_, 0.0);
}

// Z_h(mo, mi) = Re sum_i out_mo,i b_i in_mi,i + direct: with the ports' outputs times b split
// into Re and -Im (q x np each, both formulas' b side by side: trapezoidal b, Euler be), two real
// products with the ports' inputs' real and imaginary parts.
StepCoefs& PortMarch::coefs(double h) {
  if (h == last_h_) return *last_coefs_;
  auto it = cache_.find(h);
  if (it == cache_.end()) {
    if (cache_.size() > 256) cache_.clear();
    StepCoefs c;
    static_cast<ModeCoefs&>(c) = mode_coefs(m_.poles, h);
    Eigen::MatrixXd ob(2 * q_, 2 * np_);  // columns: trapezoidal per port, then Euler
    for (int f = 0; f < 2; ++f) {
      const Eigen::ArrayXd& br = f == 0 ? c.br : c.ber;
      const Eigen::ArrayXd& bi = f == 0 ? c.bi : c.bei;
      for (int mo = 0; mo < np_; ++mo) {
        const auto ore = out_re_.col(ny_ + mo).array(), oim = out_im_.col(ny_ + mo).array();
        ob.col(f * np_ + mo).head(q_) = ore * br - oim * bi;
        ob.col(f * np_ + mo).tail(q_) = -(ore * bi + oim * br);
      }
    }
    Eigen::MatrixXd z(2 * np_, np_);
    dense_multiply(true, 1.0, ob.topRows(q_), in_re_.middleCols(ns_, np_), 0.0, z);
    dense_multiply(true, 1.0, ob.bottomRows(q_), in_im_.middleCols(ns_, np_), 1.0, z);
    const Eigen::MatrixXd dir = direct_.block(ny_, ns_, np_, np_);
    c.z_trap = z.topRows(np_) + dir;
    c.z_euler = z.bottomRows(np_) + dir;
    ++stats_.step_sizes;
    it = cache_.emplace(h, std::move(c)).first;
  }
  last_h_ = h;
  last_coefs_ = &it->second;
  return it->second;
}

// Two inputs a pass over the modes (half the loads and stores of one at a time).
ISOLINK_WIDE_SIMD void PortMarch::weighted_inputs(int from, int count, const double* w,
                                                  Eigen::ArrayXd& re, Eigen::ArrayXd& im) const {
  re.resize(q_), im.resize(q_);
  double* rr = re.data();
  double* ri = im.data();
  const size_t q = static_cast<size_t>(q_);
  int k = 0;
  if (count % 2 == 1) {
    const double* ar = in_re_.data() + (from + k) * q;
    const double* ai = in_im_.data() + (from + k) * q;
    for (size_t i = 0; i < q; ++i) rr[i] = ar[i] * w[k], ri[i] = ai[i] * w[k];
    ++k;
  } else {
    for (size_t i = 0; i < q; ++i) rr[i] = 0.0, ri[i] = 0.0;
  }
  for (; k + 1 < count; k += 2) {
    const double* ar = in_re_.data() + (from + k) * q;
    const double* ai = in_im_.data() + (from + k) * q;
    const double *br = ar + q, *bi = ai + q;
    const double wa = w[k], wb = w[k + 1];
    for (size_t i = 0; i < q; ++i) {
      rr[i] += ar[i] * wa + br[i] * wb;
      ri[i] += ai[i] * wa + bi[i] * wb;
    }
  }
}

void PortMarch::modal_inputs(const PortState& s, Eigen::ArrayXd& sur, Eigen::ArrayXd& sui,
                             Eigen::ArrayXd& sdr, Eigen::ArrayXd& sdi) const {
  weighted_inputs(0, ns_, s.u.data(), sur, sui);
  weighted_inputs(ns_, np_, s.d.data(), sdr, sdi);
}

Status PortMarch::initial_state() {
  MnaSystem sys;
  if (Status s = sys.build(circuit_); !s.ok()) return s;
  std::vector<double> x(sys.n + 1, 0.0);
  if (Status s = sys.dc(circuit_, x); !s.ok()) return s.with_context("DC operating point");
  PortState& s = cur();
  s.t = 0;
  s.u.resize(ns_);
  for (int k = 0; k < ns_; ++k) s.u[k] = sources_[k]->value(0.0);
  s.v.resize(np_), s.d.resize(np_), s.q.resize(np_), s.jq.assign(np_, 0.0);
  controls_at(0.0, s.vc);
  for (int m = 0; m < np_; ++m) {
    const NonlinearPort np = port_el_[m]->nonlinear_port(pm_.port_index[m]);
    s.v[m] = x[np.p] - x[np.n];
    const PortEval e = eval(m, s.v[m], s.vc);
    s.d[m] = e.i - pm_.port_shunt[m] * s.v[m];
    s.q[m] = e.q;
  }
  s.xr.resize(q_), s.xi.resize(q_);
  modal_inputs(s, s.sur, s.sui, s.sdr, s.sdi);
  for (int i = 0; i < q_; ++i) {
    const Cplx xm = -Cplx(s.sur[i] + s.sdr[i], s.sui[i] + s.sdi[i]) / m_.poles[i];
    s.xr[i] = xm.real(), s.xi[i] = xm.imag();
  }
  // The model's outputs in that steady state against the circuit's operating point.
  const Eigen::VectorXd modal =
      out_re_.transpose() * s.xr.matrix() - out_im_.transpose() * s.xi.matrix();
  double mismatch = 0, allowed = 0;
  s.y.resize(ny_);
  for (int o = 0; o < ny_ + np_; ++o) {
    double y = pm_.offset[o] + modal(o);
    for (int k = 0; k < ns_; ++k) y += m_.direct[k][o] * s.u[k];
    for (int m = 0; m < np_; ++m) y += m_.direct[ns_ + m][o] * s.d[m];
    if (o < ny_) {
      s.y[o] = y;
      continue;
    }
    const double exact = s.v[o - ny_];
    mismatch = std::max(mismatch, std::fabs(y - exact));
    allowed = std::max(allowed, 1e-6 + 1e-5 * std::fabs(exact));
  }
  stats_.dc_mismatch = mismatch;
  if (!(mismatch <= allowed))
    return Status::Error(fmt::format(
        "port model: its DC state is {:.3g} V from the circuit's operating point at a port",
        mismatch));
  s.fill_watched();
  peak_.assign(s.watched.size(), 0.0);
  update_tolerances(s);
  return Status::Ok();
}

void PortMarch::update_tolerances(const PortState& s) {
  const size_t n = s.watched.size();
  inv_tol_.resize(n);
  for (size_t k = 0; k < n; ++k) peak_[k] = std::max(peak_[k], std::fabs(s.watched[k]));
  // A port voltage against the largest port voltage's peak: a diode held near its knee (the
  // forward half of a back-to-back TVS, 0.6 V between nodes that swing 5 V) is no scale of its
  // own, against its own peak it limited nearly every step of a 5 m link's march. A charge
  // against its own peak, as the transient's.
  const double v_peak = np_ > 0 ? *std::max_element(peak_.begin(), peak_.begin() + np_) : 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double peak = static_cast<int>(k) < np_ ? v_peak : peak_[k];
    inv_tol_[k] = 1.0 / (opt_.trtol * (opt_.reltol * peak + abs_tol_[k]));
  }
  for (int p = 0; p < ny_; ++p) probe_peak_[p] = std::max(probe_peak_[p], std::fabs(s.y[p]));
}

void PortMarch::record(const PortState& s) {
  if (s.t < opt_.tstart - tiny_) return;
  w_.time.push_back(s.t);
  for (int p = 0; p < ny_; ++p) w_.columns[pm_.probe_column[p]].push_back(s.y[p]);
  for (const PortModel::PortCurrentProbe& c : pm_.port_current_probes)
    w_.columns[c.column].push_back(c.sign * element_current(s, c.port));
}

const ModeCoefs& PortMarch::inner_coefs(double delta) {
  auto it = inner_cache_.find(delta);
  if (it != inner_cache_.end()) return it->second;
  if (inner_cache_.size() > 64) inner_cache_.clear();
  return inner_cache_.emplace(delta, mode_coefs(m_.poles, delta)).first->second;
}

ISOLINK_WIDE_SIMD void PortMarch::probes_inside(const PortState& s0, const PortState& s1, double h,
                                                bool euler, int n) {
  const ModeCoefs& c = inner_coefs(h / n);
  // The step's modal input, linear in t: w(0) = in.u0 + in.d0 (Euler: in.d1), w(h) = in.u1 + in.d1.
  const Eigen::ArrayXd& d0r = euler ? s1.sdr : s0.sdr;
  const Eigen::ArrayXd& d0i = euler ? s1.sdi : s0.sdi;
  in_xr_ = s0.xr, in_xi_ = s0.xi;
  in_wr_ = s0.sur + d0r, in_wi_ = s0.sui + d0i;
  in_dwr_ = s1.sur + s1.sdr - in_wr_, in_dwi_ = s1.sui + s1.sdi - in_wi_;  // w(h) - w(0)
  rows_.resize(static_cast<size_t>(n - 1) * ny_);
  for (int k = 1; k < n; ++k) {
    const double f = static_cast<double>(k) / n;
    in_nr_ = (s0.sur + d0r) + f * in_dwr_;
    in_ni_ = (s0.sui + d0i) + f * in_dwi_;
    scratch_r_ = c.er * in_xr_ - c.ei * in_xi_ + c.ar * in_wr_ - c.ai * in_wi_ + c.br * in_nr_ -
                 c.bi * in_ni_;
    in_xi_ = c.er * in_xi_ + c.ei * in_xr_ + c.ar * in_wi_ + c.ai * in_wr_ + c.br * in_ni_ +
             c.bi * in_nr_;
    in_xr_.swap(scratch_r_);
    in_wr_.swap(in_nr_), in_wi_.swap(in_ni_);
    double* y = rows_.data() + static_cast<size_t>(k - 1) * ny_;
    for (int p = 0; p < ny_; ++p) y[p] = modal_output(p, in_xr_, in_xi_);
    add_direct_share(s0, s1, f, y);
  }
}

void PortMarch::add_direct_share(const PortState& s0, const PortState& s1, double f, double* y) {
  std::vector<double>& u = inner_u_;
  std::vector<double>& d = inner_d_;
  u.resize(ns_), d.resize(np_);
  const double t = s0.t + f * (s1.t - s0.t);
  for (int j = 0; j < ns_; ++j) u[j] = sources_[j]->value(t);
  for (int m = 0; m < np_; ++m) d[m] = (1 - f) * s0.d[m] + f * s1.d[m];
  Eigen::Map<Eigen::VectorXd> out(y, ny_);
  out.noalias() +=
      direct_.topLeftCorner(ny_, ns_) * Eigen::Map<const Eigen::VectorXd>(u.data(), ns_);
  out.noalias() +=
      direct_.block(0, ns_, ny_, np_) * Eigen::Map<const Eigen::VectorXd>(d.data(), np_);
  out += offset_.head(ny_);
}

void PortMarch::make_fold(StepCoefs& c, double h, int n) const {
  const int fold = n == 2 ? 0 : n == 4 ? 1 : 2;
  Eigen::MatrixXd &fr = c.fold_r[fold], &fi = c.fold_i[fold];
  fr.resize(q_, 3 * ny_ * (n - 1)), fi.resize(q_, 3 * ny_ * (n - 1));
  for (int k = 1; k < n; ++k) {
    const double f = static_cast<double>(k) / n;
    const ModeCoefs sub = mode_coefs(m_.poles, f * h);
    for (int p = 0; p < ny_; ++p)
      for (int i = 0; i < q_; ++i) {
        const Cplx out(out_re_(i, p), out_im_(i, p)), b(sub.br[i], sub.bi[i]);
        const Cplx w[3] = {out * Cplx(sub.er[i], sub.ei[i]),
                           out * (Cplx(sub.ar[i], sub.ai[i]) + (1 - f) * b), out * f * b};
        const int col = 3 * (ny_ * (k - 1) + p);
        for (int j = 0; j < 3; ++j) fr(i, col + j) = w[j].real(), fi(i, col + j) = w[j].imag();
      }
  }
}

ISOLINK_WIDE_SIMD void PortMarch::folded_rows(const PortState& s0, const PortState& s1, double h,
                                              bool euler, int n) {
  StepCoefs& c = coefs(h);
  const int fold = n == 2 ? 0 : n == 4 ? 1 : 2;
  if (c.fold_r[fold].cols() != 3 * ny_ * (n - 1)) make_fold(c, h, n);
  const Eigen::MatrixXd &fr = c.fold_r[fold], &fi = c.fold_i[fold];
  // w0 = in.u0 + in.d0 (Euler: in.d1), w1 = in.u1 + in.d1, as probes_inside.
  const double* d0r = (euler ? s1.sdr : s0.sdr).data();
  const double* d0i = (euler ? s1.sdi : s0.sdi).data();
  const double *x0r = s0.xr.data(), *x0i = s0.xi.data(), *u0r = s0.sur.data(), *u0i = s0.sui.data(),
               *u1r = s1.sur.data(), *u1i = s1.sui.data(), *d1r = s1.sdr.data(),
               *d1i = s1.sdi.data();
  rows_.resize(static_cast<size_t>(n - 1) * ny_);
  for (int k = 1; k < n; ++k) {
    double* y = rows_.data() + static_cast<size_t>(k - 1) * ny_;
    for (int p = 0; p < ny_; ++p) {
      const int col = 3 * (ny_ * (k - 1) + p);
      const double *er = fr.col(col).data(), *ei = fi.col(col).data();
      const double *ar = er + q_, *ai = ei + q_, *br = ar + q_, *bi = ai + q_;
      double sum = 0.0;
      for (int i = 0; i < q_; ++i)
        sum += er[i] * x0r[i] - ei[i] * x0i[i] + ar[i] * (u0r[i] + d0r[i]) -
               ai[i] * (u0i[i] + d0i[i]) + br[i] * (u1r[i] + d1r[i]) - bi[i] * (u1i[i] + d1i[i]);
      y[p] = sum;
    }
    add_direct_share(s0, s1, static_cast<double>(k) / n, y);
  }
}

double PortMarch::inner_deviation(const PortState& s0, const PortState& s1, int n) const {
  double worst = 0.0;
  for (int p = 0; p < ny_; ++p) {
    const double peak = std::max({probe_peak_[p], std::fabs(s0.y[p]), std::fabs(s1.y[p])});
    const double tol = opt_.trtol * (opt_.reltol * peak + probe_abs_tol_[p]);
    auto at = [&](int k) {
      return k == 0 ? s0.y[p] : k == n ? s1.y[p] : rows_[static_cast<size_t>(k - 1) * ny_ + p];
    };
    for (int k = 1; k < n; ++k)
      worst = std::max(worst, std::fabs(at(k) - 0.5 * (at(k - 1) + at(k + 1))) / tol);
  }
  return worst;
}

// Method step 5: the step's rows at most TSTEP apart, and as many more as the probes' linear
// interpolation between rows needs to stay within trtol (reltol peak + vntol | abstol): at
// 2^j equal parts, the deviation at twice the spacing measured on the rows themselves (a
// midpoint at least), a quarter of it taken as the deviation at their own spacing.
Status PortMarch::record_inside(const PortState& s0, const PortState& s1, double h, bool euler) {
  if (ny_ == 0 && pm_.port_current_probes.empty()) return Status::Ok();
  if (s1.t <= opt_.tstart) return Status::Ok();
  constexpr int kMaxParts = 1024;
  int n = 2;
  while (n < kMaxParts && (s1.t - s0.t) / n > opt_.tstep * (1 + 1e-9)) n *= 2;
  const bool print_rows = (s1.t - s0.t) > opt_.tstep * (1 + 1e-9);  // TSTEP's rows needed
  if (ny_ == 0 && !print_rows) return Status::Ok();  // the port currents are lines in between
  if (ny_ > 0) {
    rows_inside(s0, s1, h, euler, n);
    double dev = inner_deviation(s0, s1, n);
    if (!print_rows && dev <= 1.0) return Status::Ok();  // the step's ends suffice
    if (dev > 4.0 && n < kMaxParts) {
      // Quartered per halving of the spacing: n' = n sqrt(dev / 4), a power of two.
      while (n < kMaxParts && dev > 4.0) n *= 2, dev /= 4;
      rows_inside(s0, s1, h, euler, n);
    }
  }
  if (w_.time.size() + n > static_cast<size_t>(opt_.max_steps))
    return Status::Error(fmt::format("port model gave up at t={:g} s after {} rows (max_steps)",
                                     s0.t, w_.time.size()));
  for (int k = 1; k < n; ++k) {
    const double f = static_cast<double>(k) / n, t = s0.t + f * (s1.t - s0.t);
    if (t < opt_.tstart - tiny_) continue;
    w_.time.push_back(t);
    for (int p = 0; p < ny_; ++p)
      w_.columns[pm_.probe_column[p]].push_back(rows_[static_cast<size_t>(k - 1) * ny_ + p]);
    for (const PortModel::PortCurrentProbe& c : pm_.port_current_probes)
      w_.columns[c.column].push_back(
          c.sign * ((1 - f) * element_current(s0, c.port) + f * element_current(s1, c.port)));
  }
  return Status::Ok();
}

// Newton on the port voltages: v = v_oc + Z_h d(v), d the port current with its charge's
// current by the step's formula; v in: the first iterate, out: the solution (into next_state()
// too).
ISOLINK_WIDE_SIMD bool PortMarch::newton(const StepCoefs& c, double h, bool euler,
                                         const std::vector<double>& v_oc, std::vector<double>& v) {
  const Eigen::MatrixXd& z = euler ? c.z_euler : c.z_trap;
  const double a0 = euler ? 1.0 / h : 2.0 / h;
  const NewtonTolerances& tol = opt_.newton;
  PortState& s1 = next_state();
  std::vector<double>& hq = s1.jq;  // the charge current's history part, then its value
  for (int m = 0; m < np_; ++m) hq[m] = euler ? -cur().q[m] / h : -a0 * cur().q[m] - cur().jq[m];
  bool limited = true;
  double last_fnorm = 0.0;
  controls_at(s1.t, s1.vc);
  for (int it = 0; it <= tol.max_iterations; ++it) {
    for (int m = 0; m < np_; ++m) {
      const PortEval e = eval(m, v[m], s1.vc);
      s1.q[m] = e.q;
      const double gs = pm_.port_shunt[m];
      s1.d[m] = e.i - gs * v[m] + a0 * e.q + hq[m];
      dd_[m] = e.g - gs + a0 * e.c;
    }
    bool f_ok = true;
    for (int mo = 0; mo < np_; ++mo) {
      double f = v[mo] - v_oc[mo];
      for (int mi = 0; mi < np_; ++mi) f -= z(mo, mi) * s1.d[mi];
      f_(mo) = f;
      if (!(std::fabs(f) <= tol.reltol * std::fabs(v[mo]) + tol.vntol)) {
        f_ok = false;
        worst_port_ = mo;
      }
    }
    if (it == tol.max_iterations) break;
    // The Jacobian is factored on the first iteration and again whenever the last update was
    // limited or did not halve the residual; otherwise its factors are reused (chord steps).
    // (Reused from one step to the next of the same size too, it took 45 % more iterations on
    // the corpus's TVS links for the factorisations it saved: no faster.)
    const double fnorm = f_.lpNorm<Eigen::Infinity>();
    if (it == 0 || limited || !(fnorm < 0.5 * last_fnorm)) {
      for (int mi = 0; mi < np_; ++mi) jac_.col(mi) = -z.col(mi) * dd_[mi];
      jac_.diagonal().array() += 1.0;
      lu_.compute(jac_);
    }
    last_fnorm = fnorm;
    f_ = -f_;
    dv_ = lu_.solve(f_);
    ++stats_.newton_iterations;
    // Converged: this iterate's residual and the update from it within the tolerances, after at
    // least one update that was not limited. The iterate is kept, its currents and charges as
    // evaluated (the update is the error estimate, not applied: the end point's evaluation that
    // applying it needs was a third of each step's device evaluations, 4 % of a 5 m link's march,
    // the waveform within 0.001 mV).
    bool small = true;
    for (int m = 0; m < np_; ++m)
      if (std::fabs(dv_(m)) >
          tol.reltol * std::max(std::fabs(v[m] + dv_(m)), std::fabs(v[m])) + tol.vntol)
        small = false;
    if (it > 0 && !limited && small && f_ok) {
      for (int m = 0; m < np_; ++m) s1.jq[m] = a0 * s1.q[m] + hq[m];
      s1.v = v;
      return true;
    }
    limited = false;
    for (int m = 0; m < np_; ++m) {
      const double vn = v[m] + dv_(m);
      if (!std::isfinite(vn)) return false;
      bool lim = false;
      v[m] = port_el_[m]->limit_port(pm_.port_index[m], vn, v[m], &lim);
      limited = limited || lim;
    }
  }
  return false;
}

ISOLINK_WIDE_SIMD Status PortMarch::advance(double h, bool euler, bool* converged) {
  const StepCoefs& c = coefs(h);
  const PortState& s0 = cur();
  PortState& s1 = next_state();
  s1.t = s0.t + h;
  s1.u.resize(ns_);
  for (int k = 0; k < ns_; ++k) s1.u[k] = sources_[k]->value(s1.t);
  const Eigen::Map<const Eigen::VectorXd> u1(s1.u.data(), ns_);
  weighted_inputs(0, ns_, s1.u.data(), s1.sur, s1.sui);
  // x1 = e x0 + a (su0 [+ sd0]) + b su1, complex products in real arrays.
  Eigen::ArrayXd& wr = scratch_r_;
  Eigen::ArrayXd& wi = scratch_i_;
  if (euler) {
    wr = s0.sur, wi = s0.sui;
  } else {
    wr = s0.sur + s0.sdr, wi = s0.sui + s0.sdi;
  }
  s1.xr = c.er * s0.xr - c.ei * s0.xi + c.ar * wr - c.ai * wi + c.br * s1.sur - c.bi * s1.sui;
  s1.xi = c.er * s0.xi + c.ei * s0.xr + c.ar * wi + c.ai * wr + c.br * s1.sui + c.bi * s1.sur;
  std::vector<double>& v_oc = v_oc_;
  std::vector<double>& v = v_;
  {
    Eigen::Map<Eigen::VectorXd> voc(v_oc.data(), np_);
    for (int m = 0; m < np_; ++m) voc[m] = modal_output(ny_ + m, s1.xr, s1.xi);
    voc.noalias() += direct_.block(ny_, 0, np_, ns_) * u1;
    voc += offset_.segment(ny_, np_);
  }
  // The first iterate: the parabola through the last three points (since the last breakpoint),
  // else the line through the last two, at the step's end. The parabola's first iterate is
  // nearer: 11 % fewer Newton iterations on a 5 m TVS link (234,287 -> 209,411), the same steps.
  v = s0.v;
  if (hist_count_ == 3) {
    const PortState &sm = hist(1), &sm2 = hist(0);
    const double t = s1.t, t0 = s0.t, t1 = sm.t, t2 = sm2.t;
    const double l0 = (t - t1) * (t - t2) / ((t0 - t1) * (t0 - t2));
    const double l1 = (t - t0) * (t - t2) / ((t1 - t0) * (t1 - t2));
    const double l2 = (t - t0) * (t - t1) / ((t2 - t0) * (t2 - t1));
    for (int m = 0; m < np_; ++m) v[m] = l0 * s0.v[m] + l1 * sm.v[m] + l2 * sm2.v[m];
  } else if (hist_count_ == 2) {
    const PortState& sm = hist(0);
    const double r = h / (s0.t - sm.t);
    for (int m = 0; m < np_; ++m) v[m] += r * (s0.v[m] - sm.v[m]);
  }
  s1.v.resize(np_), s1.d.resize(np_), s1.q.resize(np_), s1.jq.resize(np_);
  *converged = newton(c, h, euler, v_oc, v);
  if (!*converged) {
    ++stats_.newton_failures;
    return Status::Ok();
  }
  const Eigen::Map<const Eigen::VectorXd> d1(s1.d.data(), np_);
  weighted_inputs(ns_, np_, s1.d.data(), s1.sdr, s1.sdi);
  const Eigen::ArrayXd& bdr = euler ? c.ber : c.br;
  const Eigen::ArrayXd& bdi = euler ? c.bei : c.bi;
  s1.xr += bdr * s1.sdr - bdi * s1.sdi;
  s1.xi += bdr * s1.sdi + bdi * s1.sdr;
  s1.y.resize(ny_);
  if (ny_ > 0) {
    Eigen::Map<Eigen::VectorXd> y1(s1.y.data(), ny_);
    for (int p = 0; p < ny_; ++p) y1[p] = modal_output(p, s1.xr, s1.xi);
    y1.noalias() += direct_.topLeftCorner(ny_, ns_) * u1;
    y1.noalias() += direct_.block(0, ns_, ny_, np_) * d1;
    y1 += offset_.head(ny_);
  }
  for (int p = 0; p < ny_; ++p) {
    const double y = s1.y[p];
    if (!std::isfinite(y))
      return Status::Error(fmt::format("port model: non-finite value at t={:g} s ({})", s1.t,
                                       pm_.labels[pm_.probe_column[p]]));
  }
  s1.fill_watched();
  return Status::Ok();
}

void PortMarch::accept_next_state() {
  if (hist_count_ == 3) {
    hist_at_[0] = hist_at_[1], hist_at_[1] = hist_at_[2];
    hist_count_ = 2;
  }
  hist_at_[hist_count_++] = next_at_;
  for (int slot = 0; slot < 4; ++slot)  // a slot the history does not hold
    if (std::find(hist_at_.begin(), hist_at_.begin() + hist_count_, slot) ==
        hist_at_.begin() + hist_count_) {
      next_at_ = slot;
      break;
    }
}

void PortMarch::controls_at(double t, std::vector<double>& vc) const {
  vc.resize(nc_);
  for (int c = 0; c < nc_; ++c) vc[c] = control_sign_[c] * controls_[c]->value(t);
}

bool PortMarch::control_changed(const PortState& s1) const {
  for (int m = 0; m < np_; ++m) {
    const int c = pm_.port_control[m];
    if (c >= 0 && port_el_[m]->control_state(pm_.port_index[m], cur().vc[c]) !=
                      port_el_[m]->control_state(pm_.port_index[m], s1.vc[c]))
      return true;
  }
  return false;
}

// The transient's truncation term (trapezoidal, third divided difference over four points).
double PortMarch::truncation_ratio(const PortState& s1) const {
  if (hist_count_ != 3) return 0.0;
  const double t1 = s1.t, t0 = hist(2).t, tm1 = hist(1).t, tm2 = hist(0).t;
  const auto &x1 = s1.watched, &x0 = hist(2).watched, &xm1 = hist(1).watched,
             &xm2 = hist(0).watched;
  const double coef = (1.0 / 12.0) * 6.0, step = t1 - t0;
  const double ia = 1.0 / (t1 - t0), ib = 1.0 / (t0 - tm1), ic = 1.0 / (tm1 - tm2);
  const double ie = 1.0 / (t1 - tm1), iff = 1.0 / (t0 - tm2), ig = 1.0 / (t1 - tm2);
  const double h3 = step * step * step * coef * ig;
  const double w1 = h3 * ie * ia, w2 = -h3 * ib * (ie + iff), w3 = h3 * iff * ic;
  double ratio = 0.0;
  for (size_t k = 0; k < x1.size(); ++k)
    ratio = std::max(ratio, inv_tol_[k] * std::fabs(w1 * (x1[k] - x0[k]) + w2 * (x0[k] - xm1[k]) +
                                                    w3 * (xm1[k] - xm2[k])));
  return ratio;
}

// Method step 4's second estimate. The march takes each port's current as a straight line over a
// step; the port voltages at its ends can be smooth while the current bends (a diode's knee on a
// slow ramp: v ~ log t, i ~ t), and the rows inside the step (method step 5) then carry the bend.
// The bend's peak, h^2 d'' / 8 with d'' from the last three points (the conduction current i(v)
// only: the charge current's trapezoidal value rings, its charge is watched; the shunt's
// give-back g_s v bends as the port voltage, whose share through Z_h g_s << 1 the rows show,
// and counted it took 15-30 % more steps on the corpus's TVS links), through the step's
// impedances Z_euler (a constant current over the step), is a port voltage error; its ratio to
// the port voltage's tolerance, of order 2 in h, is returned as of order 3 (r^1.5). Summed with
// their signs: with |Z| the steps of the corpus's 3-7 m links rose by a further 30 %.
double PortMarch::current_shape_ratio(const PortState& s1, double h) {
  if (hist_count_ < 2) return 0.0;
  const PortState &s0 = hist(hist_count_ - 1), &sm = hist(hist_count_ - 2);
  const double i10 = 1.0 / (s1.t - s0.t), i0m = 1.0 / (s0.t - sm.t), i1m = 1.0 / (s1.t - sm.t);
  const double h1 = s1.t - s0.t;
  bool any = false;
  for (int m = 0; m < np_; ++m) {
    const double g = pm_.port_shunt[m];  // the conduction current alone
    const double r1 = s1.d[m] - s1.jq[m] + g * s1.v[m], r0 = s0.d[m] - s0.jq[m] + g * s0.v[m],
                 rm = sm.d[m] - sm.jq[m] + g * sm.v[m];
    const double dd2 = ((r1 - r0) * i10 - (r0 - rm) * i0m) * i1m;  // d'' / 2
    bend_[m] = 0.25 * h1 * h1 * dd2;
    any = any || bend_[m] != 0;
  }
  if (!any) return 0.0;
  const Eigen::MatrixXd& z = coefs(h).z_euler;
  double ratio = 0.0;
  for (int mo = 0; mo < np_; ++mo) {
    double dv = 0.0;
    for (int mi = 0; mi < np_; ++mi) dv += z(mo, mi) * bend_[mi];
    ratio = std::max(ratio, std::fabs(dv) * inv_tol_[mo]);
  }
  return ratio * std::sqrt(ratio);
}

// The backward-Euler first step, judged with the second step's point: h1^2 x'' / 2.
double PortMarch::euler_start_ratio(const PortState& s2) const {
  const double t0 = hist(0).t, t1 = hist(1).t, t2 = s2.t, h1 = t1 - t0;
  const auto &x0 = hist(0).watched, &x1 = hist(1).watched, &x2 = s2.watched;
  const double i21 = 1.0 / (t2 - t1), i10 = 1.0 / h1, i20 = 1.0 / (t2 - t0);
  double ratio = 0.0;
  for (size_t k = 0; k < x2.size(); ++k) {
    const double dd2 = ((x2[k] - x1[k]) * i21 - (x1[k] - x0[k]) * i10) * i20;
    ratio = std::max(ratio, inv_tol_[k] * h1 * h1 * std::fabs(dd2));
  }
  return ratio;
}

Status PortMarch::newton_failed(double t, double h) const {
  return Status::Error(fmt::format(
      "port model: time step too small at t={:g} s (h={:g} s): Newton's iteration on the ports "
      "does not converge at {}",
      t, h, pm_.port_elements[worst_port_]));
}

StatusOr<Waveform> PortMarch::run(PortModelStats* stats_out) {
  if (Status s = initial_state(); !s.ok()) return s;
  const double tstop = opt_.tstop, tiny = tiny_, hmax = control_.hmax, hmin = control_.hmin;
  std::vector<double> bps;
  for (const auto& e : circuit_.elements()) e->breakpoints(tstop, bps);
  bps.push_back(tstop);
  std::sort(bps.begin(), bps.end());
  std::vector<double> merged;
  for (double t : bps)
    if (t > tiny && (merged.empty() || t - merged.back() > tiny)) merged.push_back(t);
  bps.swap(merged);
  for (const std::string& l : pm_.labels) w_.add_column(l, {});
  record(cur());
  size_t next_bp = 0;
  double h = control_.ladder(0.1 * std::min(hmax, bps[0]));
  double last_regular_h = hmax;
  bool after_bp = true;
  while (cur().t < tstop - tiny) {
    if (stats_.accepted + stats_.rejected >= opt_.max_steps)
      return Status::Error(fmt::format("port model gave up at t={:g} s after {} steps (max_steps)",
                                       cur().t, opt_.max_steps));
    while (next_bp < bps.size() && bps[next_bp] <= cur().t + tiny) ++next_bp;
    const double bp = next_bp < bps.size() ? bps[next_bp] : tstop;
    double step = std::min(h, hmax);
    bool lands = false;
    if (cur().t + step >= bp - tiny) {
      step = bp - cur().t;
      lands = true;
    } else if (cur().t + 1.5 * step > bp) {
      step = 0.5 * (bp - cur().t);
    }
    const bool euler = after_bp || hist_count_ < 2;
    bool converged = true;
    if (Status s = advance(step, euler, &converged); !s.ok()) return s;
    if (!converged) {
      ++stats_.rejected;
      h = step / 8;
      if (h < hmin) return newton_failed(cur().t, h);
      h = control_.ladder(h);
      continue;
    }
    // A switch that changed state in this step: its end is a corner of the solution, taken as a
    // breakpoint (no error check across it, the formula restarted after it), as the transient.
    const bool event = nc_ > 0 && control_changed(next_state());
    const double ratio = euler || event ? 0.0
                                        : std::max(truncation_ratio(next_state()),
                                                   current_shape_ratio(next_state(), step));
    if (!event && hist_count_ == 2) {
      const double ratio1 = euler_start_ratio(next_state());
      if (ratio1 > 1.0) {  // undo the Euler step and this one; retry the first shorter
        stats_.rejected += 2;
        --stats_.accepted;
        const double t0 = hist(0).t, t1 = hist(1).t;
        const double h_retry = StepControl::shrink_by_order(t1 - t0, ratio1, 2, 0.1);
        if (h_retry < hmin)
          return Status::Error(
              fmt::format("port model: time step too small at t={:g} s (h={:g} s)", t0, h_retry));
        while (!w_.time.empty() && w_.time.back() > t0) {  // the Euler step's rows
          w_.time.pop_back();
          for (auto& col : w_.columns) col.pop_back();
        }
        hist_count_ = 1;  // hist(0), the Euler step's start, is the current point again
        after_bp = true;
        h = control_.ladder(h_retry);
        continue;
      }
    }
    if (ratio > 1.0) {
      ++stats_.rejected;
      h = control_.shrink(step, ratio);
      if (h < hmin)
        return Status::Error(
            fmt::format("port model: time step too small at t={:g} s (h={:g} s)", cur().t, h));
      h = control_.ladder(h);
      continue;
    }
    ++stats_.accepted;
    if (lands) next_state().t = bp;
    if (!event)  // a switch's step: its current jumps, no straight line to show inside it
      if (Status s = record_inside(cur(), next_state(), step, euler); !s.ok()) return s;
    accept_next_state();
    record(cur());
    update_tolerances(cur());
    if (!lands) last_regular_h = step;
    h = control_.grow(step, ratio);
    after_bp = false;
    if (event && !lands) {
      after_bp = true;
      h = control_.ladder(0.1 * std::min(last_regular_h, bp - cur().t));
      restart_history();
    }
    if (lands) {
      after_bp = true;
      const double next = next_bp + 1 < bps.size() ? bps[next_bp + 1] : tstop;
      h = control_.ladder(0.1 * std::min(last_regular_h, next - cur().t));
      restart_history();
    }
  }
  if (stats_out) *stats_out = stats_;
  return std::move(w_);
}

}  // namespace

StatusOr<Waveform> run_port_model(Circuit& circuit, const PortModel& model,
                                  const TransientOptions& opt, PortModelStats* stats) {
  for (const auto& e : circuit.elements()) e->bind_time(opt.tstep, opt.tstop);
  return run_port_model_bound(circuit, model, opt, stats);
}

StatusOr<Waveform> run_port_model_bound(const Circuit& circuit, const PortModel& model,
                                        const TransientOptions& opt, PortModelStats* stats) {
  if (Status s = opt.validate(); !s.ok()) return s;
  if (opt.uic || !opt.node_ic.empty())
    return Status::Error(
        ".ic / .tran uic: the port model starts from the circuit's own DC operating point");
  for (const std::string& name : model.source_names)
    if (!circuit.find_element(name) || !circuit.find_element(name)->source_function())
      return Status::Error("port model: built from another circuit (source " + name + ")");
  for (const auto& [name, value] : model.constant_sources) {
    const Element* e = circuit.find_element(name);
    if (!e || !e->source_function() || e->source_function()->dc_value() != value)
      return Status::Error("port model: built from another circuit (constant source " + name + ")");
  }
  for (const auto& [name, sign] : model.control_sources)
    if (!circuit.find_element(name) || !circuit.find_element(name)->source_function())
      return Status::Error("port model: built from another circuit (control source " + name + ")");
  for (const std::string& name : model.port_elements)
    if (!circuit.find_element(name))
      return Status::Error("port model: built from another circuit (element " + name + ")");
  PortModelStats st;
  StatusOr<Waveform> w = PortMarch(circuit, model, opt).run(&st);
  if (w.ok() && stats) {
    st.model_seconds = model.seconds;
    st.model = model.model.stats;
    st.ports = model.ports;
    st.modes = static_cast<int>(model.model.poles.size());
    *stats = st;
  }
  return w;
}

}  // namespace isolink
