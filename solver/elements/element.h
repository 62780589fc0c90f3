// Element: one circuit element kind's behaviour in modified nodal analysis (MNA).
//
// Lifecycle (driven by Circuit and the engines, never by users of a kind):
//   1. parse:   ElementKind::parse(card) -> Element, values checked, nodes still names.
//   2. connect: Circuit maps node names to unknown indices (0 = ground) and hands out branch
//               unknowns (branch_count()); link() resolves references to other elements (K -> L),
//               then check() tests what needs them all linked.
//   3. stamp:   stamp(m) writes its constant G (conductance) and C (d/dt) entries by unknown
//               index through an MnaStamp (solver/mna.h), twice: once to declare the pattern,
//               once to add the values. Entries in the ground row or column are dropped, so
//               stamps never test for ground. The element keeps nothing of it (no slots).
//   4. excite:  stamp_rhs(t, b) adds the excitation at time t into b on every step.
// After Circuit::finalize the engines only read an element (const), except bind_time: run_transient
// applies it (it takes a Circuit&), the LTI engine's caller applies it before
// LtiResponses::compute.
//   5. load:    nonlinear elements (the diode) also have nonlinear ports: two-terminal branches
//               whose current i(v) and charge q(v) depend on the branch voltage v = x[p] - x[n].
//               The engines' Newton iteration (solver/newton.h) evaluates each port at every
//               iteration (eval_port), limits the voltage step (limit_port) and stamps the
//               linearised current and charge itself; stamp() declares the port's four entries.
// The linear part of a circuit is time-invariant: G and C never change during a run; only the
// nonlinear ports' linearisation does, and it is added on top of them.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"
#include "solver/card.h"

namespace isolink {

class Circuit;
class MnaStamp;
class SourceFunction;

// How an element joins two nodes at DC, for the topology checks before the operating point.
// Inductive: an inductor, a short at DC; one that would close a loop of voltage sources and
// inductors is opened instead (its current starts at 0, as ngspice's operating point gives).
enum class DcLink { Conductive, VoltageDefining, Inductive, CurrentSource };
struct DcEdge {
  int a, b;
  DcLink link;
};

// One nonlinear port: a two-terminal branch from unknown p to unknown n (0 = ground). A
// controlled port (the switch) also depends on the control voltage x[cp] - x[cn], which draws no
// current and enters no stamp: its current's derivative with respect to it is 0.
struct NonlinearPort {
  int p = 0, n = 0;
  bool controlled = false;
  int cp = 0, cn = 0;
};
// A port evaluated at branch voltage v: the current from p through the element to n (A), its
// derivative (S), the charge stored between p and n (C) and its derivative (F).
struct PortEval {
  double i = 0, g = 0, q = 0, c = 0;
};

class Element {
 public:
  Element(std::string name, SourceLoc loc) : name_(std::move(name)), loc_(std::move(loc)) {}
  virtual ~Element() = default;

  const std::string& name() const { return name_; }
  const SourceLoc& loc() const { return loc_; }
  const std::vector<std::string>& node_names() const { return node_names_; }
  const std::vector<int>& nodes() const { return nodes_; }
  const std::vector<int>& branches() const { return branches_; }

