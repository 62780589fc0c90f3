#include "netlists/traffic/command.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <optional>
#include <utility>

#include "base/hex.h"
#include "protocol/crc16.h"

namespace isolink::traffic {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& ch : out) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return out;
}

bool has_hex_prefix(std::string_view s) {
  return s.size() >= 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
}

// Decimal or 0x-prefixed hex, non-negative; nullopt when malformed or absurdly large.
std::optional<long> parse_number(std::string_view s) {
  int base = 10;
  if (has_hex_prefix(s)) {
    base = 16;
    s.remove_prefix(2);
  }
  if (s.empty() || s.size() > 9) return std::nullopt;
  long v = 0;
  for (char ch : s) {
    int d = base == 16 ? hex_digit(ch) : (ch >= '0' && ch <= '9' ? ch - '0' : -1);
    if (d < 0) return std::nullopt;
    v = v * base + d;
  }
  return v;
}

StatusOr<long> number_field(std::string_view kw, std::string_view key, std::string_view value,
                            long lo, long hi, std::string_view rule) {
  std::optional<long> v = parse_number(value);
  if (!v) {
    return Status::Error(
        fmt::format("{}: {}={} is not a number (decimal or 0x-prefixed hex)", kw, key, value));
  }
  if (*v < lo || *v > hi) {
    return Status::Error(fmt::format("{}: {}={} is out of range: {}", kw, key, value, rule));
  }
  return *v;
}

}  // namespace

std::vector<std::string_view> split_ws(std::string_view text) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    size_t j = i;
    while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
    if (j > i) out.push_back(text.substr(i, j - i));
    i = j;
  }
  return out;
}

StatusOr<std::vector<uint8_t>> parse_hex_bytes(std::string_view text, std::string_view field) {
  std::string_view digits = text;
  if (has_hex_prefix(digits)) digits.remove_prefix(2);
  if (digits.empty()) return Status::Error(fmt::format("{}='{}' has no hex digits", field, text));
  for (size_t i = 0; i < digits.size(); ++i) {
    if (hex_digit(digits[i]) < 0) {
      return Status::Error(fmt::format("{}={}: '{}' is not a hex digit", field, text, digits[i]));
    }
  }
  if (digits.size() % 2 != 0) {
    return Status::Error(
        fmt::format("{}={} has an odd number of hex digits ({}): each byte takes two", field, text,
                    digits.size()));
  }
  std::vector<uint8_t> out;
  out.reserve(digits.size() / 2);
  for (size_t i = 0; i < digits.size(); i += 2) {
    out.push_back(static_cast<uint8_t>(hex_digit(digits[i]) * 16 + hex_digit(digits[i + 1])));
  }
  return out;
}

Status validate_command(const Command& c) {
  const std::string_view kw = command_keyword(c.kind);
  if (has_device(c.kind) && (c.device < 0 || c.device > 63)) {
    return Status::Error(
        fmt::format("{}: dev={} is out of range: device addresses are 0-63", kw, c.device));
  }
  if (is_read(c.kind) && (c.read_bytes < 1 || c.read_bytes > 128)) {
    return Status::Error(
        fmt::format("{}: n={} is out of range: a read asks for 1-128 bytes", kw, c.read_bytes));
  }
  if (is_write(c.kind) && (c.data.empty() || c.data.size() > 8)) {
    return Status::Error(
        fmt::format("{}: data has {} bytes: a write carries 1-8 data bytes", kw, c.data.size()));
  }
  if (c.kind == CommandKind::kRaw && c.data.empty()) {
    return Status::Error("raw: no bytes given: expected hex bytes, e.g. 'raw 80 00 02 15 0B'");
  }
  return Status::Ok();
}

std::vector<uint8_t> encode_command(const Command& c) {
  std::vector<uint8_t> out;
  if (c.kind == CommandKind::kRaw) {
    out = c.data;
    if (c.crc) append_crc16(out);
    return out;
  }
  uint8_t init = init_byte_base(c.kind);
  if (is_write(c.kind)) init = static_cast<uint8_t>(init | ((c.data.size() - 1) & 0x07u));
  out.push_back(init);
  if (has_device(c.kind)) out.push_back(static_cast<uint8_t>(c.device));
  out.push_back(static_cast<uint8_t>(c.reg >> 8));
  out.push_back(static_cast<uint8_t>(c.reg & 0xFFu));
  if (is_read(c.kind)) {
    out.push_back(static_cast<uint8_t>(c.read_bytes - 1));
  } else {
    out.insert(out.end(), c.data.begin(), c.data.end());
  }
  append_crc16(out);
  return out;
}

