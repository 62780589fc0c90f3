// Builds Cards by hand for the solver tests (the SPICE reader has its own tests).
#pragma once

#include <string>
#include <vector>

#include "solver/card.h"
#include "solver/circuit.h"

namespace isolink::testing {

inline CardArg num(double v) {
  CardArg a;
  a.number = v;
  return a;
}
inline CardArg word(std::string w) {
  CardArg a;
  a.kind = CardArg::Kind::Word;
  a.word = std::move(w);
  return a;
}
inline CardArg call(std::string f, std::vector<double> v) {
  CardArg a;
  a.kind = CardArg::Kind::Call;
  a.word = std::move(f);
  a.call = std::move(v);
  return a;
}
inline Card card(std::string name, std::vector<std::string> nodes, std::vector<CardArg> args,
                 std::vector<std::string> refs = {}) {
  Card c;
  c.letter = name[0];
  c.name = std::move(name);
  c.nodes = std::move(nodes);
  c.node_locs.resize(c.nodes.size());
  c.refs = std::move(refs);
  c.ref_locs.resize(c.refs.size());
  c.args = std::move(args);
  return c;
}
// Adds every card, finalizes; returns the first error's message (empty when fine).
inline std::string build(Circuit& circuit, const std::vector<Card>& cards) {
  for (const auto& c : cards)
    if (Status s = circuit.add(c); !s.ok()) return s.message();
  Status s = circuit.finalize();
  return s.ok() ? "" : s.message();
}

}  // namespace isolink::testing
