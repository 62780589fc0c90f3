// UTF-8 validation for text that reaches JSON (nlohmann-json throws on invalid UTF-8) or a file
// name: names, keys and values read from YAML files.
//
//   if (size_t at = invalid_utf8_at(text); at != std::string::npos) ... error at byte `at`
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace isolink {

// The offset of the first byte that does not belong to a well-formed UTF-8 sequence (overlong
// forms, surrogates and code points above U+10FFFF count as malformed), or npos.
size_t invalid_utf8_at(std::string_view s);

}  // namespace isolink
