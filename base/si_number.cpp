#include "base/si_number.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

namespace isolink {
namespace {

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}
bool is_alpha(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) != 0;
}
char to_lower(char c) {
  return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}

}  // namespace

std::optional<SiNumber> scan_si_number(std::string_view s, const SiOptions& opt) {
  std::size_t i = 0;
  const std::size_t n = s.size();
  char buf[64];
  std::size_t b = 0;
  auto put = [&](char c) {
    if (b < sizeof(buf) - 12) buf[b++] = c;
  };
  bool digits = false;
  int dropped_int_digits = 0;  // integer digits beyond the buffer (absurdly long numbers)
  while (i < n && is_digit(s[i])) {
    if (b < sizeof(buf) - 12)
      buf[b++] = s[i];
    else
      ++dropped_int_digits;
    ++i, digits = true;
  }
  if (i < n && s[i] == '.') {
    if (i + 1 < n && is_digit(s[i + 1])) {
      put('.');
      ++i;
      while (i < n && is_digit(s[i])) put(s[i++]);
      digits = true;
    } else if (digits) {
      ++i;  // "5." is 5
    }
  }
  if (!digits) return std::nullopt;
  long exponent = dropped_int_digits;
  // RKM notation (IEC 60062): the scale letter stands for the decimal point, "4k7" = 4.7e3,
  // "2r2" = 2.2 ('r': no scale), "1u5" = 1.5e-6. Only after plain integer digits.
  char rkm = 0;
  if (opt.scale && i + 1 < n && i > 0 && is_digit(s[i - 1]) && is_digit(s[i + 1]) &&
      std::string_view("fpnumkgtrFPNUMKGTR").find(s[i]) != std::string_view::npos &&
      s.substr(0, i).find('.') == std::string_view::npos) {
    rkm = to_lower(s[i++]);
    put('.');
    while (i < n && is_digit(s[i])) put(s[i++]);
  }
  if (!rkm && i < n && (s[i] == 'e' || s[i] == 'E')) {
    std::size_t j = i + 1;
    bool neg = false;
    if (j < n && (s[j] == '+' || s[j] == '-')) neg = s[j++] == '-';
    if (j < n && is_digit(s[j])) {
      long e = 0;
      while (j < n && is_digit(s[j])) {
        if (e < 100000) e = e * 10 + (s[j] - '0');
        ++j;
      }
      exponent += neg ? -e : e;
      i = j;
    } else {
      return std::nullopt;  // "1e", "1e+": an exponent with no digits is not a unit letter
    }
  }
  double scale = 1.0;
  if (rkm) {
    static constexpr std::string_view kLetters = "fpnumkgt";
    static constexpr int kExponents[] = {-15, -12, -9, -6, -3, 3, 9, 12};
    const std::size_t k = kLetters.find(rkm);
    if (k != std::string_view::npos) exponent += kExponents[k];
  } else if (opt.scale && i < n && is_alpha(s[i])) {
    auto starts = [&](const char* w) {
      for (std::size_t k = 0; w[k]; ++k)
        if (i + k >= n || to_lower(s[i + k]) != w[k]) return false;
      return true;
    };
    if (starts("meg")) {
      exponent += 6;
      i += 3;
    } else if (starts("mil")) {
      scale = 25.4e-6;
      i += 3;
    } else {
      static constexpr std::string_view kLetters = "fpnumkgt";
      static constexpr int kExponents[] = {-15, -12, -9, -6, -3, 3, 9, 12};
      const std::size_t k = kLetters.find(to_lower(s[i]));
      if (k != std::string_view::npos) {
        exponent += kExponents[k];
        ++i;
      }
    }
  }
  if (opt.unit_letters)
    while (i < n && is_alpha(s[i])) ++i;  // unit letters ("F", "ohm")
  if (exponent != 0) {
    auto r = std::to_chars(buf + b + 1, buf + sizeof(buf), exponent);
    buf[b] = 'e';
    b = static_cast<std::size_t>(r.ptr - buf);
  }
  double value = 0.0;
  if (std::from_chars(buf, buf + b, value).ec == std::errc::result_out_of_range)
    value = exponent > 0 ? HUGE_VAL : 0.0;
  return SiNumber{value * scale, i};
}

bool parse_si_number(std::string_view s, double& out, const SiOptions& opt) {
  bool neg = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    neg = s[0] == '-';
    s.remove_prefix(1);
  }
  auto r = scan_si_number(s, opt);
  if (!r || r->length != s.size()) return false;
  out = neg ? -r->value : r->value;
  return true;
}

}  // namespace isolink
