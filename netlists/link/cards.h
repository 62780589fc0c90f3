// Cards built in code: the link builders (pins, board networks, parts, cable) append ordinary
// element Cards to a list, which becomes a Netlist (export-spice) or a Circuit (simulation).
//
//   std::vector<Card> cards;
//   cards.push_back(make_card('r', "rterm", {"lp", "ln"}, {number_arg(1e3)}));
//   Circuit c;  if (Status s = add_cards(c, cards); !s.ok()) return s;
#pragma once

#include <string>
#include <vector>

#include "solver/card.h"
#include "solver/circuit.h"

namespace isolink::link {

// A card with no source location (node_locs/ref_locs sized to match).
Card make_card(char letter, std::string name, std::vector<std::string> nodes,
               std::vector<CardArg> args, std::vector<std::string> refs = {});
// A positional number argument.
CardArg number_arg(double v);
// "2.2 nF", "49 ohm", "260 uH": 4 significant digits with an SI prefix, for reports.
std::string format_si(double v, const char* unit);
// Adds every card to the circuit; the first failure names the card.
Status add_cards(Circuit& circuit, const std::vector<Card>& cards);

}  // namespace isolink::link
