#include "eye/decode.h"

#include <cctype>

namespace isolink::eye {
namespace {

const char* sign_char(int s) {
  return s > 0 ? "+" : "-";
}

void push_bit(std::vector<int>& h, int bit) {
  h.push_back(bit ? +1 : -1);
  h.push_back(bit ? -1 : +1);
}

}  // namespace

std::vector<int> frame_half_bits(uint8_t byte, const FrameFormat& fmt, bool error_bit) {
  std::vector<int> h;
  h.reserve(fmt.half_bits());
  h.push_back(+1);  // preamble
  push_bit(h, 0);   // sync
  push_bit(h, 0);
  if (fmt.sof) push_bit(h, fmt.sof_value);
  for (int i = 0; i < 8; ++i) {
    int n = fmt.bit_order == BitOrder::kLsbFirst ? i : 7 - i;
    push_bit(h, (byte >> n) & 1);
  }
  push_bit(h, error_bit ? 1 : 0);
  h.push_back(-1);  // postamble
  return h;
}

std::string half_bit_role(size_t h, const FrameFormat& fmt) {
  const size_t len = fmt.half_bits();
  if (h == 0) return "preamble";
  if (h + 1 == len) return "postamble";
  if (h >= len) return "";
  size_t j = (h - 1) / 2;
  if (j < 2) return "sync " + std::to_string(j);
  if (fmt.sof && j == 2) return "SOF";
  size_t d = j - 2 - (fmt.sof ? 1 : 0);
  if (d < 8) return "bit " + std::to_string(fmt.bit_order == BitOrder::kLsbFirst ? d : 7 - d);
  return "error bit";
}

std::vector<DecodedByte> decode_half_bits(std::span<const int> hb, const FrameFormat& fmt) {
  std::vector<DecodedByte> out;
  const size_t n = hb.size();
  const size_t len = fmt.half_bits();
  size_t p = 0;
  while (p < n) {
    DecodedByte d;
    d.first_half = p;
    auto fail = [&](const char* fault, std::string detail) {
      d.half_count = n - p;
      d.fault = fault;
      d.detail = std::move(detail);
      out.push_back(d);
    };
    auto too_short = [&] {
      fail("length", "the frame ends after " + std::to_string(n - p) + " half bits; a byte needs " +
                         std::to_string(len));
    };
    if (hb[p] < 0) {
      fail("sync", "preamble is - (expected +)");
      return out;
    }
    int value = 0;
    bool ok = true;
    for (size_t j = 0; j < fmt.bits() && ok; ++j) {
      size_t i = p + 1 + 2 * j;
      if (i + 1 >= n) {
        too_short();
        return out;
      }
      const std::string role = half_bit_role(1 + 2 * j, fmt);
      const bool framing = j < 2 || (fmt.sof && j == 2);
      if (hb[i] == hb[i + 1]) {
        fail(framing ? "sync" : "weak bit", role + " is (" + sign_char(hb[i]) + ", " +
                                                sign_char(hb[i + 1]) + "): neither 0 nor 1");
        return out;
      }
      int bit = hb[i] > 0 ? 1 : 0;
      if (j < 2) {
        if (bit != 0) {
          fail("sync", role + " is 1 (expected 0)");
          return out;
        }
      } else if (fmt.sof && j == 2) {
        if (bit != fmt.sof_value) {
          fail("sync", "SOF is " + std::to_string(bit) + " (expected " +
                           std::to_string(fmt.sof_value) + ")");
          return out;
        }
      } else if (j + 1 == fmt.bits()) {
        d.error_bit = bit != 0;
      } else {
        size_t k = j - 2 - (fmt.sof ? 1 : 0);
        size_t n_bit = fmt.bit_order == BitOrder::kLsbFirst ? k : 7 - k;
        value |= bit << n_bit;
      }
    }
    if (p + len - 1 >= n) {
      too_short();
      return out;
    }
    if (hb[p + len - 1] > 0) {
      fail("sync", "postamble is + (expected -)");
      return out;
    }
    d.half_count = len;
    d.byte = static_cast<uint8_t>(value);
    out.push_back(d);
    p += len;
  }
  return out;
}

std::string to_hex(std::span<const uint8_t> bytes) {
  static const char* kDigits = "0123456789ABCDEF";
  std::string s;
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (i) s += ' ';
    s += kDigits[bytes[i] >> 4];
    s += kDigits[bytes[i] & 15];
  }
  return s;
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
    std::string_view tok = text.substr(i, j - i);
    std::string_view digits = tok;
    if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
      digits.remove_prefix(2);
    bool hex = !digits.empty();
    for (char c : digits) hex = hex && std::isxdigit(static_cast<unsigned char>(c));
    if (!hex || (digits.size() > 2 && digits.size() % 2 != 0))
      return Status::Error("'" + std::string(tok) +
                           "' is not a hex byte (expected e.g. \"80 00 02\")");
    auto nibble = [](char c) {
      return std::isdigit(static_cast<unsigned char>(c))
                 ? c - '0'
                 : std::tolower(static_cast<unsigned char>(c)) - 'a' + 10;
    };
    if (digits.size() <= 2) {
      int v = 0;
      for (char c : digits) v = v * 16 + nibble(c);
      out.push_back(static_cast<uint8_t>(v));
    } else {
      for (size_t k = 0; k < digits.size(); k += 2)
        out.push_back(static_cast<uint8_t>(nibble(digits[k]) * 16 + nibble(digits[k + 1])));
    }
    i = j;
  }
  if (out.empty()) return Status::Error("no hex bytes in '" + std::string(text) + "'");
  return out;
}

}  // namespace isolink::eye
