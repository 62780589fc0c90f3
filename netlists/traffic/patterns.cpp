#include "netlists/traffic/patterns.h"

#include <fmt/format.h>

#include <cctype>
#include <string>

namespace isolink::traffic {

bool prbs_order_supported(int order) {
  return order == 7 || order == 9 || order == 15;
}

Prbs::Prbs(int order, uint32_t seed) : order_(order), tap_(0), mask_(0), state_(0) {
  switch (order) {
    case 7:
      tap_ = 6;
      break;  // x^7 + x^6 + 1
    case 9:
      tap_ = 5;
      break;  // x^9 + x^5 + 1
    case 15:
      tap_ = 14;
      break;  // x^15 + x^14 + 1
    default:
      return;
  }
  mask_ = (1u << order) - 1u;
  state_ = seed & mask_;
  if (state_ == 0) state_ = mask_;  // the all-zero state locks up; use all ones
}

int Prbs::next() {
  if (mask_ == 0) return 0;
  const uint32_t bit = ((state_ >> (order_ - 1)) ^ (state_ >> (tap_ - 1))) & 1u;
  state_ = ((state_ << 1) | bit) & mask_;
  return static_cast<int>(bit);
}

std::vector<int> prbs_bits(int order, size_t n) {
  Prbs g(order);
  std::vector<int> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = g.next();
  return out;
}

std::vector<uint8_t> prbs_bytes(int order, size_t n) {
  Prbs g(order);
  std::vector<uint8_t> out(n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 8; ++k) out[i] = static_cast<uint8_t>(out[i] | (g.next() << k));
  }
  return out;
}

std::string_view pattern_name(Pattern p) {
  switch (p) {
    case Pattern::kPrbs7:
      return "prbs7";
    case Pattern::kPrbs9:
      return "prbs9";
    case Pattern::kPrbs15:
      return "prbs15";
    case Pattern::kAll256:
      return "all256";
    case Pattern::kAlt:
      return "alt";
    case Pattern::kZeros:
      return "zeros";
    case Pattern::kOnes:
      return "ones";
    case Pattern::kRuns:
      return "runs";
    case Pattern::kDoubles:
      return "doubles";
  }
  return "prbs7";
}

StatusOr<Pattern> parse_pattern(std::string_view name) {
  std::string n(name);
  for (char& ch : n) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  for (Pattern p :
       {Pattern::kPrbs7, Pattern::kPrbs9, Pattern::kPrbs15, Pattern::kAll256, Pattern::kAlt,
        Pattern::kZeros, Pattern::kOnes, Pattern::kRuns, Pattern::kDoubles}) {
    if (n == pattern_name(p)) return p;
  }
  if (n == "55aa") return Pattern::kAlt;
  return Status::Error(fmt::format(
      "unknown pattern '{}': expected prbs7, prbs9, prbs15, all256, alt, zeros, ones, runs or "
      "doubles",
      name));
}

size_t default_pattern_bytes(Pattern p) {
  switch (p) {
    case Pattern::kAll256:
      return 256;
    case Pattern::kPrbs15:
      return 64;
    default:
      return 16;
  }
}

std::vector<uint8_t> pattern_bytes(Pattern p, size_t n) {
  switch (p) {
    case Pattern::kPrbs7:
      return prbs_bytes(7, n);
    case Pattern::kPrbs9:
      return prbs_bytes(9, n);
    case Pattern::kPrbs15:
      return prbs_bytes(15, n);
    default:
      break;
  }
  std::vector<uint8_t> out(n);
  for (size_t i = 0; i < n; ++i) {
    switch (p) {
      case Pattern::kAll256:
        out[i] = static_cast<uint8_t>(i & 0xFFu);
        break;
      case Pattern::kAlt:
        out[i] = (i % 2 == 0) ? 0x55 : 0xAA;
        break;
      case Pattern::kZeros:
        out[i] = 0x00;
        break;
      case Pattern::kOnes:
        out[i] = 0xFF;
        break;
      case Pattern::kRuns:
        out[i] = ((i / 8) % 2 == 0) ? 0x00 : 0xFF;
        break;
      default:
        out[i] = 0xAA;
        break;  // kDoubles
    }
  }
  return out;
}

}  // namespace isolink::traffic
