#include "eye/pulses.h"

#include <gtest/gtest.h>

#include <random>

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

// Against the definition, sample by sample, on waveforms with long runs on either side of the
// threshold (what find_excursions takes in blocks), ties for the peak and runs of every length
// from 1: sample i lies in an excursion of sign s exactly when s v[i] >= vth; each excursion is
// the whole run [ia, ib); its peak is the run's largest s v, at the first sample that has it.
TEST(Excursions, EveryRunOfSamplesPastTheThresholdIsOneExcursion) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> t, v;
    const double vth = 1.2;
    while (v.size() < 300) {
      const int level = static_cast<int>(rng() % 3) - 1;  // a run below, inside or above
      const size_t len = 1 + rng() % (trial % 2 ? 40 : 9);
      for (size_t k = 0; k < len; ++k) {
        double x = level * (vth + (rng() % 4) * 0.5);  // on the threshold, or 0.5-1.5 V past
        if (level == 0) x = (static_cast<double>(rng() % 5) - 2) * 0.5;  // -1.0 .. 1.0
        v.push_back(x);
        t.push_back(static_cast<double>(t.size()) * ns);
      }
    }
    const std::vector<Excursion> ex = find_excursions(t, v, vth);
    std::vector<int> sign_at(v.size(), 0);
    size_t next = 0;
    for (const Excursion& e : ex) {
      ASSERT_TRUE(e.sign == 1 || e.sign == -1);
      ASSERT_LT(e.ia, e.ib);
      EXPECT_GE(e.ia, next);  // in order, not overlapping
      next = e.ib;
      double peak = -1;
      size_t at = 0;
      for (size_t i = e.ia; i < e.ib; ++i) {
        sign_at[i] = e.sign;
        if (e.sign * v[i] > peak) peak = e.sign * v[i], at = i;
      }
      EXPECT_EQ(e.peak, peak) << "trial " << trial;
      EXPECT_EQ(e.peak_t, t[at]) << "trial " << trial;
      EXPECT_EQ(e.open_start, e.ia == 0);
      EXPECT_EQ(e.open_end, e.ib == v.size());
      if (e.ia > 0) {  // the crossing between the sample before and the first inside
        EXPECT_NEAR(e.a, t[e.ia - 1] + (e.sign * vth - v[e.ia - 1]) / (v[e.ia] - v[e.ia - 1]) * ns,
                    1e-18);
      }
    }
    for (size_t i = 0; i < v.size(); ++i) {
      const int want = v[i] >= vth ? 1 : (v[i] <= -vth ? -1 : 0);
      ASSERT_EQ(sign_at[i], want) << "trial " << trial << " sample " << i;
    }
  }
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
