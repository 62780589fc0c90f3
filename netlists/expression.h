// Parameter expressions as ngspice writes them inside {...} or '...' and after .param NAME=.
//
//   ParamLookup lookup = [&](const std::string& name) -> std::optional<double> { ... };
//   StatusOr<double> v = evaluate_expression("sqrt(rx*2) + 1k", lookup,
//                                            [&](std::size_t off) { return line.loc(base + off);
//                                            });
//
// Grammar (lowest precedence first):
//   expr    := or ('?' expr ':' expr)?                 ternary, as ngspice
//   or      := and ('||' and)*                         logical values: 0 false, else true -> 1/0
//   and     := compare ('&&' compare)*
//   compare := sum (('==' | '!=' | '<' | '>' | '<=' | '>=') sum)*    ('=' too in a condition)
//   sum     := term (('+' | '-') term)*
//   term    := unary (('*' | '/') unary)*
//   unary   := ('-' | '+' | '!') unary | power
//   power   := primary (('^' | '**') unary)?          right-associative, -2^2 = -4
//   primary := NUMBER (SPICE suffixes: 1k, 2.2n, 10meg) | NAME | NAME '(' expr (',' expr)* ')'
//            | '(' expr ')'
// Names are case-insensitive; parameters shadow the constant pi. Functions: sqrt exp log ln
// (natural) log10 sin cos tan atan sinh cosh tanh abs min max pow floor ceil, and the user
// functions of .func (which shadow the built-in ones, as in ngspice).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"

namespace isolink::spice {

// Value of a parameter by lower-case name, nullopt when undefined.
using ParamLookup = std::function<std::optional<double>(const std::string& name)>;
// Source location of an offset in the expression text (for error carets).
using OffsetLoc = std::function<SourceLoc(std::size_t offset)>;

// A .func definition: `.func NAME(a, b) {body}`. The body sees its arguments, then the
// parameters of the scope that calls it.
struct UserFunction {
  std::vector<std::string> params;  // lower case
  std::string body;
  OffsetLoc where;  // location of an offset in body
};
// User function by lower-case name, nullptr when undefined.
using FunctionLookup = std::function<const UserFunction*(const std::string& name)>;

// Errors: syntax (unexpected character, unbalanced parentheses, missing operand), undefined
// parameter, unknown function or wrong argument count, division by zero, non-finite result;
// each at the offending character. A single '=' is an error ("equality is '=='"), except with
// `condition` (a .if / .elseif condition), where it is equality as ngspice reads it:
// `.elseif (select2 = 2)`; in the bodies of .func functions it stays an error.
StatusOr<double> evaluate_expression(std::string_view text, const ParamLookup& lookup,
                                     const OffsetLoc& where,
                                     const FunctionLookup& functions = nullptr,
                                     bool condition = false);

}  // namespace isolink::spice
