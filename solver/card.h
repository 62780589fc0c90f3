// Card: one flattened element instance as the netlist layer hands it to the solver.
//
// The SPICE reader (netlists/) resolves includes, parameters, expressions and subcircuits, then
// gives each element as a Card: names and nodes already hierarchical ("x1.r3", "x1.mid"), every
// value already a number. Element kinds (solver/elements/) turn a Card into an Element, checking
// their own values. Nothing here knows SPICE syntax.
//   R1 a b 49              -> letter 'r', nodes {a, b}, args {49}
//   V1 p 0 PULSE(0 5 1n)   -> letter 'v', args {Call "pulse" [0, 5, 1e-9]}
//   V2 p 0 DC 2.5          -> args {Word "dc", 2.5}
//   K1 L1 L2 0.99          -> refs {l1, l2}, args {0.99}
//   C1 a b 1n ic=0         -> args {1e-9}, params {ic: 0}
//   D1 a k dclamp 2 off    -> model {dclamp: D(...)}, args {2, Word "off"}
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "base/source_loc.h"

namespace isolink {

struct CardArg {
  enum class Kind { Number, Word, Call };
  Kind kind = Kind::Number;
  double number = 0.0;       // Kind::Number
  std::string word;          // Kind::Word (lower case), or the function name of Kind::Call
  std::vector<double> call;  // Kind::Call arguments, e.g. pwl(t1 v1 t2 v2 ...)
  SourceLoc loc;
};

// A .model card as the netlist layer resolved it: the model's name and type ("d"), and its
// parameters with their values already numbers (expressions and .param resolved) and locations.
//   .model DCLAMP D(IS=1e-14 BV=27 CJO=12p)  -> name "dclamp", type "d", params {is, bv, cjo}
struct CardModel {
  std::string name;                                     // lower case
  std::string type;                                     // lower case ("d")
  SourceLoc loc;                                        // the model's name on its .model card
  std::vector<std::pair<std::string, CardArg>> params;  // keys lower case, in card order

  const CardArg* param(const std::string& key) const {
    for (const auto& [k, v] : params)
      if (k == key) return &v;
    return nullptr;
  }
};

struct Card {
  char letter = 0;                   // element kind letter, lower case ('r', 'c', ...)
  std::string name;                  // full hierarchical name, lower case ("x1.r3")
  SourceLoc loc;                     // where the element's name starts
  std::vector<std::string> nodes;    // node names, lower case, "0" is ground
  std::vector<SourceLoc> node_locs;  // one per node
  std::vector<std::string> refs;     // other elements named by this one (K: two inductors)
  std::vector<SourceLoc> ref_locs;   // one per ref
  std::vector<CardArg> args;         // positional values after nodes and refs
  std::vector<std::pair<std::string, CardArg>> params;  // key=value pairs, keys lower case
  // Kinds that take a model (D): the .model the card names, resolved by the reader; else empty.
  std::shared_ptr<const CardModel> model;
  SourceLoc model_loc;  // where the card names its model

  const CardArg* param(const std::string& key) const {
    for (const auto& [k, v] : params)
      if (k == key) return &v;
    return nullptr;
  }
};

// ngspice's flattened names: "r.x1.r3" is element "x1.r3" of kind r (as spice_writer writes
// hierarchical names, as K cards name such inductors, "l.x1.l3", and as ngspice names probes,
// "i(v.x1.vm)"); any other name comes back unchanged.
inline std::string unflatten_name(const std::string& name) {
  if (name.size() > 2 && name[1] == '.') {
    const std::string rest = name.substr(2);
    const std::size_t dot = rest.rfind('.');
    if (dot != std::string::npos && dot + 1 < rest.size() && rest[dot + 1] == name[0]) return rest;
  }
  return name;
}

}  // namespace isolink
