#include "netlists/link/cards.h"

#include <fmt/format.h>

#include <cmath>

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

std::string format_si(double v, const char* unit) {
  static const std::pair<double, const char*> kPrefixes[] = {
      {1e9, "G"},  {1e6, "M"},  {1e3, "k"},   {1, ""},     {1e-3, "m"},
      {1e-6, "u"}, {1e-9, "n"}, {1e-12, "p"}, {1e-15, "f"}};
  if (v == 0 || !std::isfinite(v)) return fmt::format("{:g} {}", v, unit);
  for (const auto& [scale, prefix] : kPrefixes)
    if (std::fabs(v) >= scale * 0.9999995)
      return fmt::format("{:.4g} {}{}", v / scale, prefix, unit);
  return fmt::format("{:g} {}", v, unit);
}

Status add_cards(Circuit& circuit, const std::vector<Card>& cards) {
  for (const Card& c : cards)
    if (Status s = circuit.add(c); !s.ok())
      return s.with_context(fmt::format("element {}", c.name));
  return Status::Ok();
}

}  // namespace isolink::link