StatusOr<Command> parse_command(std::string_view text) {
  std::vector<std::string_view> tokens = split_ws(text);
  if (tokens.empty()) {
    return Status::Error("empty command: expected e.g. 'stack-write reg=0x0100 data=02B778BC'");
  }
  const std::optional<CommandKind> found = command_kind_of(lower(tokens[0]));
  if (!found) {
    return Status::Error(fmt::format(
        "unknown command '{}': expected single-read, single-write, stack-read, stack-write, "
        "broadcast-read, broadcast-write, broadcast-write-reverse or raw",
        tokens[0]));
  }
  Command c;
  c.kind = *found;

  if (c.kind == CommandKind::kRaw) {
    for (size_t i = 1; i < tokens.size(); ++i) {
      if (lower(tokens[i]) == "nocrc") {
        c.crc = false;
        continue;
      }
      StatusOr<std::vector<uint8_t>> b = parse_hex_bytes(tokens[i], "raw byte");
      if (!b) return b.status();
      c.data.insert(c.data.end(), b->begin(), b->end());
    }
    Status s = validate_command(c);
    if (!s.ok()) return s;
    return c;
  }

  const std::string_view name = command_keyword(c.kind);
  std::vector<std::string_view> allowed;
  if (has_device(c.kind)) allowed.push_back("dev");
  allowed.push_back("reg");
  allowed.push_back(is_read(c.kind) ? "n" : "data");
  std::string allowed_list;
  for (std::string_view a : allowed)
    allowed_list += (allowed_list.empty() ? "" : ", ") + std::string(a);

  std::vector<std::string> seen;
  for (size_t i = 1; i < tokens.size(); ++i) {
    const std::string_view tok = tokens[i];
    const size_t eq = tok.find('=');
    if (eq == std::string_view::npos || eq == 0) {
      return Status::Error(
          fmt::format("{}: '{}' is not a key=value field (expected {})", name, tok, allowed_list));
    }
    const std::string key = lower(tok.substr(0, eq));
    const std::string_view value = tok.substr(eq + 1);
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      return Status::Error(
          fmt::format("{}: unknown field '{}' (expected {})", name, key, allowed_list));
    }
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
      return Status::Error(fmt::format("{}: field '{}' given twice", name, key));
    }
    seen.push_back(key);
    if (key == "dev") {
      StatusOr<long> v = number_field(name, key, value, 0, 63, "device addresses are 0-63");
      if (!v) return v.status();
      c.device = static_cast<int>(*v);
    } else if (key == "reg") {
      StatusOr<long> v =
          number_field(name, key, value, 0, 0xFFFF, "register addresses are 16 bits (0-0xFFFF)");
      if (!v) return v.status();
      c.reg = static_cast<uint16_t>(*v);
    } else if (key == "n") {
      StatusOr<long> v = number_field(name, key, value, 1, 128, "a read asks for 1-128 bytes");
      if (!v) return v.status();
      c.read_bytes = static_cast<int>(*v);
    } else {  // data
      StatusOr<std::vector<uint8_t>> b = parse_hex_bytes(value, "data");
      if (!b) return b.status().with_context(std::string(name));
      if (b->size() > 8) {
        return Status::Error(fmt::format("{}: data={} has {} bytes: a write carries 1-8 data bytes",
                                         name, value, b->size()));
      }
      c.data = std::move(*b);
    }
  }
  for (std::string_view a : allowed) {
    if (std::find(seen.begin(), seen.end(), a) == seen.end()) {
      return Status::Error(
          fmt::format("{}: missing field '{}=' (needs {})", name, a, allowed_list));
    }
  }
  Status s = validate_command(c);
  if (!s.ok()) return s;
  return c;
}

StatusOr<std::vector<uint8_t>> command_bytes(std::string_view text) {
  StatusOr<Command> c = parse_command(text);
  if (!c) return c.status();
  return encode_command(*c);
}

}  // namespace isolink::traffic
