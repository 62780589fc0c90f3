// Circuit: nodes and elements, connected into MNA unknowns.
//
// Lifecycle:
//   Circuit c;
//   for (const Card& card : netlist.cards) if (Status s = c.add(card); !s.ok()) return s;
//   if (Status s = c.finalize(); !s.ok()) return s;   // unknowns, links, DC topology checks
//   for (auto& w : c.warnings()) print(w);             // e.g. nodes tied for lack of a DC path
// Unknown 0 is ground; 1..node_count()-1 are node voltages (V); then one per branch current (A).
//
// Ownership: the Circuit owns its elements. After finalize() the engines only read it
// (`const Circuit&`: MnaSystem, AcAnalysis, LtiResponses, the reduced model), except
// run_transient and the LTI engine's caller, which bind the sources' time defaults
// (Element::bind_time). LtiResponses and AcAnalysis keep pointers into the circuit: it must
// outlive them. Probes hold unknown indices of this circuit only.
// Errors: add() names the card's location (unknown kind, bad value, duplicate name, added after
// finalize); finalize() names the element (a reference to a missing inductor, a loop of voltage
// sources and inductors, a current source into a node without a DC path).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "solver/elements/element.h"

namespace isolink {

class Circuit {
 public:
  // Conductance (S) that ties a node with no DC path to ground (documented in the README).
  static constexpr double kFloatingTie = 1e-12;

  // Parses the card with its element kind and adds it; duplicate names are an error.
  Status add(const Card& card);
  // Adds an element built elsewhere; its node_names() must be set.
  Status add(std::unique_ptr<Element> element);
  // Numbers unknowns, links references, checks DC topology; call once after the last add.
  Status finalize();

  int unknown_count() const { return unknowns_; }                          // without ground
  int node_count() const { return static_cast<int>(node_names_.size()); }  // with ground
  // Unknown index of a node name (lower case), -1 if absent; "0" and "gnd" give 0.
  int find_node(std::string_view name) const;
  const Element* find_element(std::string_view name) const;
  // "node rxp" or "current of l1".
  std::string unknown_name(int unknown) const;
  bool unknown_is_state(int unknown) const { return is_state_[unknown]; }
  bool unknown_is_node(int unknown) const { return unknown < node_count(); }
  const std::vector<std::unique_ptr<Element>>& elements() const { return elements_; }
  std::vector<std::unique_ptr<Element>>& elements() { return elements_; }
  // Nodes tied to ground through kFloatingTie because nothing else gives them a DC path.
  const std::vector<int>& floating_nodes() const { return floating_; }
  // Inductor branch unknowns held at 0 A in the DC operating point because the inductor closes
  // a loop of voltage sources and inductors (a warning names them).
  const std::vector<int>& dc_open_branches() const { return dc_open_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  int intern_node(const std::string& name);

  std::vector<std::unique_ptr<Element>> elements_;
  std::unordered_map<std::string, size_t> element_index_;
  std::vector<std::string> node_names_{"0"};
  std::unordered_map<std::string, int> node_index_{{"0", 0}, {"gnd", 0}};
  std::vector<std::string> branch_names_;  // per branch unknown: element name
  std::vector<bool> is_state_;
  std::vector<int> floating_;
  std::vector<int> dc_open_;
  std::vector<std::string> warnings_;
  int unknowns_ = 0;
  bool finalized_ = false;
};

}  // namespace isolink
