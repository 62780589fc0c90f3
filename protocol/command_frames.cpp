#include "protocol/command_frames.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "base/hex.h"
#include "protocol/crc16.h"

namespace isolink {
namespace {

struct KindName {
  CommandKind kind;
  std::string_view name;
};
// In request-type order: kKinds[t] is request type t (init byte 0x80 + 0x10 * t).
constexpr std::array<KindName, 8> kKinds = {{
    {CommandKind::kSingleRead, "single-read"},
    {CommandKind::kSingleWrite, "single-write"},
    {CommandKind::kStackRead, "stack-read"},
    {CommandKind::kStackWrite, "stack-write"},
    {CommandKind::kBroadcastRead, "broadcast-read"},
    {CommandKind::kBroadcastWrite, "broadcast-write"},
    {CommandKind::kBroadcastWriteReverse, "broadcast-write-reverse"},
    {CommandKind::kRaw, "raw"},
}};

constexpr size_t kCrcBytes = 2;
// The longest frame: a response of 128 data bytes (init, device, register, data, CRC).
constexpr size_t kMaxFrameBytes = 1 + 1 + 2 + 128 + kCrcBytes;

// Bytes the init byte announces (0: no request type, length unknown).
size_t announced_length(uint8_t init) {
  const size_t data = (init & 0x07u) + 1u;
  if (!(init & 0x80u)) return 1 + 1 + 2 + (init & 0x7Fu) + 1 + kCrcBytes;  // response
  const std::optional<CommandKind> k = command_kind_of_init(init);
  if (!k) return 0;
  return 1 + (has_device(*k) ? 1 : 0) + 2 + data + kCrcBytes;
}

// The bytes in [lo, hi) all decoded.
bool all_decoded(std::span<const TimedByte> b, size_t lo, size_t hi) {
  return std::all_of(b.begin() + lo, b.begin() + hi,
                     [](const TimedByte& x) { return x.value.has_value(); });
}

// The bytes in [lo, hi) decoded, at least 3, and ending in their own valid CRC.
bool ends_in_valid_crc(std::span<const TimedByte> b, size_t lo, size_t hi) {
  if (hi - lo < 3 || !all_decoded(b, lo, hi)) return false;
  std::vector<uint8_t> v;
  for (size_t i = lo; i < hi; ++i) v.push_back(*b[i].value);
  return crc16_frame_ok(v);
}

std::string hex_word(unsigned v, int digits) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s(static_cast<size_t>(digits), '0');
  for (int i = digits - 1; i >= 0; --i, v >>= 4) s[static_cast<size_t>(i)] = kDigits[v & 0xFu];
  return s;
}

std::string spaced_kind(std::string_view name) {
  std::string s(name);
  std::replace(s.begin(), s.end(), '-', ' ');
  return s;
}

// Fills the fields that the frame's bytes reach; a complete frame's last two bytes are its CRC.
void fill_fields(ParsedFrame& f, bool complete) {
  const std::vector<uint8_t>& b = f.bytes;
  const uint8_t init = b[0];
  f.response = !(init & 0x80u);
  f.command = command_kind_of_init(init);
  const size_t payload = complete ? b.size() - kCrcBytes : b.size();
  if (complete) {
    f.crc = static_cast<uint16_t>(b[b.size() - 1] << 8 | b[b.size() - 2]);
    f.crc_expected = crc16_ibm(std::span<const uint8_t>(b).first(payload));
    f.crc_ok = *f.crc == *f.crc_expected;
    if (!f.crc_ok) f.flags.push_back(FrameFlag::kBadCrc);
  }
  if (!f.command && !f.response) {
    f.flags.push_back(FrameFlag::kUnknownInit);
    return;
  }
  const bool device = f.response || has_device(*f.command);
  size_t at = 1;
  if (device && payload > at) f.device = b[at];
  at += device ? 1 : 0;
  if (payload >= at + 2) f.reg = static_cast<uint16_t>(b[at] << 8 | b[at + 1]);
  at += 2;
  const size_t data_end = complete ? payload : std::min(payload, f.expected_length - kCrcBytes);
  if (data_end > at) f.data.assign(b.begin() + static_cast<long>(at), b.begin() + data_end);
  if (f.command && is_read(*f.command) && !f.data.empty()) f.read_bytes = f.data[0] + 1;
  if (f.command && ((init & 0x08u) || (is_read(*f.command) && (init & 0x07u))))
    f.flags.push_back(FrameFlag::kReserved);
  if ((f.device && *f.device > 63) || (f.read_bytes && *f.read_bytes > 128))
    f.flags.push_back(FrameFlag::kRange);
}

// The problems, in words, for the text line.
std::string problems_text(const ParsedFrame& f, const FrameSplitOptions& opt) {
  std::string s;
  auto add = [&](const std::string& p) { s += (s.empty() ? "" : "; ") + p; };
  for (FrameFlag flag : f.flags) {
    switch (flag) {
      case FrameFlag::kBadCrc:
        break;  // said with the CRC
      case FrameFlag::kTruncated:
        add("truncated: " + std::to_string(f.byte_count) + " of " +
            std::to_string(f.expected_length) + " bytes before " +
            (f.cut_by_record ? "the record ends"
                             : "an idle gap of more than " +
                                   std::to_string(std::lround(opt.max_idle_s * 1e6)) + " us"));
        break;
      case FrameFlag::kLength:
        add("the init byte announces " + std::to_string(f.expected_length) + " bytes, the frame " +
            "has " + std::to_string(f.byte_count) + " with a valid CRC");
        break;
      case FrameFlag::kUndecoded:
        add("a byte of it did not decode");
        break;
      case FrameFlag::kUnknownInit:
        add("init byte " + hex_word(f.bytes.empty() ? 0 : f.bytes[0], 2) +
            " names no request type");
        break;
      case FrameFlag::kReserved:
        add("reserved init-byte bits set");
        break;
      case FrameFlag::kRange:
        add(f.read_bytes && *f.read_bytes > 128 ? "a read of more than 128 bytes"
                                                : "device address over 63");
        break;
    }
  }
  return s;
}

std::string frame_text(const ParsedFrame& f, const FrameSplitOptions& opt) {
  std::string s = spaced_kind(f.kind_name());
  if (f.device) s += " dev " + std::to_string(*f.device);
  if (f.reg) s += " 0x" + hex_word(*f.reg, 4);
  if (f.read_bytes) {
    s += ", " + std::to_string(*f.read_bytes) + " byte" + (*f.read_bytes == 1 ? "" : "s");
  } else if (!f.data.empty()) {
    constexpr size_t kShown = 16;  // a response carries up to 128 bytes: the JSON has them all
    s += " = " + to_hex(std::span<const uint8_t>(f.data).first(std::min(f.data.size(), kShown)));
    if (f.data.size() > kShown) s += " ... (" + std::to_string(f.data.size()) + " bytes)";
  } else if (!f.reg && !f.bytes.empty()) {
    s += ": " + to_hex(f.bytes);
  }
  if (f.crc) {
    s += ", CRC " + crc_wire_hex(*f.crc) +
         (f.crc_ok ? " ok" : " bad (expected " + crc_wire_hex(*f.crc_expected) + ")");
  }
  std::string p = problems_text(f, opt);
  if (!p.empty() && f.at_record_start)
    p += " (it starts at the record's start: bytes before the record are not seen)";
  return p.empty() ? s : s + ": " + p;
}

ParsedFrame make_frame(std::span<const TimedByte> b, size_t lo, size_t hi, bool complete,
                       std::optional<FrameFlag> flag) {
  ParsedFrame f;
  f.start_s = b[lo].start_s;
  f.end_s = b[hi - 1].end_s;
  f.first_byte = lo;
  f.byte_count = hi - lo;
  for (size_t i = lo; i < hi && b[i].value; ++i) f.bytes.push_back(*b[i].value);
  if (b[lo].value) f.expected_length = announced_length(*b[lo].value);
  if (flag) f.flags.push_back(*flag);
  if (b[lo].value) fill_fields(f, complete);
  return f;
}

// Rules 2-5 on the burst [lo, hi).
void parse_burst(std::span<const TimedByte> b, size_t lo, size_t hi,
                 std::vector<ParsedFrame>& out) {
  size_t p = lo;
  while (p < hi) {
    const size_t need = b[p].value ? announced_length(*b[p].value) : 0;
    const size_t end = need ? std::min(p + need, hi) : hi;
    if (!all_decoded(b, p, end)) {
      out.push_back(make_frame(b, p, hi, false, FrameFlag::kUndecoded));
      return;
    }
    if (need == 0) {  // no request type: the rest of the burst, CRC read at its end
      out.push_back(make_frame(b, p, hi, all_decoded(b, p, hi) && hi - p >= 3, std::nullopt));
      return;
    }
    if (end - p < need) {
      const bool crc = ends_in_valid_crc(b, p, hi);
      out.push_back(make_frame(b, p, hi, crc, crc ? FrameFlag::kLength : FrameFlag::kTruncated));
      return;
    }
    if (!ends_in_valid_crc(b, p, end) && end < hi && hi - p <= kMaxFrameBytes &&
        ends_in_valid_crc(b, p, hi)) {
      out.push_back(make_frame(b, p, hi, true, FrameFlag::kLength));
      return;
    }
    out.push_back(make_frame(b, p, end, true, std::nullopt));
    p = end;
  }
}

}  // namespace

