#include "netlists/traffic/stimulus.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace isolink::traffic {
namespace {

TEST(ParseTime, SpiceSuffixes) {
  struct Case {
    const char* text;
    double seconds;
  };
  const Case cases[] = {{"250n", 250e-9},   {"250ns", 250e-9}, {"1u", 1e-6},     {"1us", 1e-6},
                        {"2.5e-7", 2.5e-7}, {"10ms", 10e-3},   {"3.8U", 3.8e-6}, {"1s", 1.0},
                        {"5p", 5e-12},      {"0", 0.0}};
  for (const Case& c : cases) {
    StatusOr<double> t = parse_time(c.text);
    ASSERT_TRUE(t.ok()) << c.text << ": " << t.status().message();
    EXPECT_NEAR(*t, c.seconds, c.seconds * 1e-12) << c.text;
  }
  // Exactly the literal, not one ulp off (250 * 1e-9 != 250e-9 in doubles).
  EXPECT_EQ(*parse_time("250n"), 250e-9);
  EXPECT_EQ(*parse_time("3.8u"), 3.8e-6);
  EXPECT_FALSE(parse_time("").ok());
  EXPECT_FALSE(parse_time("fast").ok());
  EXPECT_NE(parse_time("10x").status().message().find("unknown unit suffix 'x'"),
            std::string::npos);
  EXPECT_NE(parse_time("10nsec").status().message().find("trailing text"), std::string::npos);
}

// Times come from the one scanner (base/si_number.h): its whole suffix set, exact decimals, and
// the traffic rule on top (the unit may only be "s").
TEST(ParseTime, SharedScannerRules) {
  EXPECT_EQ(*parse_time("1mil"), 25.4e-6);
  EXPECT_EQ(*parse_time("2t"), 2e12);
  EXPECT_EQ(*parse_time("1u5"), 1.5e-6);  // RKM
  EXPECT_EQ(*parse_time(" 20US "), 20e-6);
  EXPECT_EQ(*parse_time("1megs"), 1e6);
  EXPECT_EQ(*parse_time("-1n"), -1e-9);  // the sign is read; callers check the range
  EXPECT_FALSE(parse_time("1e").ok());
  EXPECT_FALSE(parse_time("1nF").ok());
  EXPECT_NE(parse_time("10 us").status().message().find("unknown unit suffix ' us'"),
            std::string::npos);
  EXPECT_NE(parse_time("1e400").status().message().find("not a finite time"), std::string::npos);
}

TEST(Stimulus, ScriptBuildsItemsInOrder) {
  StatusOr<Drive> d = build_drive(
      "wake couplets=2; stack-read reg=0x0215 n=12 # comment\n"
      "pattern alt bytes=2; idle 20u; tone fault couplets=1 pulse=2u");
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->frames.size(), 4u);
  EXPECT_EQ(d->frames[0].kind, FrameKind::kTone);
  EXPECT_EQ(d->frames[0].couplets, 2);
  EXPECT_NEAR(d->frames[0].start, 1e-6, 1e-15);  // lead
  EXPECT_NEAR(d->frames[0].end, 5e-6, 1e-15);    // 2 couplets x 2 x 1 us
  EXPECT_EQ(d->frames[1].label, "stack-read reg=0x0215 n=12");
  EXPECT_EQ(d->frames[1].bytes, (std::vector<uint8_t>{0xA0, 0x02, 0x15, 0x0B, 0xCC, 0xB3}));
  EXPECT_NEAR(d->frames[1].start, 17e-6, 1e-15);  // + 12 us frame gap
  EXPECT_EQ(d->frames[2].label, "alt");
  EXPECT_EQ(d->frames[2].bytes, (std::vector<uint8_t>{0x55, 0xAA}));
  EXPECT_EQ(d->frames[3].kind, FrameKind::kTone);
  EXPECT_EQ(d->frames[3].tone, Tone::kFault);
  // idle 20u adds to the 12 us frame gap.
  EXPECT_NEAR(d->frames[3].start - d->frames[2].end, 32e-6, 1e-12);
  EXPECT_NEAR(d->frames[3].end - d->frames[3].start, 4e-6, 1e-12);  // 1 couplet of 2 us pulses
  EXPECT_NEAR(d->duration(), d->frames[3].end + 5e-6, 1e-12);       // tail
}

TEST(Stimulus, OptionsReachTheEncoder) {
  StimulusOptions opt;
  opt.encoding.half_bit = 500e-9;
  opt.encoding.sof = false;
  opt.timing.lead = 0;
  opt.timing.tail = 0;
  StatusOr<Drive> d = build_drive("raw 00 nocrc", opt);
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_NEAR(d->duration(), 24 * 500e-9, 1e-15);  // 12 bit times without SOF
  EXPECT_EQ(d->segments.size(), 24u);              // no SOF: no double pulse in 0x00
}

