#include "netlists/traffic/encoding.h"

#include <fmt/format.h>

#include <cmath>

namespace isolink::traffic {

Status validate(const EncodingOptions& opt) {
  if (!(opt.half_bit > 0.0) || !std::isfinite(opt.half_bit)) {
    return Status::Error(
        fmt::format("pulse width {} s is invalid: it must be a positive time", opt.half_bit));
  }
  if (opt.sof_value != 0 && opt.sof_value != 1) {
    return Status::Error(fmt::format("SOF value {} is invalid: a bit is 0 or 1", opt.sof_value));
  }
  if (opt.error_bit != 0 && opt.error_bit != 1) {
    return Status::Error(fmt::format("error bit {} is invalid: a bit is 0 or 1", opt.error_bit));
  }
  return Status::Ok();
}

std::vector<int> byte_wire_bits(uint8_t byte, const EncodingOptions& opt) {
  return frame_wire_bits(byte, opt, opt.error_bit != 0);
}

std::vector<int> byte_half_bits(uint8_t byte, const EncodingOptions& opt) {
  return frame_half_bits(byte, opt, opt.error_bit != 0);
}

int byte_half_bit_count(const EncodingOptions& opt) {
  return static_cast<int>(opt.half_bits());
}

double byte_duration(const EncodingOptions& opt) {
  return byte_half_bit_count(opt) * opt.half_bit;
}

std::string byte_bit_string(uint8_t byte, const EncodingOptions& opt) {
  const std::vector<int> bits = byte_wire_bits(byte, opt);
  std::string s = "+ 00 ";
  size_t i = 2;
  if (opt.sof) s += bits[i++] ? "1 " : "0 ";
  for (int k = 0; k < 8; ++k) s += bits[i++] ? '1' : '0';
  s += bits[i] ? " 1 -" : " 0 -";
  return s;
}

int double_pulse_count(uint8_t byte, const EncodingOptions& opt) {
  const std::vector<int> h = byte_half_bits(byte, opt);
  int count = 0;
  for (size_t i = 1; i < h.size(); ++i) {
    if (h[i] == h[i - 1]) {
      ++count;
      ++i;  // two half bits per pulse at most inside one frame; skip the pair
    }
  }
  return count;
}

}  // namespace isolink::traffic
