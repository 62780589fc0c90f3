#include "netlists/traffic/tones.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace isolink::traffic {
namespace {

TEST(Tones, DefaultRunIsEightCoupletsOfOneMicrosecond) {
  const ToneOptions opt;
  EXPECT_EQ(opt.couplets, 8);
  EXPECT_DOUBLE_EQ(opt.pulse, 1e-6);
  EXPECT_NEAR(tone_duration(opt), 16e-6, 1e-18);
  const std::vector<int> h = tone_half_bits(Tone::kWake, opt);
  ASSERT_EQ(h.size(), 16u);
  for (size_t i = 0; i < h.size(); ++i) EXPECT_EQ(h[i], i % 2 == 0 ? +1 : -1) << i;
}

TEST(Tones, PolarityAssumption) {
  EXPECT_EQ(tone_polarity(Tone::kWake), +1);
  EXPECT_EQ(tone_polarity(Tone::kSleepToActive), +1);
  EXPECT_EQ(tone_polarity(Tone::kHeartbeat), +1);
  EXPECT_EQ(tone_polarity(Tone::kShutdown), -1);
  EXPECT_EQ(tone_polarity(Tone::kFault), -1);
  ToneOptions opt;
  opt.couplets = 3;
  EXPECT_EQ(tone_half_bits(Tone::kShutdown, opt), (std::vector<int>{-1, +1, -1, +1, -1, +1}));
}

TEST(Tones, NamesRoundTripAndUnknownNameIsListed) {
  for (Tone t :
       {Tone::kWake, Tone::kSleepToActive, Tone::kShutdown, Tone::kHeartbeat, Tone::kFault}) {
    StatusOr<Tone> p = parse_tone(tone_name(t));
    ASSERT_TRUE(p.ok());
    EXPECT_EQ(*p, t);
  }
  StatusOr<Tone> a = parse_tone("STOA");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(*a, Tone::kSleepToActive);
  StatusOr<Tone> bad = parse_tone("wakeup");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("unknown tone 'wakeup'"), std::string::npos);
  EXPECT_NE(bad.status().message().find("sleep-to-active"), std::string::npos);
}

TEST(Tones, ValidateNamesBadOptions) {
  ToneOptions opt;
  opt.couplets = 0;
  EXPECT_NE(validate(opt).message().find("couplets=0"), std::string::npos);
  opt = {};
  opt.pulse = -1e-6;
  EXPECT_NE(validate(opt).message().find("pulse width"), std::string::npos);
  EXPECT_TRUE(validate(ToneOptions{}).ok());
}

}  // namespace
}  // namespace isolink::traffic