TEST(Stimulus, ErrorsNameTheItem) {
  StatusOr<Drive> d = build_drive("wake; stack-read reg=0x0215 n=200");
  ASSERT_FALSE(d.ok());
  const std::string& m = d.status().message();
  EXPECT_NE(m.find("item 2 (stack-read reg=0x0215 n=200)"), std::string::npos) << m;
  EXPECT_NE(m.find("n=200 is out of range"), std::string::npos) << m;

  d = build_drive("jump");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("unknown item 'jump'"), std::string::npos);
  d = build_drive("pattern prbs7 bytes=0");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("bytes=0 is out of range"), std::string::npos);
  d = build_drive("tone wake couplets=0");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("couplets=0 is out of range"), std::string::npos);
  d = build_drive("idle");
  ASSERT_FALSE(d.ok());
  d = build_drive(" ; # only a comment");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("stimulus is empty"), std::string::npos);
}

TEST(Stimulus, GapSetsTheIdleBeforeTheNextItemExactly) {
  // gap replaces the 1 us lead and the 12 us frame gap; idle still adds to it.
  StatusOr<Drive> d = build_drive(
      "gap 2u; raw 5A nocrc; gap 3.85u; raw 35 nocrc err; "
      "idle 1u; gap 4u; raw 00 nocrc");
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->frames.size(), 3u);
  const double frame = 6.5e-6;
  EXPECT_NEAR(d->frames[0].start, 2e-6, 1e-15);
  EXPECT_NEAR(d->frames[1].start, 2e-6 + frame + 3.85e-6, 1e-15);
  EXPECT_NEAR(d->frames[2].start, d->frames[1].end + 5e-6, 1e-15);
  // err: the second byte carries the error bit: its last bit is (+, -), so the half bit before
  // the postamble is -, touching it (one 500 ns negative pulse at the end).
  EXPECT_EQ(d->level_at(d->frames[1].end - 0.6e-6), +1);
  EXPECT_EQ(d->level_at(d->frames[1].end - 0.4e-6), -1);
  EXPECT_EQ(d->level_at(d->frames[0].end - 0.4e-6), +1);  // 0x5A with error bit 0: (-, +)
  EXPECT_FALSE(build_drive("gap -1u; raw 00 nocrc").ok());
  EXPECT_NE(build_drive("gap; raw 00").status().message().find("gap: expected one time"),
            std::string::npos);
}

// An item that would take the traffic past kMaxDriveSeconds is refused before it is built: one
// 'pattern prbs15 bytes=999999' is 1 us lead + 999,999 x 6.5 us frames + 999,998 x 3.8 us gaps =
// 10.2999869 s (20 M segments, 0.5 GB, were built before the end-of-script check saw that).
TEST(Stimulus, ItemPastTheLimitIsRefusedBeforeItIsBuilt) {
  StatusOr<Drive> d = build_drive("wake; pattern prbs15 bytes=999999; pattern all256 bytes=999999");
  ASSERT_FALSE(d.ok());
  const std::string& m = d.status().message();
  EXPECT_NE(m.find("item 2 (pattern prbs15 bytes=999999): the traffic would last 10.3 s by the "
                   "end of this item; the limit is 1 s"),
            std::string::npos)
      << m;
  // A pattern that fits (97,000 bytes: 0.999 s) still builds, and idle still counts at the end.
  d = build_drive("pattern alt bytes=97000");
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_NEAR(d->duration(), 1e-6 + 97000 * 6.5e-6 + 96999 * 3.8e-6 + 5e-6, 1e-9);
  d = build_drive("pattern alt bytes=97000; idle 10m");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("the traffic lasts 1.0091 s; the limit is 1 s"),
            std::string::npos)
      << d.status().message();
  // Tones of 100,000 couplets of 1 ns pulses last 0.2 ms each but are 200,000 segments (and one
  // idle before each): the 20th would end at 20 x 200,001 = 4,000,020 segments.
  std::string tones;
  for (int i = 0; i < 21; ++i) tones += "tone wake couplets=100000 pulse=1n;";
  d = build_drive(tones);
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("item 20 (tone wake couplets=100000 pulse=1n): the traffic "
                                      "would have up to 4000020 level segments by the end of "
                                      "this item; the limit is 4000000"),
            std::string::npos)
      << d.status().message();
}

}  // namespace
}  // namespace isolink::traffic
