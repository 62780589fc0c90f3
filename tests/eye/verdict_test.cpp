// The verdict rule (eye/verdict.h, eye/README.md "Verdict"), one record of each kind, synthesized
// here: a clean link passes; a link whose pulses have the daisy-chain's timing but fail their
// rules fails, even when nothing decodes; records that cannot show the link (no pulses, an
// unrelated sine or square wave, the wrong column, mV read as V, a record cut in its only frame,
// P and N swapped) are inconclusive. Each asserts the verdict and the reason's text.
#include "eye/verdict.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "eye/check.h"
#include "synth.h"

namespace isolink::eye {
namespace {

const std::vector<uint8_t> kCommand = {0x80, 0x00, 0x02, 0x15, 0x0B, 0xCB, 0x49};

CheckResult check(const Waveform& w) {
  StatusOr<Rules> rules = load_rules("bq7961x");
  EXPECT_TRUE(rules.ok());
  StatusOr<CheckResult> r = check_waveform(w, *rules);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return *r;
}

// The record's reasons, one a line, for failure messages.
std::string reasons(const CheckResult& r) {
  std::string s;
  for (const std::string& x : r.reasons) s += x + "\n";
  return s;
}
bool has_reason(const CheckResult& r, const std::string& text) {
  for (const std::string& x : r.reasons)
    if (x.find(text) != std::string::npos) return true;
  return false;
}

// A failing link as ngspice shows a long cap-only cable: half bits of T = 207 ns (widths 207 ns,
// under the 220 ns window), 1.5 V pulses (VSTART under 1.6 V), full-swing edges of 89 ns (the
// +/-1.2 V crossings 71 ns apart, over 60 ns), and inter-symbol interference moving the end of
// every double pulse 50 ns early (364 ns: it reads as one half bit, so no frame forms a byte; a
// pulse after it gains the 50 ns).
Waveform failing_link(double scale = 1.0) {
  synth::Pwl w;
  double t0 = 1e-6;
  for (uint8_t b : kCommand) {
    synth::Train tr;
    tr.t0 = t0;
    tr.T = 207e-9;
    tr.tr = 89e-9;
    tr.pulses = synth::pulses_from_half_bits(frame_half_bits(b, FrameFormat{}), 1.5);
    for (synth::Pulse& p : tr.pulses)
      if (p.k == 2) p.shift = -50e-9;
    synth::append_train(w, tr);
    t0 = tr.end() + 2e-6;
  }
  Waveform out = synth::sample(w, 1e-9, t0);
  for (double& x : out.columns[0]) x *= scale;
  return out;
}

Waveform from_function(double t_end, double dt, double (*f)(double)) {
  Waveform w;
  std::vector<double> v;
  for (double t = 0; t <= t_end; t += dt) {
    w.time.push_back(t);
    v.push_back(f(t));
  }
  w.add_column("v", std::move(v));
  return w;
}

TEST(Verdict, CleanLinkPasses) {
  const CheckResult r = check(synth::ideal_frames(kCommand, FrameFormat{}));
  EXPECT_STREQ(r.verdict(), "pass") << reasons(r);
  EXPECT_TRUE(r.reasons.empty());
  EXPECT_EQ(r.bytes, kCommand);
}

TEST(Verdict, FailingDaisyChainPulsesFailEvenWhenNothingDecodes) {
  const CheckResult r = check(failing_link());
  EXPECT_TRUE(r.bytes.empty()) << reasons(r);
  EXPECT_STREQ(r.verdict(), "fail") << reasons(r);
  EXPECT_FALSE(r.pass);
  EXPECT_FALSE(r.inconclusive);
  // every pulse fails VSTART (1.5 V < 1.6 V); the widths are those built in
  EXPECT_EQ(r.failing(), r.pulses.size());
  ASSERT_TRUE(r.width_min().has_value());
  EXPECT_NEAR(*r.width_min() * 1e9, 207, 1.0);
  ASSERT_TRUE(r.edge_max().has_value());
  EXPECT_NEAR(*r.edge_max() * 1e9, 0.8 * 89, 1.0);  // 2.4 V of a 3 V swing in 89 ns
  EXPECT_TRUE(has_reason(r, fmt::format("{} of {} pulses fail", r.pulses.size(), r.pulses.size())))
      << reasons(r);
  EXPECT_TRUE(has_reason(r,
                         "no frame decodes: 150 pulses in 7 runs, none forms a byte, but "
                         "pulses 22..44 (23 in a row, widths 207-414 ns) have the "
                         "daisy-chain's timing and 150 of 150 pulses fail their rules"))
      << reasons(r);
  EXPECT_TRUE(has_reason(r, "pulses fail their rules: a failed link")) << reasons(r);

  // the run itself: a frame's pulses, widths 207 ns (one half bit) to 414 ns (2 x 207 ns)
  StatusOr<Rules> rules = load_rules("bq7961x");
  const std::optional<ChainRun> run = daisy_chain_run(r.pulses, *rules);
  ASSERT_TRUE(run.has_value());
  EXPECT_GE(run->pulses, kChainRunPulses);
  EXPECT_GE(run->singles, kChainRunSingles);
  EXPECT_NEAR(run->width_min * 1e9, 207, 1.0);
  EXPECT_NEAR(run->width_max * 1e9, 414, 1.0);
}

TEST(Verdict, NoPulsesIsInconclusive) {
  const CheckResult r =
      check(from_function(20e-6, 1e-9, [](double t) { return 0.8 * std::sin(2e7 * t); }));
  EXPECT_STREQ(r.verdict(), "inconclusive");
  ASSERT_EQ(r.reasons.size(), 1u);
  EXPECT_EQ(r.reasons[0], "no pulses: nothing stays past +/-1.2 V for 100 ns (largest |v| 0.8 V)");
}

TEST(Verdict, UnrelatedSineIsInconclusive) {
  // 100 kHz, 3 V: 3.6 us pulses, each alone in its run (its edges take over 200 ns)
  const CheckResult r = check(from_function(
      50e-6, 2e-9, [](double t) { return 3.0 * std::sin(2 * std::numbers::pi * 1e5 * t); }));
  EXPECT_STREQ(r.verdict(), "inconclusive") << reasons(r);
  EXPECT_TRUE(has_reason(r,
                         "and no 8 pulses in a row have the daisy-chain's timing "
                         "(alternating, widths 125-625 ns, 4 of one half bit): the record "
                         "does not show the link"))
      << reasons(r);
}

TEST(Verdict, SquareWaveAtAnotherRateIsInconclusive) {
  // 1 MHz, +/-2 V, 16 ns edges (a clipped sine): alternating 500 ns pulses in one run, but none of
  // one half bit
  const CheckResult r = check(from_function(30e-6, 1e-9, [](double t) {
    return 2.0 * std::clamp(20 * std::sin(2 * std::numbers::pi * 1e6 * t), -1.0, 1.0);
  }));
  EXPECT_STREQ(r.verdict(), "inconclusive") << reasons(r);
  EXPECT_GT(r.pulses.size(), 50u);
  EXPECT_TRUE(has_reason(r, "the record does not show the link")) << reasons(r);
}

TEST(Verdict, WrongColumnIsInconclusive) {
  // the time column read as the differential: 0 .. 20 us "volts"
  Waveform w = synth::ideal_frames(kCommand, FrameFormat{});
  w.columns[0] = w.time;
  CheckResult r = check(w);
  EXPECT_STREQ(r.verdict(), "inconclusive");
  ASSERT_EQ(r.reasons.size(), 1u);
  EXPECT_EQ(r.reasons[0].rfind("no pulses: nothing stays past +/-1.2 V", 0), 0u) << r.reasons[0];
  // a supply rail: one 3.3 V level from start to end, a pulse cut at both ends
  for (double& x : w.columns[0]) x = 3.3;
  r = check(w);
  EXPECT_STREQ(r.verdict(), "inconclusive") << reasons(r);
  EXPECT_TRUE(has_reason(r, "the record does not show the link")) << reasons(r);
  EXPECT_TRUE(has_reason(r, "the record cuts 1 pulse")) << reasons(r);
}

TEST(Verdict, MillivoltsReadAsVoltsAreInconclusive) {
  // a clean link and a failing one, both 1000x too large: no verdict either way
  for (const Waveform& w : {[] {
                              Waveform x = synth::ideal_frames(kCommand, FrameFormat{});
                              for (double& v : x.columns[0]) v *= 1e3;
                              return x;
                            }(),
                            failing_link(1e3)}) {
    const CheckResult r = check(w);
    EXPECT_STREQ(r.verdict(), "inconclusive") << reasons(r);
    EXPECT_TRUE(has_reason(r, "V: no daisy-chain signal as read")) << reasons(r);
  }
  // volts read as kV (or mV data scaled twice): 2 mV peaks, no pulses
  Waveform x = synth::ideal_frames(kCommand, FrameFormat{});
  for (double& v : x.columns[0]) v *= 1e-3;
  const CheckResult r = check(x);
  EXPECT_STREQ(r.verdict(), "inconclusive");
  EXPECT_EQ(r.reasons.at(0),
            "no pulses: nothing stays past +/-1.2 V for 100 ns (largest |v| 0.002 V)");
}

TEST(Verdict, RecordCutInItsOnlyFrameIsInconclusive) {
  // one frame, the record ending inside its 12th pulse: 11 good pulses, nothing decodes
  const Waveform full = synth::ideal_frames({0xCB}, FrameFormat{});
  const CheckResult whole = check(full);
  ASSERT_STREQ(whole.verdict(), "pass");
  const double cut = whole.pulses.at(11).a + 50e-9;
  Waveform w;
  std::vector<double> v;
  for (size_t i = 0; i < full.samples() && full.time[i] <= cut; ++i) {
    w.time.push_back(full.time[i]);
    v.push_back(full.columns[0][i]);
  }
  w.add_column("v", std::move(v));
  const CheckResult r = check(w);
  EXPECT_STREQ(r.verdict(), "inconclusive") << reasons(r);
  EXPECT_EQ(r.failing(), 0u);
  EXPECT_TRUE(has_reason(r, "have the daisy-chain's timing and meet the rules")) << reasons(r);
  EXPECT_TRUE(has_reason(r, "the record cuts 1 pulse")) << reasons(r);
}

TEST(Verdict, SwappedPAndNAreInconclusive) {
  // good pulses that decode only with the signs flipped: a misread record, not a failed link
  Waveform w = synth::ideal_frames(kCommand, FrameFormat{});
  for (double& x : w.columns[0]) x = -x;
  const CheckResult r = check(w);
  EXPECT_STREQ(r.verdict(), "inconclusive") << reasons(r);
  EXPECT_TRUE(has_reason(r, "meet the rules: P and N swapped")) << reasons(r);
}

TEST(Verdict, RunNeedsEnoughAlternatingPulsesOfTheHalfBitsTiming) {
  StatusOr<Rules> rules = load_rules("bq7961x");
  auto pulse = [](int sign, double width) {
    PulseMetrics p;
    p.sign = sign;
    p.width.value = width;
    return p;
  };
  std::vector<PulseMetrics> ps;
  for (int i = 0; i < 7; ++i) ps.push_back(pulse(i % 2 ? -1 : 1, 250e-9));
  EXPECT_FALSE(daisy_chain_run(ps, *rules).has_value());  // 7 < 8
  ps.push_back(pulse(-1, 600e-9));                        // 8th, 2.4 T: inside the window
  ASSERT_TRUE(daisy_chain_run(ps, *rules).has_value());
  EXPECT_EQ(daisy_chain_run(ps, *rules)->pulses, 8u);
  ps.back().width.value = 630e-9;  // 2.52 T: outside
  EXPECT_FALSE(daisy_chain_run(ps, *rules).has_value());
  ps.back().width.value = 250e-9;
  ps.back().sign = +1;  // same sign as the one before: no run through it
  EXPECT_FALSE(daisy_chain_run(ps, *rules).has_value());
  ps.back().sign = -1;
  for (int i = 0; i < 8; ++i) ps[i].width.value = 500e-9;  // double bits only: no single half bit
  for (int i = 0; i < 3; ++i) ps[i].width.value = 250e-9;  // 3 singles < 4
  EXPECT_FALSE(daisy_chain_run(ps, *rules).has_value());
  ps[3].width.value = 120e-9;  // 0.48 T: under the window, breaks the run
  EXPECT_FALSE(daisy_chain_run(ps, *rules).has_value());
  ps[3].width.value = 130e-9;  // 0.52 T: a fourth single
  EXPECT_TRUE(daisy_chain_run(ps, *rules).has_value());
}

}  // namespace
}  // namespace isolink::eye
