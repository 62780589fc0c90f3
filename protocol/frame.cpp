#include "protocol/frame.h"

namespace isolink {
namespace {

const char* sign_char(int s) {
  return s > 0 ? "+" : "-";
}

void push_bit(std::vector<int>& h, int bit) {
  h.push_back(bit ? +1 : -1);
  h.push_back(bit ? -1 : +1);
}

}  // namespace

std::vector<int> frame_wire_bits(uint8_t byte, const FrameFormat& fmt, bool error_bit) {
  std::vector<int> bits = {0, 0};  // sync
  bits.reserve(fmt.bits());
  if (fmt.sof) bits.push_back(fmt.sof_value ? 1 : 0);
  for (int i = 0; i < 8; ++i) {
    const int n = fmt.bit_order == BitOrder::kLsbFirst ? i : 7 - i;
    bits.push_back((byte >> n) & 1);
  }
  bits.push_back(error_bit ? 1 : 0);
  return bits;
}

std::vector<int> frame_half_bits(uint8_t byte, const FrameFormat& fmt, bool error_bit) {
  std::vector<int> h;
  h.reserve(fmt.half_bits());
  h.push_back(+1);  // preamble
  for (int bit : frame_wire_bits(byte, fmt, error_bit)) push_bit(h, bit);
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

}  // namespace isolink
