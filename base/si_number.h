// The one SPICE / SI number scanner: "2.2nF", "10Meg", "4k7", "1e-9", "5mil".
//
// Usage:
//   std::optional<SiNumber> n = scan_si_number("2.2nF*3");  // n->value 2.2e-9, n->length 5
//   double v; bool ok = parse_si_number("-4k7", v);        // v == -4700
//   SiOptions bare{.scale = false, .unit_letters = false};   // "12m" reads 12, stops at "m"
// Every reader of numbers with SI suffixes goes through here (netlists, link YAML, rule sets,
// traffic times); each caller keeps its own rule for what may follow (a unit, nothing, ...).
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

namespace isolink {

struct SiOptions {
  // Scale suffixes f p n u m k g t meg mil (any case; "m" is milli, "meg" mega, "mil" 25.4e-6)
  // and RKM notation (IEC 60062: the scale letter is the decimal point, "4k7" = 4700,
  // "2r2" = 2.2, "1u5" = 1.5e-6). Off: the number ends before the first letter ("12m" -> 12).
  bool scale = true;
  // Letters after the scale suffix are a unit and are consumed ("2.2nF", "1kohm", "10Megs").
  // Off: scanning stops after the scale suffix, so the caller can check the unit itself.
  bool unit_letters = true;
};

struct SiNumber {
  double value;        // +inf when it overflows, 0 when it underflows
  std::size_t length;  // characters used
};

// Scans an unsigned number at the start of s: digits, optional fraction and exponent, then what
// opt allows. nullopt when s does not start with a digit or '.' followed by a digit, or when an
// 'e' after the mantissa has no exponent digits ("1e" is refused, not read as 1 with a unit).
// The decimal text is converted once ("3.8u" is the double nearest 3.8e-6, not 3.8 * 1e-6).
std::optional<SiNumber> scan_si_number(std::string_view s, const SiOptions& opt = {});

// True when all of s, with an optional leading sign, is one number (no blanks).
bool parse_si_number(std::string_view s, double& out, const SiOptions& opt = {});

}  // namespace isolink
