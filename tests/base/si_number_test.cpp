// The one SPICE / SI number scanner (base/si_number.h): every suffix, RKM, exact decimals and the
// options behind each caller's rule (netlists: units ignored; YAML quantities and traffic times:
// the scan stops after the suffix so the caller checks the unit; lengths: no suffix at all).
#include "base/si_number.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string_view>

namespace isolink {
namespace {

double num(const char* s) {
  double v = std::nan("");
  EXPECT_TRUE(parse_si_number(s, v)) << s;
  return v;
}

TEST(SiNumber, SuffixTable) {
  EXPECT_DOUBLE_EQ(num("2.2nF"), 2.2e-9);
  EXPECT_DOUBLE_EQ(num("2.2n"), 2.2e-9);
  EXPECT_DOUBLE_EQ(num("1meg"), 1e6);
  EXPECT_DOUBLE_EQ(num("1MEG"), 1e6);
  EXPECT_DOUBLE_EQ(num("10Meg"), 10e6);
  EXPECT_DOUBLE_EQ(num("1m"), 1e-3);
  EXPECT_DOUBLE_EQ(num("1M"), 1e-3);  // SPICE: M is milli, not mega
  EXPECT_DOUBLE_EQ(num("1ms"), 1e-3);
  EXPECT_DOUBLE_EQ(num("10mil"), 254e-6);
  EXPECT_DOUBLE_EQ(num("1e-9"), 1e-9);
  EXPECT_DOUBLE_EQ(num("1E3"), 1000.0);
  EXPECT_DOUBLE_EQ(num("1e+3"), 1000.0);
  EXPECT_DOUBLE_EQ(num(".5u"), 0.5e-6);
  EXPECT_DOUBLE_EQ(num("5."), 5.0);
  EXPECT_DOUBLE_EQ(num("1kohm"), 1000.0);
  EXPECT_DOUBLE_EQ(num("1k"), 1000.0);
  EXPECT_DOUBLE_EQ(num("4.7K"), 4700.0);
  EXPECT_DOUBLE_EQ(num("3f"), 3e-15);
  EXPECT_DOUBLE_EQ(num("3p"), 3e-12);
  EXPECT_DOUBLE_EQ(num("2g"), 2e9);
  EXPECT_DOUBLE_EQ(num("2t"), 2e12);
  EXPECT_DOUBLE_EQ(num("2.5V"), 2.5);  // unit letters without a scale are ignored
  EXPECT_DOUBLE_EQ(num("1e3k"), 1e6);
  EXPECT_DOUBLE_EQ(num("-47p"), -47e-12);
  EXPECT_DOUBLE_EQ(num("+3"), 3.0);
  EXPECT_DOUBLE_EQ(num("100"), 100.0);
  // Exactly the decimal value, not 2.2 * 1e-9 rounded twice.
  EXPECT_EQ(num("2.2n"), 2.2e-9);
  EXPECT_EQ(num("0.1u"), 0.1e-6);
}

TEST(SiNumber, Malformed) {
  double v = 0;
  EXPECT_FALSE(parse_si_number("1.2.3", v));
  EXPECT_FALSE(parse_si_number("abc", v));
  EXPECT_FALSE(parse_si_number("", v));
  EXPECT_FALSE(parse_si_number("-", v));
  EXPECT_FALSE(parse_si_number(".", v));
  EXPECT_FALSE(parse_si_number("1k5.2", v));
  EXPECT_FALSE(parse_si_number("1.5k2", v));
  EXPECT_FALSE(parse_si_number("1_0", v));
  // An 'e' with no exponent digits was read as 1 with a unit letter (issue 15).
  EXPECT_FALSE(parse_si_number("1e", v));
  EXPECT_FALSE(parse_si_number("1e+", v));
  EXPECT_FALSE(parse_si_number("2.2E-", v));
  EXPECT_TRUE(parse_si_number("1e3", v));
  EXPECT_EQ(v, 1000.0);
}

// RKM (IEC 60062): the letter is the decimal point and the scale.
TEST(SiNumber, RkmNotation) {
  double v = 0;
  ASSERT_TRUE(parse_si_number("4K7", v));
  EXPECT_EQ(v, 4.7e3);
  ASSERT_TRUE(parse_si_number("2R2", v));
  EXPECT_EQ(v, 2.2);
  ASSERT_TRUE(parse_si_number("1u5", v));
  EXPECT_EQ(v, 1.5e-6);
  ASSERT_TRUE(parse_si_number("4m7ohm", v));
  EXPECT_EQ(v, 4.7e-3);
  ASSERT_TRUE(parse_si_number("10k25", v));
  EXPECT_EQ(v, 10.25e3);
  ASSERT_TRUE(parse_si_number("1meg", v));  // not RKM: no digit after the letter
  EXPECT_EQ(v, 1e6);
}

TEST(SiNumber, ScanStopsAfterUnit) {
  auto r = scan_si_number("2.2nF*3");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->length, 5u);
  EXPECT_DOUBLE_EQ(r->value, 2.2e-9);
  EXPECT_FALSE(scan_si_number("x1"));
}

// Caller rule: YAML quantities and traffic times stop after the scale suffix and read the unit
// themselves ("2.2nF" is 2.2n and then "F"; "2.2nH" must not pass for a capacitance).
TEST(SiNumber, StopBeforeUnitLetters) {
  const SiOptions suffix_only{.scale = true, .unit_letters = false};
  struct Case {
    std::string_view text;
    double value;
    std::size_t length;
  };
  const Case cases[] = {{"2.2nF", 2.2e-9, 4},  {"10megohm", 10e6, 5}, {"10mils", 254e-6, 5},
                        {"1ms", 1e-3, 2},      {"3fF", 3e-15, 2},     {"3pF", 3e-12, 2},
                        {"150uH", 150e-6, 4},  {"1kohm", 1e3, 2},     {"2G", 2e9, 2},
                        {"2Ts", 2e12, 2},      {"4k7ohm", 4.7e3, 3},  {"49ohm", 49, 2},
                        {"2.5e-7s", 2.5e-7, 6}};
  for (const Case& c : cases) {
    auto r = scan_si_number(c.text, suffix_only);
    ASSERT_TRUE(r) << c.text;
    EXPECT_DOUBLE_EQ(r->value, c.value) << c.text;
    EXPECT_EQ(r->length, c.length) << c.text;
  }
  double v = 0;
  EXPECT_FALSE(parse_si_number("2.2nF", v, suffix_only));  // "F" is left over
  EXPECT_TRUE(parse_si_number("-2.2n", v, suffix_only));
  EXPECT_EQ(v, -2.2e-9);
}

// Caller rule: lengths (metres) and temperatures take no scale suffix; "12m" is 12 metres.
TEST(SiNumber, NoScaleReadsTheBareNumber) {
  const SiOptions bare{.scale = false, .unit_letters = false};
  auto r = scan_si_number("12m", bare);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->value, 12.0);
  EXPECT_EQ(r->length, 2u);
  r = scan_si_number("4k7", bare);  // no RKM either: the number ends before the letter
  ASSERT_TRUE(r);
  EXPECT_EQ(r->value, 4.0);
  EXPECT_EQ(r->length, 1u);
  r = scan_si_number("1.5e3meg", bare);  // the exponent still belongs to the number
  ASSERT_TRUE(r);
  EXPECT_EQ(r->value, 1500.0);
  EXPECT_EQ(r->length, 5u);
  EXPECT_FALSE(scan_si_number("1e", bare));
  double v = 0;
  EXPECT_TRUE(parse_si_number("-40", v, bare));
  EXPECT_EQ(v, -40.0);
  EXPECT_FALSE(parse_si_number("1k", v, bare));
  // Scale off but unit letters on: letters are a unit, not a scale ("1k" is 1 with unit "k").
  EXPECT_TRUE(parse_si_number("1k", v, {.scale = false, .unit_letters = true}));
  EXPECT_EQ(v, 1.0);
}

TEST(SiNumber, OverflowAndUnderflow) {
  auto big = scan_si_number("1e400");
  ASSERT_TRUE(big);
  EXPECT_TRUE(std::isinf(big->value));
  auto tiny = scan_si_number("1e-400f");
  ASSERT_TRUE(tiny);
  EXPECT_EQ(tiny->value, 0.0);
  // 80 integer digits: the value keeps its magnitude (1e79), not a truncated mantissa.
  auto longnum = scan_si_number(std::string(1, '1') + std::string(79, '0'));
  ASSERT_TRUE(longnum);
  EXPECT_NEAR(longnum->value, 1e79, 1e79 * 1e-12);
}

}  // namespace
}  // namespace isolink
