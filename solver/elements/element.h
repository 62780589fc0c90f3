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
// The circuits isolink targets are linear and time-invariant: G and C never change during a run.
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
  // False for an element whose stamps change with time or with the solution (a switch, a diode):
  // the LTI engine refuses a circuit holding one. Every kind in the registry today is LTI.
  virtual bool linear_time_invariant() const { return true; }
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
};

// All element kinds, in letter order.
std::span<const ElementKind> element_kinds();
// The kinds and their parameters as a Markdown table (the README's element reference and
// `isolink elements --markdown`).
std::string element_reference_markdown();
// nullptr when no kind has that letter (any case).
const ElementKind* find_element_kind(char letter);

}  // namespace isolink
