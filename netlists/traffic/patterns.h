// Byte patterns for analysis: PRBS, all byte values, named stress patterns.
//
// Usage:
//   StatusOr<Pattern> p = parse_pattern("prbs7");
//   std::vector<uint8_t> b = pattern_bytes(*p, 32);    // 32 bytes; DriveBuilder::add_bytes sends
//   them Prbs gen(15);                                       // x^15 + x^14 + 1, all-ones seed int
//   bit = gen.next();
// PRBS bits are packed into bytes least significant bit first, so with the default LSB-first
// encoding the data bits on the wire follow the PRBS sequence. Patterns carry no CRC.
//   prbs7   x^7 + x^6 + 1    (period 127 bits)       prbs9   x^9 + x^5 + 1  (511 bits)
//   prbs15  x^15 + x^14 + 1  (period 32767 bits)     all256  0x00, 0x01, ... 0xFF, repeating
//   alt     0x55, 0xAA alternating                   zeros   0x00 repeated
//   ones    0xFF repeated                            runs    8 x 0x00 then 8 x 0xFF, repeating
//   doubles 0xAA repeated: 10 double pulses in its 16 (the most of any byte with SOF 1, error 0)
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink::traffic {

// Fibonacci LFSR PRBS generator: the new bit is the XOR of the two tap stages.
class Prbs {
 public:
  // order 7, 9 or 15 (other orders: every next() returns 0); seed's low `order` bits, nonzero.
  explicit Prbs(int order, uint32_t seed = 0xFFFFFFFFu);
  // Next bit of the sequence (0 or 1).
  int next();
  int order() const { return order_; }

 private:
  int order_;
  int tap_;        // second tap (the first is the order itself)
  uint32_t mask_;  // (1 << order) - 1
  uint32_t state_;
};

// True for the PRBS orders Prbs supports (7, 9, 15).
bool prbs_order_supported(int order);
// n bits of PRBS-order from the all-ones seed.
std::vector<int> prbs_bits(int order, size_t n);
// n bytes of PRBS-order, bits packed LSB first.
std::vector<uint8_t> prbs_bytes(int order, size_t n);

enum class Pattern { kPrbs7, kPrbs9, kPrbs15, kAll256, kAlt, kZeros, kOnes, kRuns, kDoubles };

// "prbs7", "prbs9", "prbs15", "all256", "alt", "zeros", "ones", "runs", "doubles".
std::string_view pattern_name(Pattern p);
// Case-insensitive; also accepts "55aa" for alt; errors list the valid names.
StatusOr<Pattern> parse_pattern(std::string_view name);
// Default length in bytes: 256 for all256, 16 for prbs7/prbs9 (128 bits, one period + 1),
// 64 for prbs15, 16 for the stress patterns.
size_t default_pattern_bytes(Pattern p);
// n bytes of the pattern (n = 0 gives none).
std::vector<uint8_t> pattern_bytes(Pattern p, size_t n);

}  // namespace isolink::traffic
