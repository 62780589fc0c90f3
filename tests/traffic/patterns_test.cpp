#include "netlists/traffic/patterns.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace isolink::traffic {
namespace {

bool has_period(const std::vector<int>& bits, size_t p) {
  for (size_t i = 0; i + p < bits.size(); ++i) {
    if (bits[i] != bits[i + p]) return false;
  }
  return true;
}

TEST(Prbs, Prbs7PeriodIs127) {
  const std::vector<int> bits = prbs_bits(7, 2 * 127);
  EXPECT_TRUE(has_period(bits, 127));
  for (size_t p = 1; p < 127; ++p) ASSERT_FALSE(has_period(bits, p)) << p;
  int ones = 0;
  for (size_t i = 0; i < 127; ++i) ones += bits[i];
  EXPECT_EQ(ones, 64);  // a maximal-length sequence has 2^(n-1) ones per period
}

TEST(Prbs, Prbs15PeriodIs32767) {
  const std::vector<int> bits = prbs_bits(15, 2 * 32767);
  EXPECT_TRUE(has_period(bits, 32767));
  // 32767 = 7 * 31 * 151: the minimal period divides it; none of the proper divisors works.
  for (size_t p : {1, 7, 31, 151, 217, 1057, 4681}) EXPECT_FALSE(has_period(bits, p)) << p;
  int ones = 0;
  for (size_t i = 0; i < 32767; ++i) ones += bits[i];
  EXPECT_EQ(ones, 16384);
}

TEST(Prbs, Prbs9PeriodIs511) {
  const std::vector<int> bits = prbs_bits(9, 2 * 511);
  EXPECT_TRUE(has_period(bits, 511));
  for (size_t p : {1, 7, 73}) EXPECT_FALSE(has_period(bits, p)) << p;  // 511 = 7 * 73
}

TEST(Prbs, FirstBitsFromAllOnesSeedByHand) {
  // x^7+x^6+1 from 1111111: stages 7 and 6 stay 1 for six shifts (bits 0), then 1 XOR 0.
  EXPECT_EQ(prbs_bits(7, 8), (std::vector<int>{0, 0, 0, 0, 0, 0, 1, 0}));
  // Packed LSB first: bit 6 set -> 0x40.
  EXPECT_EQ(prbs_bytes(7, 1), (std::vector<uint8_t>{0x40}));
  // x^15+x^14+1: fourteen 0s, then a 1 at index 14 -> bytes 0x00, 0x40.
  EXPECT_EQ(prbs_bytes(15, 2), (std::vector<uint8_t>{0x00, 0x40}));
  EXPECT_TRUE(prbs_order_supported(15));
  EXPECT_FALSE(prbs_order_supported(8));
}

TEST(Prbs, ZeroSeedFallsBackToAllOnes) {
  Prbs a(7, 0), b(7);
  for (int i = 0; i < 20; ++i) ASSERT_EQ(a.next(), b.next());
}

TEST(Patterns, NamedPatternsByHand) {
  EXPECT_EQ(pattern_bytes(Pattern::kAlt, 4), (std::vector<uint8_t>{0x55, 0xAA, 0x55, 0xAA}));
  EXPECT_EQ(pattern_bytes(Pattern::kZeros, 2), (std::vector<uint8_t>{0x00, 0x00}));
  EXPECT_EQ(pattern_bytes(Pattern::kOnes, 2), (std::vector<uint8_t>{0xFF, 0xFF}));
  const std::vector<uint8_t> runs = pattern_bytes(Pattern::kRuns, 17);
  EXPECT_EQ(runs[7], 0x00);
  EXPECT_EQ(runs[8], 0xFF);
  EXPECT_EQ(runs[15], 0xFF);
  EXPECT_EQ(runs[16], 0x00);
  EXPECT_EQ(pattern_bytes(Pattern::kDoubles, 3), (std::vector<uint8_t>{0xAA, 0xAA, 0xAA}));
  const std::vector<uint8_t> all = pattern_bytes(Pattern::kAll256, 258);
  EXPECT_EQ(all[0], 0x00);
  EXPECT_EQ(all[255], 0xFF);
  EXPECT_EQ(all[256], 0x00);
  EXPECT_EQ(all[257], 0x01);
  EXPECT_EQ(pattern_bytes(Pattern::kPrbs7, 2), (std::vector<uint8_t>{0x40, 0x30}));
}

TEST(Patterns, NamesAndDefaults) {
  StatusOr<Pattern> p = parse_pattern("PRBS15");
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(*p, Pattern::kPrbs15);
  EXPECT_EQ(default_pattern_bytes(Pattern::kAll256), 256u);
  EXPECT_EQ(default_pattern_bytes(Pattern::kPrbs7), 16u);
  StatusOr<Pattern> alt = parse_pattern("55aa");
  ASSERT_TRUE(alt.ok());
  EXPECT_EQ(*alt, Pattern::kAlt);
  StatusOr<Pattern> bad = parse_pattern("prbs31");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("unknown pattern 'prbs31'"), std::string::npos);
}

}  // namespace
}  // namespace isolink::traffic
