#include "netlists/link/cards.h"

#include <fmt/format.h>

namespace isolink::link {

Card make_card(char letter, std::string name, std::vector<std::string> nodes,
               std::vector<CardArg> args, std::vector<std::string> refs) {
  Card c;
  c.letter = letter;
  c.name = std::move(name);
  c.nodes = std::move(nodes);
  c.node_locs.resize(c.nodes.size());
  c.refs = std::move(refs);
  c.ref_locs.resize(c.refs.size());
  c.args = std::move(args);
  return c;
}

CardArg number_arg(double v) {
  CardArg a;
  a.number = v;
  return a;
}

Status add_cards(Circuit& circuit, const std::vector<Card>& cards) {
  for (const Card& c : cards)
    if (Status s = circuit.add(c); !s.ok()) return s.with_context(fmt::format("element {}", c.name));
  return Status::Ok();
}

}  // namespace isolink::link
