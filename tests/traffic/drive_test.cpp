#include "netlists/traffic/drive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "netlists/traffic/command.h"

namespace isolink::traffic {
namespace {

constexpr double kTol = 1e-15;  // seconds; times here are sums of a few exact-ish doubles

void expect_segment(const DriveSegment& g, double start_us, double end_us, int level) {
  EXPECT_NEAR(g.start, start_us * 1e-6, kTol);
  EXPECT_NEAR(g.end, end_us * 1e-6, kTol);
  EXPECT_EQ(g.level, level);
}

void expect_contiguous_and_merged(const Drive& d) {
  ASSERT_FALSE(d.segments.empty());
  EXPECT_EQ(d.segments.front().start, 0.0);
  for (size_t i = 0; i < d.segments.size(); ++i) {
    EXPECT_GT(d.segments[i].end, d.segments[i].start) << i;
    if (i > 0) {
      EXPECT_EQ(d.segments[i].start, d.segments[i - 1].end) << i;
      EXPECT_NE(d.segments[i].level, d.segments[i - 1].level) << i;
    }
  }
}

Drive one_frame(const std::vector<uint8_t>& bytes) {
  DriveBuilder b;  // lead 1 us, byte gap 3.8 us, tail 5 us
  EXPECT_TRUE(b.add_frame(bytes, "test").ok());
  return b.finish();
}

TEST(Drive, ZeroByteSegmentsByHand) {
  const Drive d = one_frame({0x00});
  expect_contiguous_and_merged(d);
  // idle, 4 singles, double +, double -, 18 singles, idle: 24 pulses.
  ASSERT_EQ(d.segments.size(), 26u);
  expect_segment(d.segments[0], 0.0, 1.0, 0);
  expect_segment(d.segments[1], 1.0, 1.25, +1);   // preamble
  expect_segment(d.segments[2], 1.25, 1.5, -1);   // sync 0
  expect_segment(d.segments[4], 1.75, 2.0, -1);   // sync 0, first half
  expect_segment(d.segments[5], 2.0, 2.5, +1);    // sync 0 second half + SOF 1 first half
  expect_segment(d.segments[6], 2.5, 3.0, -1);    // SOF 1 second half + bit 0 first half
  expect_segment(d.segments[7], 3.0, 3.25, +1);   // bit 0 second half
  expect_segment(d.segments[24], 7.25, 7.5, -1);  // postamble
  expect_segment(d.segments[25], 7.5, 12.5, 0);   // tail
  EXPECT_NEAR(d.duration(), 12.5e-6, kTol);
  EXPECT_EQ(d.pulses().size(), 24u);
}

TEST(Drive, FfByteSegmentsByHand) {
  const Drive d = one_frame({0xFF});
  expect_contiguous_and_merged(d);
  ASSERT_EQ(d.segments.size(), 26u);
  expect_segment(d.segments[5], 2.0, 2.5, +1);    // sync -> SOF double
  expect_segment(d.segments[6], 2.5, 2.75, -1);   // SOF second half alone
  expect_segment(d.segments[21], 6.25, 6.5, +1);  // bit 7 first half
  expect_segment(d.segments[22], 6.5, 7.0, -1);   // bit 7 second half + error 0 first half
  expect_segment(d.segments[23], 7.0, 7.25, +1);  // error 0 second half
  expect_segment(d.segments[24], 7.25, 7.5, -1);  // postamble
}

TEST(Drive, BytesAreSpacedByTheBytePeriod) {
  const Drive d = one_frame({0x00, 0xFF, 0x12});
  ASSERT_EQ(d.frames.size(), 1u);
  const DriveFrame& f = d.frames[0];
  EXPECT_EQ(f.kind, FrameKind::kData);
  EXPECT_EQ(f.bytes, (std::vector<uint8_t>{0x00, 0xFF, 0x12}));
  ASSERT_EQ(f.byte_starts.size(), 3u);
  EXPECT_NEAR(f.byte_starts[0], 1.0e-6, kTol);
  EXPECT_NEAR(f.byte_starts[1], 11.3e-6, kTol);  // + 6.5 us byte + 3.8 us gap = 10.3 us period
  EXPECT_NEAR(f.byte_starts[2], 21.6e-6, kTol);
  EXPECT_NEAR(f.start, 1.0e-6, kTol);
  EXPECT_NEAR(f.end, 28.1e-6, kTol);
  EXPECT_EQ(d.level_at(8.0e-6), 0);    // idle between bytes
  EXPECT_EQ(d.level_at(11.3e-6), +1);  // next preamble owns its start
  EXPECT_EQ(d.level_at(11.2e-6), 0);
}

TEST(Drive, StackWriteExamplePulseTrain) {
  StatusOr<std::vector<uint8_t>> bytes = command_bytes("stack-write reg=0x0100 data=02B778BC");
  ASSERT_TRUE(bytes.ok());
  const Drive d = one_frame(*bytes);
  expect_contiguous_and_merged(d);
  const std::vector<Pulse> p = d.pulses();
  double on = 0;
  for (const Pulse& q : p) {
    on += q.width;
    const double halves = q.width / 250e-9;
    EXPECT_NEAR(halves, std::round(halves), 1e-6);
    EXPECT_TRUE(std::round(halves) == 1 || std::round(halves) == 2);
  }
  EXPECT_NEAR(on, 9 * 6.5e-6, 1e-12);  // 9 bytes x 13 bit times
  // 9 x 26 half bits minus one per double pulse. A double sits wherever two adjacent wire bits
  // differ (sync 00, SOF 1, data, error 0): B3 6, 01 2, 00 2, 02 4, B7 6, 78 4, BC 6, 0A 6,
  // 35 6 = 42 (counted by hand from the bit strings) -> 234 - 42 = 192 pulses.
  EXPECT_EQ(p.size(), 192u);
  EXPECT_NEAR(d.frames[0].end, (1.0 + 9 * 6.5 + 8 * 3.8) * 1e-6, 1e-12);
}

TEST(Drive, ToneSegmentsAreOneMicrosecond) {
  DriveBuilder b;
  ASSERT_TRUE(b.add_tone(Tone::kShutdown).ok());
  ASSERT_TRUE(b.add_frame({0x00}).ok());
  const Drive d = b.finish();
  expect_contiguous_and_merged(d);
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_EQ(d.frames[0].kind, FrameKind::kTone);
  EXPECT_EQ(d.frames[0].couplets, 8);
  EXPECT_NEAR(d.frames[0].end, 17e-6, kTol);
  for (size_t i = 1; i <= 16; ++i) {
    EXPECT_NEAR(d.segments[i].end - d.segments[i].start, 1e-6, kTol) << i;
    EXPECT_EQ(d.segments[i].level, i % 2 == 1 ? -1 : +1) << i;  // shutdown: - couplets
  }
  // Frame gap 12 us after the tone.
  expect_segment(d.segments[17], 17.0, 29.0, 0);
  EXPECT_NEAR(d.frames[1].start, 29e-6, kTol);
}

TEST(Drive, IdleAddsToTheGap) {
  Timing t;
  t.lead = 0;
  t.tail = 0;
  t.frame_gap = 2e-6;
  DriveBuilder b({}, t);
  ASSERT_TRUE(b.add_frame({0x00}).ok());
  ASSERT_TRUE(b.add_idle(3e-6).ok());
  ASSERT_TRUE(b.add_frame({0x00}).ok());
  EXPECT_FALSE(b.add_idle(-1).ok());
  EXPECT_FALSE(b.add_frame({}).ok());
  const Drive d = b.finish();
  EXPECT_EQ(d.segments.front().level, +1);  // no lead: the preamble starts at 0
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_NEAR(d.frames[1].start, 6.5e-6 + 5e-6, kTol);
  EXPECT_NEAR(d.duration(), 18e-6, kTol);
}

TEST(Drive, CornersAreTheInteriorBoundaries) {
  const Drive d = one_frame({0x00});
  const std::vector<double> c = d.corners();
  ASSERT_EQ(c.size(), 25u);
  EXPECT_NEAR(c.front(), 1.0e-6, kTol);
  EXPECT_NEAR(c[4], 2.0e-6, kTol);
  EXPECT_NEAR(c[5], 2.5e-6, kTol);
  EXPECT_NEAR(c[6], 3.0e-6, kTol);
  EXPECT_NEAR(c.back(), 7.5e-6, kTol);
  for (size_t i = 1; i < c.size(); ++i) EXPECT_GT(c[i], c[i - 1]);
}

TEST(Drive, LevelAt) {
  const Drive d = one_frame({0x00});
  EXPECT_EQ(d.level_at(-1.0), 0);
  EXPECT_EQ(d.level_at(0.5e-6), 0);
  EXPECT_EQ(d.level_at(1.1e-6), +1);
  EXPECT_EQ(d.level_at(1.3e-6), -1);
  EXPECT_EQ(d.level_at(2.7e-6), -1);  // inside the double - (2.5-3.0 us)
  EXPECT_EQ(d.level_at(12.5e-6), 0);
}

TEST(Drive, LineVoltages) {
  EXPECT_DOUBLE_EQ(p_volts(+1), 5.0);
  EXPECT_DOUBLE_EQ(n_volts(+1), 0.0);
  EXPECT_DOUBLE_EQ(p_volts(-1), 0.0);
  EXPECT_DOUBLE_EQ(n_volts(-1), 5.0);
  EXPECT_DOUBLE_EQ(p_volts(0), 2.5);
  EXPECT_DOUBLE_EQ(n_volts(0), 2.5);
}

// Parses "NAME NODE 0 PWL(t v t v ...)" with "+ " continuations into (t, v) pairs.
struct ParsedSource {
  std::string name, node, ground;
  std::vector<std::pair<double, double>> pts;
};
std::vector<ParsedSource> parse_pwl(const std::string& text) {
  std::string joined;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("+ ", 0) == 0) {
      joined += " " + line.substr(2);
    } else {
      if (!joined.empty()) joined += "\n";
      joined += line;
    }
  }
  std::vector<ParsedSource> out;
  std::istringstream lines(joined);
  while (std::getline(lines, line)) {
    ParsedSource s;
    const size_t open = line.find("PWL(");
    const size_t close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos) return {};
    std::istringstream head(line.substr(0, open));
    head >> s.name >> s.node >> s.ground;
    std::istringstream body(line.substr(open + 4, close - open - 4));
    double t, v;
    while (body >> t >> v) s.pts.emplace_back(t, v);
    out.push_back(s);
  }
  return out;
}

