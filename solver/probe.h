// Probe: one output signal of a simulation: v(a), v(a,b) = V(a) - V(b), or i(name) for the
// branch current of a V source or an inductor (positive from n+ through the element to n-).
//
//   StatusOr<Probe> p = parse_probe(circuit, "v(rxp,rxn)");
//   double value = p->value(x);   // x: the full unknown vector, x[0] = ground = 0
// Units: V for v(...), A for i(...). A Probe holds unknown indices of the circuit it was parsed
// on (no reference to it): valid for that circuit, or one built from the same cards.
#pragma once

#include <string>
#include <string_view>

#include "solver/circuit.h"

namespace isolink {

struct Probe {
  std::string label;  // normalised text: lower case, no spaces, e.g. "v(rxp,rxn)"
  int a = 0;          // unknown index
  int b = 0;          // unknown index subtracted (0 = ground)
  double value(const double* x) const { return x[a] - x[b]; }
};

// Errors name the node or element that the circuit lacks.
StatusOr<Probe> parse_probe(const Circuit& circuit, std::string_view text);

}  // namespace isolink
