#include "solver/elements/card_values.h"

#include <fmt/format.h>

#include <cmath>

namespace isolink {

Status check_params(const Card& card, std::span<const ParamSpec> table) {
  for (const auto& [key, value] : card.params) {
    bool known = false;
    std::string names;
    for (const auto& p : table) {
      known = known || key == p.name;
      names += names.empty() ? p.name : std::string(", ") + p.name;
    }
    if (!known)
      return error_at(value.loc, fmt::format("unknown parameter '{}' for {} (known: {})", key,
                                             card.name, names.empty() ? "none" : names));
  }
  return Status::Ok();
}

SourceLoc value_loc(const Card& card, const std::string& name, int index) {
  if (const CardArg* p = card.param(name)) return p->loc;
  if (index >= 0 && index < static_cast<int>(card.args.size())) return card.args[index].loc;
  return card.loc;
}

StatusOr<double> card_value(const Card& card, std::span<const ParamSpec> table,
                            const std::string& name, int index) {
  const CardArg* arg = card.param(name);
  if (!arg && index >= 0 && index < static_cast<int>(card.args.size())) arg = &card.args[index];
  if (arg) {
    if (arg->kind != CardArg::Kind::Number)
      return error_at(arg->loc, fmt::format("expected a number for {} of {}, found '{}'", name,
                                            card.name, arg->word));
    return arg->number;
  }
  for (const auto& p : table)
    if (name == p.name && !std::isnan(p.default_value)) return p.default_value;
  return error_at(card.loc, fmt::format("missing value {} for {}", name, card.name));
}

Status require_positive(const Card& card, const std::string& name, int index, double value,
                        const char* what) {
  if (value > 0 && std::isfinite(value)) return Status::Ok();
  return error_at(value_loc(card, name, index),
                  fmt::format("{} of {} must be positive, got {:g}", what, card.name, value));
}

}  // namespace isolink
