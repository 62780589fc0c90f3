#include "netlists/traffic/encoding.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace isolink::traffic {
namespace {

TEST(Encoding, ByteFrameIs13BitTimes) {
  EncodingOptions opt;
  EXPECT_EQ(byte_half_bit_count(opt), 26);
  EXPECT_NEAR(byte_duration(opt), 6.5e-6, 1e-18);
  EXPECT_EQ(byte_half_bits(0x5A, opt).size(), 26u);
  opt.sof = false;
  EXPECT_EQ(byte_half_bit_count(opt), 24);
  EXPECT_NEAR(byte_duration(opt), 6.0e-6, 1e-18);
  EXPECT_EQ(byte_half_bits(0x5A, opt).size(), 24u);
}

TEST(Encoding, ZeroByteHalfBitsByHand) {
  // + | -+ -+ | +- | (-+) x 8 | -+ | -
  const std::vector<int> expect = {+1,                              // preamble
                                   -1, +1, -1, +1,                  // sync 00
                                   +1, -1,                          // SOF 1
                                   -1, +1, -1, +1, -1, +1, -1, +1,  // bits 0-3
                                   -1, +1, -1, +1, -1, +1, -1, +1,  // bits 4-7
                                   -1, +1,                          // error 0
                                   -1};                             // postamble
  EXPECT_EQ(byte_half_bits(0x00, {}), expect);
}

TEST(Encoding, FfByteHalfBitsByHand) {
  // + | -+ -+ | +- | (+-) x 8 | -+ | -
  const std::vector<int> expect = {+1,                              // preamble
                                   -1, +1, -1, +1,                  // sync 00
                                   +1, -1,                          // SOF 1
                                   +1, -1, +1, -1, +1, -1, +1, -1,  // bits 0-3
                                   +1, -1, +1, -1, +1, -1, +1, -1,  // bits 4-7
                                   -1, +1,                          // error 0
                                   -1};                             // postamble
  EXPECT_EQ(byte_half_bits(0xFF, {}), expect);
}

TEST(Encoding, WireBitsLsbFirstAndMsbFirst) {
  // 0xB3 = 1011 0011: LSB first 1,1,0,0,1,1,0,1.
  EXPECT_EQ(byte_wire_bits(0xB3, {}), (std::vector<int>{0, 0, 1, 1, 1, 0, 0, 1, 1, 0, 1, 0}));
  EXPECT_EQ(byte_bit_string(0xB3, {}), "+ 00 1 11001101 0 -");
  EncodingOptions msb;
  msb.bit_order = BitOrder::kMsbFirst;
  EXPECT_EQ(byte_bit_string(0xB3, msb), "+ 00 1 10110011 0 -");
}

TEST(Encoding, SofAndErrorBitOptions) {
  EncodingOptions opt;
  opt.sof_value = 0;
  opt.error_bit = 1;
  EXPECT_EQ(byte_bit_string(0x01, opt), "+ 00 0 10000000 1 -");
  opt.sof = false;
  EXPECT_EQ(byte_bit_string(0x01, opt), "+ 00 10000000 1 -");
  EXPECT_EQ(byte_wire_bits(0x01, opt), (std::vector<int>{0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1}));
}

TEST(Encoding, DoublePulseCountsByHand) {
  const EncodingOptions opt;
  // 0x00: sync 0 -> SOF 1 (+ +) and SOF 1 -> bit0 0 (- -).
  EXPECT_EQ(double_pulse_count(0x00, opt), 2);
  // 0xFF: sync 0 -> SOF 1 (+ +) and bit7 1 -> error 0 (- -).
  EXPECT_EQ(double_pulse_count(0xFF, opt), 2);
  // 0xAA (LSB first 0,1,0,1,...): every boundary from the sync pair to the error bit: 10.
  EXPECT_EQ(double_pulse_count(0xAA, opt), 10);
  int most = 0;
  for (int b = 0; b < 256; ++b)
    most = std::max(most, double_pulse_count(static_cast<uint8_t>(b), opt));
  EXPECT_EQ(most, 10);
  EncodingOptions no_sof;
  no_sof.sof = false;
  EXPECT_EQ(double_pulse_count(0x00, no_sof), 0);  // all -+ couplets: no touching pair
  EncodingOptions err;
  err.error_bit = 1;
  // 0x00 with error 1: sync->SOF, SOF->bit0, bit7 0 -> error 1 (+ +), error 1 -> postamble (- -).
  EXPECT_EQ(double_pulse_count(0x00, err), 4);
}

TEST(Encoding, DoublesSitWhereAdjacentWireBitsDiffer) {
  // docs/physics.md section 2: where two adjacent bits differ, two same-polarity pulses touch.
  for (int b = 0; b < 256; ++b) {
    const std::vector<int> w = byte_wire_bits(static_cast<uint8_t>(b), {});
    int changes = 0;
    for (size_t i = 1; i < w.size(); ++i) changes += w[i] != w[i - 1];
    ASSERT_EQ(double_pulse_count(static_cast<uint8_t>(b), {}), changes) << b;
  }
  EXPECT_EQ(double_pulse_count(0xB3, {}), 6);  // 0 0 1 | 1 1 0 0 1 1 0 1 | 0: six changes
}

TEST(Encoding, EveryByteIsDcFree) {
  // Preamble + and postamble - cancel; every couplet cancels.
  for (int b = 0; b < 256; ++b) {
    int sum = 0;
    for (int h : byte_half_bits(static_cast<uint8_t>(b), {})) sum += h;
    ASSERT_EQ(sum, 0) << b;
  }
}

TEST(Encoding, ValidateNamesBadOptions) {
  EncodingOptions opt;
  EXPECT_TRUE(validate(opt).ok());
  opt.half_bit = 0;
  EXPECT_NE(validate(opt).message().find("pulse width"), std::string::npos);
  opt = {};
  opt.sof_value = 2;
  EXPECT_NE(validate(opt).message().find("SOF value 2"), std::string::npos);
  opt = {};
  opt.error_bit = -1;
  EXPECT_NE(validate(opt).message().find("error bit -1"), std::string::npos);
}

}  // namespace
}  // namespace isolink::traffic
