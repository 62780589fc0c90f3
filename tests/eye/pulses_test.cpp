#include "eye/pulses.h"

#include <gtest/gtest.h>

#include "synth.h"

namespace isolink::eye {
namespace {

constexpr double ns = 1e-9;

// A trapezoid of height h (V) whose threshold excursion (|v| >= 1.2) lasts exactly len: ramps of
// 10 ns from 0 to h, so with h = 2.4 V the 1.2 V crossings are 5 ns into each ramp.
void trapezoid(synth::Pwl& w, double t0, double len, double h) {
  w.add(t0, 0);
  w.add(t0 + 10 * ns, h);
  w.add(t0 + len, h);  // the excursion: t0 + 5 ns .. t0 + len + 5 ns
  w.add(t0 + len + 10 * ns, 0);
}

TEST(Excursions, CrossingsByLinearInterpolation) {
  std::vector<double> t = {0, 1 * ns, 2 * ns, 3 * ns, 4 * ns, 5 * ns, 6 * ns};
  std::vector<double> v = {0, 2.4, 2.0, 0.0, -1.2, -3.6, 0.0};
  auto ex = find_excursions(t, v, 1.2);
  ASSERT_EQ(ex.size(), 2u);
  EXPECT_EQ(ex[0].sign, +1);
  EXPECT_NEAR(ex[0].a, 0.5 * ns, 1e-15);
  EXPECT_NEAR(ex[0].b, 2.4 * ns, 1e-15);  // 2.0 -> 0.0 crosses 1.2 at 0.4 of the step
  EXPECT_DOUBLE_EQ(ex[0].peak, 2.4);
  EXPECT_EQ(ex[1].sign, -1);
  EXPECT_NEAR(ex[1].a, 4 * ns, 1e-15);  // a sample exactly at -1.2 V is past the threshold
  EXPECT_NEAR(ex[1].b, 5.0 * ns + 2.4 / 3.6 * ns, 1e-15);
  EXPECT_DOUBLE_EQ(ex[1].peak, 3.6);
  EXPECT_FALSE(ex[0].open_start);
  EXPECT_FALSE(ex[1].open_end);
}

TEST(Excursions, OpenAtTheRecordEnds) {
  std::vector<double> t = {0, 1 * ns, 2 * ns, 3 * ns};
  std::vector<double> v = {2.0, 0.0, 0.0, -2.0};
  auto ex = find_excursions(t, v, 1.2);
  ASSERT_EQ(ex.size(), 2u);
  EXPECT_TRUE(ex[0].open_start);
  EXPECT_DOUBLE_EQ(ex[0].a, 0.0);
  EXPECT_TRUE(ex[1].open_end);
  EXPECT_DOUBLE_EQ(ex[1].b, 3 * ns);
}

TEST(Segment, SameSignExcursionsLessThan100nsApartMergeWithADip) {
  synth::Pwl w;
  trapezoid(w, 100 * ns, 200 * ns, 2.4);   // excursion 105..305 ns
  trapezoid(w, 394 * ns, 200 * ns, 2.4);   // excursion 399..599: 94 ns gap
  trapezoid(w, 1000 * ns, 200 * ns, 2.4);  // 1005..1205: 406 ns after, separate
  Waveform x = synth::sample(w, 1 * ns, 2e-6);
  Segmentation s = segment(x.time, x.columns[0], SegmentParams{});
  ASSERT_EQ(s.pulses.size(), 2u);
  EXPECT_NEAR(s.pulses[0].a, 105 * ns, 1e-12);
  EXPECT_NEAR(s.pulses[0].b, 599 * ns, 1e-12);
  ASSERT_EQ(s.pulses[0].dips.size(), 1u);
  EXPECT_NEAR(s.pulses[0].dips[0].end - s.pulses[0].dips[0].start, 94 * ns, 1e-12);
  EXPECT_NEAR(s.pulses[0].dips[0].lowest, 0.0, 1e-12);
  EXPECT_TRUE(s.pulses[1].dips.empty());
  // same sign: no transition, two frames
  EXPECT_FALSE(s.joined_next[0]);
  EXPECT_EQ(s.frames.size(), 2u);
}

TEST(Segment, GapOf100nsDoesNotMerge) {
  synth::Pwl w;
  trapezoid(w, 100 * ns, 200 * ns, 2.4);  // 105..305
  trapezoid(w, 400 * ns, 200 * ns, 2.4);  // 405..605: exactly 100 ns gap
  Waveform x = synth::sample(w, 1 * ns, 1e-6);
  Segmentation s = segment(x.time, x.columns[0], SegmentParams{});
  EXPECT_EQ(s.pulses.size(), 2u);
}

TEST(Segment, ShortExcursionIsRingingNotAPulse) {
  synth::Pwl w;
  trapezoid(w, 100 * ns, 99 * ns, 2.4);    // 99 ns: ringing
  trapezoid(w, 500 * ns, 100 * ns, -2.4);  // 100 ns: a pulse
  Waveform x = synth::sample(w, 1 * ns, 1e-6);
  Segmentation s = segment(x.time, x.columns[0], SegmentParams{});
  ASSERT_EQ(s.ringing.size(), 1u);
  EXPECT_NEAR(s.ringing[0].end - s.ringing[0].start, 99 * ns, 1e-12);
  EXPECT_DOUBLE_EQ(s.ringing[0].peak, 2.4);
  EXPECT_EQ(s.ringing[0].sign, +1);
  ASSERT_EQ(s.pulses.size(), 1u);
  EXPECT_EQ(s.pulses[0].sign, -1);
}

TEST(Segment, ShortExcursionsMergeFirstThenCountAsAPulse) {
  synth::Pwl w;
  trapezoid(w, 100 * ns, 40 * ns, 2.4);  // 105..145
  trapezoid(w, 170 * ns, 40 * ns, 2.4);  // 175..215: merged 105..215 = 110 ns
  Waveform x = synth::sample(w, 1 * ns, 1e-6);
  Segmentation s = segment(x.time, x.columns[0], SegmentParams{});
  EXPECT_TRUE(s.ringing.empty());
  ASSERT_EQ(s.pulses.size(), 1u);
  EXPECT_NEAR(s.pulses[0].b - s.pulses[0].a, 110 * ns, 1e-12);
  EXPECT_EQ(s.pulses[0].dips.size(), 1u);
}

TEST(Segment, TransitionsJoinOppositePulsesStartingWithin200ns) {
  synth::Pwl w;
  trapezoid(w, 100 * ns, 200 * ns, 2.4);    // + 105..305
  trapezoid(w, 444 * ns, 200 * ns, -2.4);   // - 449..649: starts 144 ns after: joined
  trapezoid(w, 850 * ns, 200 * ns, 2.4);    // + 855..1055: 206 ns after: new frame
  trapezoid(w, 1254 * ns, 200 * ns, -2.4);  // - 1259..: 204 ns after: new frame
  Waveform x = synth::sample(w, 1 * ns, 2e-6);
  Segmentation s = segment(x.time, x.columns[0], SegmentParams{});
  ASSERT_EQ(s.pulses.size(), 4u);
  EXPECT_TRUE(s.joined_next[0]);
  EXPECT_FALSE(s.joined_next[1]);
  EXPECT_FALSE(s.joined_next[2]);
  ASSERT_EQ(s.frames.size(), 3u);
  EXPECT_EQ(s.frames[0].first, 0u);
  EXPECT_EQ(s.frames[0].last, 1u);
  EXPECT_EQ(s.frames[1].first, 2u);
  EXPECT_EQ(s.frames[2].first, 3u);
}

TEST(Segment, IdealFrameHasExpectedPulseCount) {
  FrameFormat f;
  // 0x00: + | -+ -+ | +- | (-+)x8 | -+ | -  -> + - + - (++) (--) + - + ...
  std::vector<int> hb = frame_half_bits(0x00, f);
  size_t runs = 1;
  for (size_t i = 1; i < hb.size(); ++i) runs += hb[i] != hb[i - 1];
  EXPECT_EQ(runs, 24u);  // two doubles around the SOF
  Waveform x = synth::ideal_frames({0x00}, f);
  Segmentation s = segment(x.time, x.columns[0], SegmentParams{});
  EXPECT_EQ(s.pulses.size(), runs);
  EXPECT_EQ(s.frames.size(), 1u);
}

}  // namespace
}  // namespace isolink::eye
