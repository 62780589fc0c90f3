#include "netlists/traffic/sequences.h"

#include <fmt/format.h>

#include <cctype>
#include <optional>

#include "netlists/traffic/patterns.h"
#include "protocol/crc16.h"

namespace isolink::traffic {

namespace {

// A decimal or 0x-prefixed hex integer, the whole text.
std::optional<long> parse_int(std::string_view s) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) s.remove_prefix(2), base = 16;
  if (s.empty() || s.size() > 8) return std::nullopt;
  long v = 0;
  for (char c : s) {
    const int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
                  : base == 16 && std::isxdigit(static_cast<unsigned char>(c))
                      ? std::tolower(static_cast<unsigned char>(c)) - 'a' + 10
                      : -1;
    if (d < 0) return std::nullopt;
    v = v * base + d;
  }
  return v;
}

}  // namespace

StatusOr<std::vector<std::string>> auto_address_commands(int devices) {
  if (devices < 2 || devices > kMaxStackDevices)
    return Status::Error(fmt::format(
        "auto-address: devices={} must be 2-{} (the base or bridge at address 0 and the stack)",
        devices, kMaxStackDevices));
  std::vector<std::string> out;
  for (int k = 0; k < 8; ++k)
    out.push_back(fmt::format("stack-write reg=0x{:04X} data=00", kRegOtpEccDataIn1 + k));
  out.push_back(fmt::format("broadcast-write reg=0x{:04X} data=01", kRegControl1));
  for (int a = 0; a < devices; ++a)
    out.push_back(fmt::format("broadcast-write reg=0x{:04X} data={:02X}", kRegDir0Addr, a));
  out.push_back(fmt::format("broadcast-write reg=0x{:04X} data=02", kRegCommCtrl));
  out.push_back(fmt::format("single-write dev={} reg=0x{:04X} data=03", devices - 1, kRegCommCtrl));
  for (int k = 0; k < 8; ++k)
    out.push_back(fmt::format("stack-read reg=0x{:04X} n=1", kRegOtpEccDataIn1 + k));
  return out;
}

StatusOr<std::vector<uint8_t>> response_frame(int device, uint16_t reg,
                                              const std::vector<uint8_t>& data) {
  if (device < 0 || device > 63)
    return Status::Error(fmt::format("response: device {} must be 0-63", device));
  if (data.empty() || data.size() > 128)
    return Status::Error(fmt::format("response: {} data bytes, must be 1-128", data.size()));
  std::vector<uint8_t> out;
  out.reserve(data.size() + 6);
  out.push_back(static_cast<uint8_t>(data.size() - 1));
  out.push_back(static_cast<uint8_t>(device));
  out.push_back(static_cast<uint8_t>(reg >> 8));
  out.push_back(static_cast<uint8_t>(reg & 0xFF));
  for (uint8_t d : data) out.push_back(d);
  append_crc16(out);
  return out;
}

StatusOr<std::vector<std::string>> auto_address_item(const std::vector<std::string_view>& fields) {
  const std::string_view f = fields.size() == 1 ? fields[0] : std::string_view();
  if (f.substr(0, 8) != "devices=")
    return Status::Error("auto-address: expected devices=N, e.g. 'auto-address devices=16'");
  const std::optional<long> n = parse_int(f.substr(8));
  if (!n || *n < 0 || *n > kMaxStackDevices)
    return Status::Error(
        fmt::format("auto-address: devices={} is not an integer of 2-64", f.substr(8)));
  return auto_address_commands(static_cast<int>(*n));
}

StatusOr<std::vector<std::vector<uint8_t>>> response_frames(
    const std::vector<std::string_view>& fields) {
  std::optional<long> reg, n, devices;
  long first = 1;
  for (std::string_view f : fields) {
    const size_t eq = f.find('=');
    const std::string key(f.substr(0, eq));
    const std::optional<long> v =
        eq == std::string_view::npos ? std::nullopt : parse_int(f.substr(eq + 1));
    if (!v)
      return Status::Error(fmt::format(
          "responses: '{}' is not a field: expected reg=R n=B devices=D [first=A] (integers, "
          "0x for hex)",
          f));
    if (key == "reg") {
      reg = v;
    } else if (key == "n") {
      n = v;
    } else if (key == "devices") {
      devices = v;
    } else if (key == "first") {
      first = *v;
    } else {
      return Status::Error(fmt::format(
          "responses: unknown field '{}' (expected reg=R n=B devices=D [first=A])", key));
    }
  }
  if (!reg || !n || !devices)
    return Status::Error("responses: expected reg=R n=B devices=D [first=A]");
  if (*reg > 0xFFFF) return Status::Error(fmt::format("responses: reg={} must be 0-0xFFFF", *reg));
  if (*n < 1 || *n > 128) return Status::Error(fmt::format("responses: n={} must be 1-128", *n));
  if (*devices < 1 || first < 0 || first + *devices > kMaxStackDevices)
    return Status::Error(
        fmt::format("responses: devices={} first={}: the addresses must lie in 0-63 (devices >= 1)",
                    *devices, first));
  const std::vector<uint8_t> data = pattern_bytes(Pattern::kPrbs7, static_cast<size_t>(*n));
  std::vector<std::vector<uint8_t>> out;
  for (long d = first; d < first + *devices; ++d) {
    StatusOr<std::vector<uint8_t>> f =
        response_frame(static_cast<int>(d), static_cast<uint16_t>(*reg), data);
    if (!f) return f.status();
    out.push_back(std::move(*f));
  }
  return out;
}

}  // namespace isolink::traffic