uint8_t init_byte_base(CommandKind kind) {
  if (kind == CommandKind::kRaw) return 0x00;
  return static_cast<uint8_t>(0x80 + 0x10 * static_cast<int>(kind));
}

std::string_view command_keyword(CommandKind kind) {
  for (const KindName& k : kKinds)
    if (k.kind == kind) return k.name;
  return "raw";
}

std::optional<CommandKind> command_kind_of(std::string_view keyword) {
  for (const KindName& k : kKinds)
    if (k.name == keyword) return k.kind;
  return std::nullopt;
}

std::optional<CommandKind> command_kind_of_init(uint8_t init) {
  if (!(init & 0x80u)) return std::nullopt;
  const size_t type = (init >> 4) & 0x07u;
  if (type >= 7) return std::nullopt;
  return kKinds[type].kind;
}

bool is_read(CommandKind kind) {
  return kind == CommandKind::kSingleRead || kind == CommandKind::kStackRead ||
         kind == CommandKind::kBroadcastRead;
}

bool is_write(CommandKind kind) {
  return kind == CommandKind::kSingleWrite || kind == CommandKind::kStackWrite ||
         kind == CommandKind::kBroadcastWrite || kind == CommandKind::kBroadcastWriteReverse;
}

bool has_device(CommandKind kind) {
  return kind == CommandKind::kSingleRead || kind == CommandKind::kSingleWrite;
}