TEST(Pwl, ParsesWithMonotonicTimesAndComplementaryLines) {
  const Drive d = one_frame({0x00, 0xFF});
  StatusOr<std::string> text = pwl_sources(d);  // 10 ns edges
  ASSERT_TRUE(text.ok()) << text.status().message();
  const std::vector<ParsedSource> src = parse_pwl(*text);
  ASSERT_EQ(src.size(), 2u);
  EXPECT_EQ(src[0].name, "VTXP");
  EXPECT_EQ(src[0].node, "txp");
  EXPECT_EQ(src[0].ground, "0");
  EXPECT_EQ(src[1].name, "VTXN");
  EXPECT_EQ(src[1].node, "txn");
  const size_t corners = d.corners().size();
  ASSERT_EQ(src[0].pts.size(), 2 + 2 * corners);
  ASSERT_EQ(src[1].pts.size(), src[0].pts.size());
  for (size_t i = 0; i < src[0].pts.size(); ++i) {
    if (i > 0) {
      ASSERT_GT(src[0].pts[i].first, src[0].pts[i - 1].first) << i;
    }
    EXPECT_EQ(src[0].pts[i].first, src[1].pts[i].first);
    EXPECT_DOUBLE_EQ(src[0].pts[i].second + src[1].pts[i].second, 5.0);
    const double v = src[0].pts[i].second;
    EXPECT_TRUE(v == 0.0 || v == 2.5 || v == 5.0) << v;
  }
  // First corner at 1 us, idle -> +: ramp from 0.995 us (2.5 V) to 1.005 us (5 V).
  EXPECT_EQ(src[0].pts[0], (std::pair<double, double>{0.0, 2.5}));
  EXPECT_NEAR(src[0].pts[1].first, 0.995e-6, 1e-15);
  EXPECT_EQ(src[0].pts[1].second, 2.5);
  EXPECT_NEAR(src[0].pts[2].first, 1.005e-6, 1e-15);
  EXPECT_EQ(src[0].pts[2].second, 5.0);
  EXPECT_NEAR(src[0].pts.back().first, d.duration(), 1e-15);
}