  // Number of branch-current unknowns this element adds (V and L: 1).
  virtual int branch_count() const { return 0; }
  // True when the branch current is a state (inductor): the step control watches its error.
  virtual bool branch_is_state() const { return false; }
  // Resolves references to other elements once every element is connected.
  virtual Status link(const Circuit& circuit) { return Status::Ok(); }
  // Checks that need every element linked (K: the coupled group's inductance matrix).
  virtual Status check(const Circuit& circuit) const { return Status::Ok(); }
  // Constant G and C entries: m.g(row, col, value), m.c(row, col, value), unknown indices. The
  // same calls, in the same order, every time (the first call declares the pattern).
  virtual void stamp(MnaStamp& m) const = 0;
  // Excitation at time t into b (b[0] is the ground trash entry).
  virtual void stamp_rhs(double t, double* b) const {}
  // True when stamp_rhs adds anything (sources): the engines call stamp_rhs on these only.
  virtual bool has_excitation() const { return false; }
  // Sources: the time dependence (nullptr for elements without one) and the excitation per unit
  // of it, so that stamp_rhs(t, b) adds source_function()->value(t) * (what stamp_unit(b) adds).
  // The LTI engine (solver/lti.h) superposes responses to these unit excitations.
  virtual const SourceFunction* source_function() const { return nullptr; }
  virtual void stamp_unit(double* b) const {}
  // False for an element whose stamps change with time or with the solution (a diode): the LTI
  // engine refuses a circuit holding one.
  virtual bool linear_time_invariant() const { return true; }
  // Nonlinear ports (solver/newton.h); none for linear kinds. The ports' unknowns are known after
  // Circuit::finalize.
  virtual int nonlinear_port_count() const { return 0; }
  virtual NonlinearPort nonlinear_port(int k) const { return {}; }
  // Current and charge of port k at branch voltage v. Must be finite for any finite v.
  virtual PortEval eval_port(int k, double v) const { return {}; }
  // A controlled port's current and charge at branch voltage v and control voltage vc.
  virtual PortEval eval_controlled_port(int k, double v, double vc) const {
    return eval_port(k, v);
  }
  // A controlled port's discrete state at control voltage vc (the switch: on). The transient
  // takes a step where one changes as ending at a breakpoint: the change is a corner of the
  // solution, not an error of the formula.
  virtual bool control_state(int k, double vc) const { return false; }
  // Newton's voltage step limit (SPICE's pnjlim): the voltage to evaluate at, given the new
  // iterate v_new and the last evaluated v_old; *limited = true when it changed v_new.
  virtual double limit_port(int k, double v_new, double v_old, bool* limited) const {
    *limited = false;
    return v_new;
  }
  // The branch voltage the DC Newton iteration starts from (SPICE: vcrit, or 0 for "off").
  virtual double port_start_voltage(int k) const { return 0.0; }
  // Internal nodes the element adds (a diode's series resistance: "d1#internal"), named in full;
  // Circuit::add appends them to the card's nodes, so nodes() lists them after the card's.
  virtual std::vector<std::string> internal_node_names() const { return {}; }
  // Resolves time defaults that depend on the analysis (ngspice: PULSE TR defaults to TSTEP).
  virtual void bind_time(double tstep, double tstop) {}
  // Times in (0, tstop] where the excitation has a corner.
  virtual void breakpoints(double tstop, std::vector<double>& out) const {}
  // DC connectivity for the topology checks.
  virtual void dc_edges(std::vector<DcEdge>& out) const {}
  // .tran ... UIC: the element's initial condition (ic=). uic_state writes a state unknown of
  // x0 (inductor current); uic_charge adds, for each node, the charge its ic= puts on the
  // node beyond C x0 (capacitor: c (ic - (v+ - v-)) at n+, the negative at n-).
  virtual void uic_state(double* x0) const {}
  virtual void uic_charge(const double* x0, double* dq) const {}

  // Called by Circuit while connecting.
  void set_node_names(std::vector<std::string> names) { node_names_ = std::move(names); }
  void set_nodes(std::vector<int> nodes) { nodes_ = std::move(nodes); }
  void set_branches(std::vector<int> branches) { branches_ = std::move(branches); }

 protected:
  std::string name_;
  SourceLoc loc_;
  std::vector<std::string> node_names_;
  std::vector<int> nodes_;
  std::vector<int> branches_;
};

// One row of an element kind's parameter table: feeds the parser, --help and the README.
struct ParamSpec {
  const char* name;       // lower case, as written in key=value or as the positional value
  double default_value;   // NaN when required (or optional, below)
  const char* unit;       // SI unit symbol, "" when dimensionless
  const char* doc;        // one line
  bool optional = false;  // default NaN and optional: absent means not given ("none" in docs)
};

// One element kind: the registry in elements/registry.cpp lists them all explicitly.
struct ElementKind {
  char letter;        // SPICE letter, lower case
  const char* name;   // "resistor"
  const char* usage;  // "Rname n+ n- value [key=value...]"
  int node_count;     // node tokens after the name
  int ref_count;      // element-name tokens after the nodes (K: 2)
  std::span<const ParamSpec> params;
  StatusOr<std::unique_ptr<Element>> (*parse)(const Card& card);
  // Kinds that name a .model (D): the model type the card must name ("d"), and the model's
  // parameter table (the reader checks names and numbers against it). nullptr / empty: none.
  const char* model_type = nullptr;
  std::span<const ParamSpec> model_params = {};
};

// All element kinds, in letter order.
std::span<const ElementKind> element_kinds();
// The kinds and their parameters as a Markdown table (the README's element reference and
// `isolink elements --markdown`).
std::string element_reference_markdown();
// nullptr when no kind has that letter (any case).
const ElementKind* find_element_kind(char letter);

}  // namespace isolink
