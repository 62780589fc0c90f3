// Helpers shared by the element kinds to read values from a Card against a parameter table.
//
//   if (Status s = check_params(card, kParams); !s.ok()) return s;
//   StatusOr<double> r = required_value(card, kParams, "r", 0);  // positional 0 or r=
#pragma once

#include <span>
#include <string>

#include "solver/card.h"
#include "solver/elements/element.h"

namespace isolink {

// Error for key=value params whose key is not in the table.
Status check_params(const Card& card, std::span<const ParamSpec> table);
// The value of `name`: key=value wins, else positional arg `index` (-1: none), else the table
// default; error when the value is missing (default NaN) or not a number.
StatusOr<double> card_value(const Card& card, std::span<const ParamSpec> table,
                            const std::string& name, int index);
// Error unless value > 0, pointing at where the value was written.
Status require_positive(const Card& card, const std::string& name, int index, double value,
                        const char* what);
// Location of the value `name` (param or positional), else the card's.
SourceLoc value_loc(const Card& card, const std::string& name, int index);

}  // namespace isolink
