#include "base/hex.h"

namespace isolink {

std::string to_hex(std::span<const uint8_t> bytes, std::string_view sep) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s;
  s.reserve(bytes.size() * (2 + sep.size()));
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (i) s += sep;
    s += kDigits[bytes[i] >> 4];
    s += kDigits[bytes[i] & 15];
  }
  return s;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

StatusOr<std::vector<uint8_t>> parse_hex_bytes(std::string_view text) {
  std::vector<uint8_t> out;
  size_t i = 0;
  auto is_sep = [](char c) { return c == ' ' || c == ',' || c == ':' || c == '\t' || c == ';'; };
  while (i < text.size()) {
    if (is_sep(text[i])) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < text.size() && !is_sep(text[j])) ++j;
    const std::string_view tok = text.substr(i, j - i);
    std::string_view digits = tok;
    if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
      digits.remove_prefix(2);
    bool hex = !digits.empty();
    for (char c : digits) hex = hex && hex_digit(c) >= 0;
    if (!hex || (digits.size() > 2 && digits.size() % 2 != 0))
      return Status::Error("'" + std::string(tok) +
                           "' is not a hex byte (expected e.g. \"80 00 02\")");
    if (digits.size() <= 2) {
      int v = 0;
      for (char c : digits) v = v * 16 + hex_digit(c);
      out.push_back(static_cast<uint8_t>(v));
    } else {
      for (size_t k = 0; k < digits.size(); k += 2)
        out.push_back(static_cast<uint8_t>(hex_digit(digits[k]) * 16 + hex_digit(digits[k + 1])));
    }
    i = j;
  }
  if (out.empty()) return Status::Error("no hex bytes in '" + std::string(text) + "'");
  return out;
}

}  // namespace isolink