std::string_view flag_name(FrameFlag f) {
  switch (f) {
    case FrameFlag::kBadCrc:
      return "bad_crc";
    case FrameFlag::kTruncated:
      return "truncated";
    case FrameFlag::kLength:
      return "length";
    case FrameFlag::kUndecoded:
      return "undecoded";
    case FrameFlag::kUnknownInit:
      return "unknown_init";
    case FrameFlag::kReserved:
      return "reserved";
    case FrameFlag::kRange:
      return "range";
  }
  return "unknown";
}

std::string_view ParsedFrame::kind_name() const {
  if (response) return "response";
  return command ? command_keyword(*command) : "unknown";
}

std::string crc_wire_hex(uint16_t crc) {
  return hex_word(static_cast<unsigned>((crc & 0xFFu) << 8 | crc >> 8), 4);
}

std::vector<ParsedFrame> parse_frames(std::span<const TimedByte> bytes,
                                      const FrameSplitOptions& opt) {
  std::vector<ParsedFrame> out;
  size_t lo = 0;
  while (lo < bytes.size()) {
    size_t hi = lo + 1;
    while (hi < bytes.size() && bytes[hi].start_s - bytes[hi - 1].end_s <= opt.max_idle_s) ++hi;
    const size_t first = out.size();
    parse_burst(bytes, lo, hi, out);
    for (size_t i = first; i < out.size(); ++i) {
      ParsedFrame& f = out[i];
      // NaN bounds compare false: unknown bounds cut nothing.
      f.at_record_start = f.start_s <= opt.record_begin_s + opt.max_idle_s;
      f.cut_by_record =
          f.end_s >= opt.record_end_s - opt.max_idle_s &&
          std::find(f.flags.begin(), f.flags.end(), FrameFlag::kTruncated) != f.flags.end();
      f.text = frame_text(f, opt);
    }
    lo = hi;
  }
  return out;
}

}  // namespace isolink
