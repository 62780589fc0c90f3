// The one hex formatter and parser for byte strings.
//
// Usage:
//   std::string s = to_hex(bytes);                                  // "80 00 02" (upper case)
//   StatusOr<std::vector<uint8_t>> b = parse_hex_bytes("0x80,0x00");  // {0x80, 0x00}
//   int d = hex_digit('b');                                         // 11 (-1 when not hex)
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink {

// "80 00 02": two upper-case digits per byte, separated by sep.
std::string to_hex(std::span<const uint8_t> bytes, std::string_view sep = " ");
// The value of one hex digit (either case), or -1.
int hex_digit(char c);
// Accepts "80 00 02", "0x80,0x00", "800002" (tokens split at blanks , : ;); a token of more
// than two digits is a run of whole bytes. An error names the offending text.
StatusOr<std::vector<uint8_t>> parse_hex_bytes(std::string_view text);

}  // namespace isolink
