#include "eye/commands.h"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "base/hex.h"

namespace isolink::eye {
namespace {

using json = nlohmann::ordered_json;

// What a flag says about a command, as the end of "command N ...".
const char* flag_words(FrameFlag f) {
  switch (f) {
    case FrameFlag::kBadCrc:
      return "has a bad CRC";
    case FrameFlag::kTruncated:
      return "is truncated";
    case FrameFlag::kLength:
      return "has a byte count that disagrees with its init byte";
    case FrameFlag::kUndecoded:
      return "holds a byte that did not decode";
    case FrameFlag::kUnknownInit:
      return "has an init byte that names no request type";
    case FrameFlag::kReserved:
      return "sets reserved init-byte bits";
    case FrameFlag::kRange:
      return "has a device address or read count out of range";
  }
  return "is malformed";
}

// Malformed frames the sender is to blame for (not those the record's end cut).
std::vector<size_t> malformed(std::span<const ParsedFrame> cs) {
  std::vector<size_t> out;
  for (size_t i = 0; i < cs.size(); ++i)
    if (!cs[i].ok() && !cs[i].cut_by_record) out.push_back(i);
  return out;
}

}  // namespace

std::vector<TimedByte> timed_bytes(const CheckResult& r) {
  std::vector<TimedByte> out;
  out.reserve(r.frames.size());
  for (const FrameResult& f : r.frames) {
    TimedByte b;
    b.start_s = f.start;
    b.end_s = f.last_pulse < r.pulses.size() ? r.pulses[f.last_pulse].b : f.start;
    b.value = f.byte;
    out.push_back(b);
  }
  return out;
}

std::vector<ParsedFrame> parse_commands(const CheckResult& r, double max_idle_s) {
  if (r.tone) return {};
  FrameSplitOptions opt;
  opt.max_idle_s = max_idle_s;
  opt.record_begin_s = r.t_begin;
  opt.record_end_s = r.t_end;
  const std::vector<TimedByte> bytes = timed_bytes(r);
  return parse_frames(bytes, opt);
}

json commands_json(std::span<const ParsedFrame> commands) {
  json out = json::array();
  for (const ParsedFrame& c : commands) {
    if (out.size() == kMaxJsonPulses) break;
    json flags = json::array();
    for (FrameFlag f : c.flags) flags.push_back(flag_name(f));
    auto opt_int = [](const auto& x) { return x ? json(*x) : json(nullptr); };
    auto opt_crc = [](const std::optional<uint16_t>& x) {
      return x ? json(crc_wire_hex(*x)) : json(nullptr);
    };
    out.push_back({{"start_s", c.start_s},
                   {"end_s", c.end_s},
                   {"kind", c.kind_name()},
                   {"device", opt_int(c.device)},
                   {"register", c.reg ? json(fmt::format("0x{:04X}", *c.reg)) : json(nullptr)},
                   {"data", to_hex(c.data)},
                   {"read_bytes", opt_int(c.read_bytes)},
                   {"crc", opt_crc(c.crc)},
                   {"crc_expected", opt_crc(c.crc_expected)},
                   {"crc_ok", c.crc_ok},
                   {"flags", std::move(flags)},
                   {"ok", c.ok()},
                   {"cut_by_record", c.cut_by_record},
                   {"at_record_start", c.at_record_start},
                   {"bytes", to_hex(c.bytes)},
                   {"first_frame", c.first_byte},
                   {"frame_count", c.byte_count},
                   {"text", c.text}});
  }
  return out;
}

void set_commands_json(const CheckResult& r, json& j) {
  j["commands"] = commands_json(r.commands);
  j["commands_omitted"] = r.commands.size() - std::min(r.commands.size(), kMaxJsonPulses);
  const std::string note = commands_note(r);
  j["commands_note"] = note.empty() ? json(nullptr) : json(note);
}

std::string commands_text(std::span<const ParsedFrame> commands) {
  if (commands.empty()) return "";
  const size_t bad = static_cast<size_t>(std::count_if(
      commands.begin(), commands.end(), [](const ParsedFrame& c) { return !c.ok(); }));
  std::string out = fmt::format("commands ({}, {} malformed):\n", commands.size(), bad);
  constexpr size_t kShown = 20;  // the JSON has them all
  for (size_t i = 0; i < std::min(commands.size(), kShown); ++i)
    out += fmt::format("  {} at {:.4f} us: {}\n", i, commands[i].start_s * 1e6, commands[i].text);
  if (commands.size() > kShown) out += fmt::format("  ... and {} more\n", commands.size() - kShown);
  return out;
}

std::string commands_note(const CheckResult& r) {
  const std::vector<size_t> bad = malformed(r.commands);
  if (bad.empty()) return "";
  const ParsedFrame& first = r.commands[bad.front()];
  std::string what = fmt::format("command {} {}", bad.front(), flag_words(first.flags.front()));
  if (bad.size() > 1)
    what += fmt::format(" ({} of {} commands are malformed)", bad.size(), r.commands.size());
  if (first.at_record_start)
    what += fmt::format(
        " (it starts {:.1f} us into the record: if its first bytes came before, capture from "
        "earlier)",
        (first.start_s - r.t_begin) * 1e6);
  if (!r.pass)
    return fmt::format(
        "{}; the waveform does not pass the receiver rules either: fix the link first, then look "
        "at the firmware if the command stays malformed",
        what);
  std::string s = fmt::format(
      "the waveform meets every receiver rule, but {}: a firmware or host problem, not the link",
      what);
  const bool none_checks = std::none_of(r.commands.begin(), r.commands.end(),
                                        [](const ParsedFrame& c) { return c.crc_ok; });
  if (none_checks && r.commands.size() > 1)
    s += fmt::format(
        " (unless the bytes are a test pattern rather than commands: none of the {} frames has a "
        "valid CRC)",
        r.commands.size());
  return s;
}

}  // namespace isolink::eye