TEST(Pwl, EdgeMustFitInsideTheShortestSegment) {
  const Drive d = one_frame({0x00});
  PwlOptions opt;
  opt.edge = 250e-9;
  StatusOr<std::string> bad = pwl_sources(d, opt);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("shorter than the shortest segment"), std::string::npos);
  opt.edge = 0;
  EXPECT_FALSE(pwl_sources(d, opt).ok());
  opt.edge = 249e-9;
  EXPECT_TRUE(pwl_sources(d, opt).ok());
}

// With a 1 ms limit: 97 bytes end at 1 us + 97 x 6.5 us + 96 x 3.8 us = 996.3 us and fit; 98
// would end at 1006.6 us and are refused, and nothing of them is built. A second 250-couplet wake
// tone (500 us) after a first would end at 1 + 500 + 12 + 500 = 1013 us.
TEST(DriveBuilder, ItemsPastTheMaximumDurationAreRefusedUnbuilt) {
  DriveBuilder b;
  ASSERT_TRUE(b.set_max_duration(1e-3).ok());
  Status s = b.add_frame(std::vector<uint8_t>(98, 0x00));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("would last 0.0010066 s by the end of this item; the limit is "
                             "0.001 s"),
            std::string::npos)
      << s.message();
  ASSERT_TRUE(b.add_frame(std::vector<uint8_t>(97, 0x00)).ok());
  Drive d = b.finish();
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_NEAR(d.frames[0].end, 996.3e-6, 1e-12);

  ASSERT_TRUE(b.set_max_duration(1e-3).ok());
  ToneOptions tone;
  tone.couplets = 250;
  ASSERT_TRUE(b.add_tone(Tone::kWake, tone).ok());
  s = b.add_tone(Tone::kWake, tone);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("would last 0.001013 s"), std::string::npos) << s.message();
  d = b.finish();
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_NEAR(d.frames[0].end, 501e-6, 1e-12);
  EXPECT_FALSE(b.set_max_duration(0).ok());
  EXPECT_FALSE(b.set_max_duration(std::nan("")).ok());
}

}  // namespace
}  // namespace isolink::traffic
