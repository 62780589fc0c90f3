// Synthetic waveforms just inside and just outside every limit of docs/physics.md section 8 ("Eye
// metrics"). Frames are byte 0x00 (preamble, sync, SOF, data, error bit, postamble): its pulses are
// 0 +, 1 -, 2 +, 3 -, 4 ++ (double), 5 -- (double), 6 +, ...; V = 2 V, edges 20 ns full swing.
#include "eye/metrics.h"

#include <gtest/gtest.h>

#include "eye/check.h"
#include "synth.h"

namespace isolink::eye {
namespace {

constexpr double ns = 1e-9;

synth::Train frame_train(uint8_t byte = 0x00) {
  synth::Train t;
  t.pulses = synth::pulses_from_half_bits(frame_half_bits(byte, FrameFormat{}));
  return t;
}

Waveform render(const synth::Train& tr, const std::vector<synth::Pwl>& overlays = {},
                double noise = 0) {
  synth::Pwl w;
  synth::append_train(w, tr);
  return synth::sample(w, 1 * ns, tr.end() + 6e-6, overlays, noise);
}

CheckResult run(const Waveform& w, const char* rules = "bq7961x") {
  StatusOr<Rules> r = load_rules(rules);
  EXPECT_TRUE(r.ok()) << r.status().message();
  StatusOr<CheckResult> c = check_waveform(w, *r);
  EXPECT_TRUE(c.ok()) << c.status().message();
  return *c;
}

bool has_fail(const PulseMetrics& p, const std::string& metric) {
  for (const auto& f : p.fails)
    if (f.rfind(metric + ":", 0) == 0) return true;
  return false;
}

TEST(Metrics, IdealFrameNumbers) {
  CheckResult r = run(render(frame_train()));
  EXPECT_TRUE(r.pass);
  ASSERT_EQ(r.pulses.size(), 24u);
  for (const PulseMetrics& p : r.pulses) {
    if (!p.idle) {
      EXPECT_NEAR(p.width.value, p.k * 250 * ns, 0.01 * ns) << p.index;
    }
    if (p.index > 0) {
      EXPECT_NEAR(p.edge.value, 12 * ns, 0.01 * ns) << p.index;  // 0.6 * tr
    }
    EXPECT_NEAR(p.vstart.value, 2.0, 1e-9);
    EXPECT_NEAR(p.vend.value, 2.0, 1e-9);
  }
  EXPECT_FALSE(r.pulses[0].edge.measured());
  EXPECT_EQ(r.pulses[4].k, 2);
  EXPECT_TRUE(r.pulses.back().idle);
  // postamble runs into idle: b - a = 250 ns - 6 ns - 6 ns (crossings 6 ns from each boundary)
  EXPECT_NEAR(r.pulses.back().width.value, 250 * ns - 12 * ns, 0.01 * ns);
  EXPECT_FALSE(r.pulses.back().width.judged());
}

// thigh / tlow 219 / 221 / 279 / 281 ns: moving one boundary by d lengthens pulse 2 by d and
// shortens pulse 3 by d.
TEST(Metrics, WidthLimits) {
  struct Case {
    double d;
    bool pass;
  };
  for (Case c : {Case{-31, false}, Case{-29, true}, Case{29, true}, Case{31, false}}) {
    synth::Train t = frame_train();
    t.pulses[2].shift = c.d * ns;
    CheckResult r = run(render(t));
    ASSERT_EQ(r.pulses.size(), 24u);
    EXPECT_NEAR(r.pulses[2].width.value, (250 + c.d) * ns, 0.01 * ns);
    EXPECT_NEAR(r.pulses[3].width.value, (250 - c.d) * ns, 0.01 * ns);
    EXPECT_EQ(r.pass, c.pass) << c.d;
    EXPECT_NEAR(r.pulses[2].width.margin, (c.d < 0 ? 250 + c.d - 220 : 280 - 250 - c.d) * ns,
                0.01 * ns);
    EXPECT_EQ(has_fail(r.pulses[2], "width"), !c.pass);
    EXPECT_EQ(has_fail(r.pulses[3], "width"), !c.pass);
    EXPECT_NEAR(*r.width_min(), (250 - std::abs(c.d)) * ns, 0.01 * ns);
    if (!c.pass) {
      ASSERT_FALSE(r.frames.empty());
      EXPECT_EQ(r.frames[0].fault, "timing");
      EXPECT_FALSE(r.frames[0].byte.has_value());
    }
  }
}

TEST(Metrics, DoublePulseWidthLimits) {
  for (double d : {29.0, 31.0}) {
    synth::Train t = frame_train();
    t.pulses[4].shift = d * ns;  // the ++ double: 500 + d
    CheckResult r = run(render(t));
    EXPECT_EQ(r.pulses[4].k, 2);
    EXPECT_NEAR(r.pulses[4].width.value, (500 + d) * ns, 0.01 * ns);
    EXPECT_EQ(r.pass, d < 30) << d;
    EXPECT_EQ(has_fail(r.pulses[4], "width"), d > 30);
  }
}

// Edge 59 / 61 ns: with V = 2.4 V the +/-1.2 V crossings are half the full-swing time apart.
TEST(Metrics, EdgeLimits) {
  for (double e : {59.0, 61.0}) {
    synth::Train t = frame_train();
    t.tr = 2 * e * ns;
    for (auto& p : t.pulses) p.vstart = p.vend = 2.4;
    CheckResult r = run(render(t));
    ASSERT_EQ(r.pulses.size(), 24u);
    ASSERT_TRUE(r.edge_max().has_value());
    EXPECT_NEAR(*r.edge_max(), e * ns, 0.01 * ns);
    EXPECT_NEAR(r.pulses[5].edge.value, e * ns, 0.01 * ns);
    EXPECT_NEAR(r.pulses[5].edge.margin, (60 - e) * ns, 0.01 * ns);
    EXPECT_EQ(r.pass, e < 60);
    EXPECT_EQ(has_fail(r.pulses[5], "edge"), e > 60);
    // widths are untouched by symmetric edges
    EXPECT_NEAR(r.pulses[2].width.value, 250 * ns, 0.01 * ns);
  }
}

// VSTART 1.59 / 1.61 V with VEND 1.35 V; VEND 1.25 V with VSTART 1.69 / 1.71 V (bq7961x).
TEST(Metrics, StartAmplitudeLimits) {
  struct Case {
    double vstart, vend;
    bool pass;
    double needed;
  };
  for (Case c : {Case{1.59, 1.35, false, 1.6}, Case{1.61, 1.35, true, 1.6},
                 Case{1.69, 1.25, false, 1.7}, Case{1.71, 1.25, true, 1.7}}) {
    synth::Train t = frame_train();
    t.pulses[2].vstart = c.vstart;
    t.pulses[2].vend = c.vend;
    CheckResult r = run(render(t));
    ASSERT_EQ(r.pulses.size(), 24u);
    const PulseMetrics& p = r.pulses[2];
    EXPECT_NEAR(p.vstart.value, c.vstart, 1e-3);
    EXPECT_NEAR(p.vend.value, c.vend, 1e-3);
    EXPECT_NEAR(p.vstart.limit, c.needed, 1e-12);
    EXPECT_NEAR(p.vstart.margin, c.vstart - c.needed, 1e-3);
    EXPECT_EQ(r.pass, c.pass) << c.vstart << " " << c.vend;
    EXPECT_EQ(has_fail(p, "vstart"), !c.pass);
    EXPECT_FALSE(has_fail(p, "vend"));
    EXPECT_NEAR(*r.vstart_min(), c.vstart, 1e-3);
    EXPECT_NEAR(*r.vend_min(), c.vend, 1e-3);
    if (!c.pass) {
      EXPECT_EQ(r.frames[0].fault, "weak bit");
      ASSERT_FALSE(r.worst.empty());
      EXPECT_EQ(r.worst[0].metric, "vstart");
      EXPECT_EQ(r.worst[0].pulse, 2u);
      EXPECT_NEAR(r.worst[0].j.margin, c.vstart - c.needed, 1e-3);
    }
  }
}

// BQ79600 bridge: VSTART >= 1.8 V and VEND >= 1.2 V whatever VEND.
TEST(Metrics, BridgeStartAmplitude) {
  for (double vs : {1.79, 1.81}) {
    synth::Train t = frame_train();
    t.pulses[6].vstart = vs;
    t.pulses[6].vend = 1.5;
    CheckResult r = run(render(t), "bq79600");
    EXPECT_NEAR(r.pulses[6].vstart.value, vs, 1e-3);
    EXPECT_NEAR(r.pulses[6].vstart.limit, 1.8, 1e-12);
    EXPECT_EQ(r.pass, vs > 1.8);
    // the same pulse passes the stack-device rule (VEND 1.5 V > 1.3 V needs only 1.6 V)
    EXPECT_TRUE(run(render(t)).pass);
  }
}

// VEND 1.19 V read 20 ns before b: the droop holds 1.19 V, then a late bump back over 1.2 V
// just before the trailing edge ends the pulse (so the sag is a dip inside the pulse).
//   droop 2.0 V (B0+10) -> 1.19 V (B1-40), held to B1-10, edge to -2 V at B1+10;
//   bump +0.2 V from B1-18 (rising 4 ns) to B1-6: b = B1-10 + 20*(0.19/3.19) ns = B1-8.809 ns,
//   so b - 20 ns = B1-28.8 ns lies in the 1.19 V hold.
TEST(Metrics, EndAmplitudeBelowLimit) {
  synth::Train t = frame_train();
  t.pulses[2].vend = 1.19;
  const double b1 = t.boundary(3);
  synth::Pwl bump;
  bump.add(b1 - 18 * ns, 0);
  bump.add(b1 - 14 * ns, 0.2);
  bump.add(b1 - 6 * ns, 0.2);
  bump.add(b1 - 5.999 * ns, 0);
  CheckResult r = run(render(t, {bump}));
  ASSERT_EQ(r.pulses.size(), 24u);
  const PulseMetrics& p = r.pulses[2];
  EXPECT_NEAR(p.b, b1 - 10 * ns + 20 * ns * 0.19 / 3.19, 0.01 * ns);
  EXPECT_NEAR(p.vend.value, 1.19, 1e-3);
  EXPECT_NEAR(p.vend.margin, -0.01, 1e-3);
  EXPECT_TRUE(has_fail(p, "vend"));
  EXPECT_TRUE(has_fail(p, "dip"));
  EXPECT_FALSE(r.pass);
  EXPECT_NEAR(*r.vend_min(), 1.19, 1e-3);
}

// Without the bump the same droop simply ends the excursion where it crosses 1.2 V
// (B0+10 + 200*(0.8/0.81) ns) and VEND is read on the droop 20 ns earlier: 1.2 + 0.81*20/200 V.
TEST(Metrics, DroopBelowThresholdEndsTheExcursionEarly) {
  synth::Train t = frame_train();
  t.pulses[2].vend = 1.19;
  const double b0 = t.boundary(2);
  CheckResult r = run(render(t));
  const PulseMetrics& p = r.pulses[2];
  EXPECT_NEAR(p.b, b0 + 10 * ns + 200 * ns * 0.8 / 0.81, 0.01 * ns);
  EXPECT_NEAR(p.vend.value, 1.2 + 0.81 * 20.0 / 200.0, 1e-3);
  // the edge into pulse 3 now runs from b to a_next = B1 - 10 + 20*(2.39/3.19) ns
  EXPECT_NEAR(r.pulses[3].edge.value, (250 - 10 + 20 * 2.39 / 3.19 - 10 - 200 * 0.8 / 0.81) * ns,
              0.01 * ns);
}

// Exponential droop on a double pulse: VSTART 2.5 V, tau 800 ns; droop over 1 V is a warning.
TEST(Metrics, ExponentialDroopWarning) {
  synth::Train t = frame_train();
  synth::Pulse& p4 = t.pulses[4];
  p4.vstart = 2.5;
  p4.tau = 800 * ns;
  const double B0 = t.boundary(4), B1 = t.boundary(5);
  const double L = 2.5 * std::exp(-(B1 - 10 * ns - (B0 + 10 * ns)) / p4.tau);
  const double b = B1 - 10 * ns + 20 * ns * (L - 1.2) / (L + 2.0);
  const double vend = 2.5 * std::exp(-(b - 20 * ns - (B0 + 10 * ns)) / p4.tau);
  ASSERT_NEAR(vend, 1.405,
              0.001);  // hand check: b - 20 ns - t_top = 461.02 ns, 2.5 * exp(-461.02 / 800)
  CheckResult r = run(render(t));
  const PulseMetrics& m = r.pulses[4];
  EXPECT_EQ(m.k, 2);
  EXPECT_NEAR(m.b, b, 0.01 * ns);
  EXPECT_NEAR(m.vstart.value, 2.5, 1e-3);
  EXPECT_NEAR(m.vend.value, vend, 1e-3);
  EXPECT_NEAR(m.droop.value, 2.5 - vend, 1e-3);
  ASSERT_EQ(m.warnings.size(), 1u);
  EXPECT_EQ(m.warnings[0].rfind("droop:", 0), 0u);
  EXPECT_TRUE(m.fails.empty());
  EXPECT_TRUE(r.pass);
  // Without warning texts: the same numbers and verdict, no text.
  StatusOr<Rules> rules = load_rules("bq7961x");
  ASSERT_TRUE(rules.ok());
  CheckOptions quiet;
  quiet.warning_texts = false;
  const Waveform w = render(t);
  StatusOr<CheckResult> q = check_waveform(w, *rules, quiet);
  ASSERT_TRUE(q.ok()) << q.status().message();
  ASSERT_EQ(q->pulses.size(), r.pulses.size());
  EXPECT_TRUE(q->pulses[4].warnings.empty());
  EXPECT_EQ(q->pulses[4].droop.value, m.droop.value);
  EXPECT_EQ(q->pulses[4].droop.margin, m.droop.margin);
  EXPECT_EQ(q->pulses[4].vend.value, m.vend.value);
  EXPECT_EQ(q->pass, r.pass);
}

// A 40 ns dip to 1.0 V inside the ++ double pulse: still one pulse, and it fails.
TEST(Metrics, DipInsidePulse) {
  synth::Train t = frame_train();
  const double tx = t.boundary(4) + 200 * ns;
  synth::Pwl dip;
  dip.add(tx, 0);
  dip.add(tx + 5 * ns, -1.0);
  dip.add(tx + 43 * ns, -1.0);
  dip.add(tx + 48 * ns, 0);
  CheckResult r = run(render(t, {dip}));
  ASSERT_EQ(r.pulses.size(), 24u);
  const PulseMetrics& p = r.pulses[4];
  ASSERT_EQ(p.dips.size(), 1u);
  EXPECT_NEAR(p.dips[0].start, tx + 4 * ns, 0.01 * ns);
  EXPECT_NEAR(p.dips[0].end - p.dips[0].start, 40 * ns, 0.01 * ns);
  EXPECT_NEAR(p.dips[0].lowest, 1.0, 1e-3);
  EXPECT_TRUE(has_fail(p, "dip"));
  EXPECT_NEAR(p.width.value, 500 * ns, 0.01 * ns);
  EXPECT_FALSE(r.pass);
  EXPECT_EQ(r.failing(), 1u);
  EXPECT_EQ(r.frames[0].fault, "weak bit");
}

// A 60 ns overshoot past +1.2 V after the (negative) postamble is ringing: a warning, not a pulse.
// A 110 ns one is a pulse (and a frame that cannot decode).
TEST(Metrics, RingingAfterPostamble) {
  for (double len : {60.0, 110.0}) {
    synth::Train t = frame_train(0x15);
    const size_t n0 = t.pulses.size();
    ASSERT_EQ(n0, 20u);  // 26 half bits, six same-sign neighbours merged
    const double t0 = t.end() + 100 * ns;
    synth::Pwl spike;
    spike.add(t0, 0);
    spike.add(t0 + 10 * ns, 1.5);  // crosses 1.2 V at t0 + 8 ns
    spike.add(t0 + (len + 6) * ns, 1.5);
    spike.add(t0 + (len + 16) * ns, 0);  // crosses at t0 + len + 8 ns
    CheckResult r = run(render(t, {spike}));
    if (len < 100) {
      ASSERT_EQ(r.ringing.size(), 1u);
      EXPECT_NEAR(r.ringing[0].start, t0 + 8 * ns, 0.01 * ns);
      EXPECT_NEAR(r.ringing[0].end - r.ringing[0].start, 60 * ns, 0.01 * ns);
      EXPECT_NEAR(r.ringing[0].peak, 1.5, 1e-3);
      EXPECT_EQ(r.ringing[0].sign, +1);
      EXPECT_EQ(r.pulses.size(), n0);
      EXPECT_TRUE(r.idle.empty());  // overshoot of the other sign is allowed
      EXPECT_TRUE(r.pass);
      EXPECT_EQ(r.bytes, std::vector<uint8_t>{0x15});
    } else {
      // 110 ns is long enough for a pulse, but it follows a whole frame: the line's kickback
      // after the postamble (rule 8.4a), allowed like any overshoot of the other sign
      ASSERT_EQ(r.ringing.size(), 1u);
      EXPECT_TRUE(r.ringing[0].after_frame);
      EXPECT_NEAR(r.ringing[0].end - r.ringing[0].start, 110 * ns, 0.01 * ns);
      EXPECT_EQ(r.pulses.size(), n0);
      EXPECT_TRUE(r.pulses.back().idle);
      EXPECT_TRUE(r.pass);
      EXPECT_EQ(r.bytes, std::vector<uint8_t>{0x15});
    }
  }
}

// After the negative postamble: back past -0.4 V within 4 us is an undershoot warning.
TEST(Metrics, IdleUndershoot) {
  struct Case {
    double level, delay_us;
    bool warn;
  };
  for (Case c : {Case{-0.6, 0.5, true}, Case{-0.39, 0.5, false}, Case{+0.6, 0.5, false},
                 Case{-0.6, 4.5, false}}) {
    synth::Train t = frame_train(0x15);
    const double t0 = t.end() + c.delay_us * 1e-6;
    synth::Pwl u;
    u.add(t0, 0);
    u.add(t0 + 20 * ns, c.level);
    u.add(t0 + 80 * ns, c.level);
    u.add(t0 + 100 * ns, 0);
    CheckResult r = run(render(t, {u}));
    EXPECT_TRUE(r.pass);
    ASSERT_EQ(r.idle.size(), c.warn ? 1u : 0u) << c.level << " " << c.delay_us;
    if (c.warn) {
      EXPECT_EQ(r.idle[0].sign, -1);
      EXPECT_NEAR(r.idle[0].peak, 0.6, 1e-3);
      EXPECT_NEAR(r.idle[0].start, t0 + 20 * ns * 0.4 / 0.6, 0.01 * ns);
      EXPECT_NEAR(r.idle[0].end, t0 + 80 * ns + 20 * ns * 0.2 / 0.6, 0.01 * ns);
      EXPECT_EQ(r.idle[0].after_pulse, r.pulses.size() - 1);
    }
  }
}

// +/-20 mV of noise moves nothing past its limit.
TEST(Metrics, NoiseKeepsAPassingFramePassing) {
  CheckResult r = run(render(frame_train(0x15), {}, 0.02));
  EXPECT_TRUE(r.pass);
  EXPECT_EQ(r.bytes, std::vector<uint8_t>{0x15});
  for (const PulseMetrics& p : r.pulses) {
    EXPECT_GE(p.vstart.value, 2.0 - 0.02);
    EXPECT_LE(p.vstart.value, 2.0 + 0.02);
    EXPECT_NEAR(p.vend.value, 2.0, 0.02);
    if (!p.idle) {
      EXPECT_NEAR(p.width.value, p.k * 250 * ns, 0.5 * ns);
    }
  }
  EXPECT_TRUE(r.ringing.empty());
}

TEST(Metrics, WorstMarginsPickSmallest) {
  std::vector<PulseMetrics> ps(3);
  for (size_t i = 0; i < 3; ++i) {
    ps[i].index = i;
    ps[i].a = static_cast<double>(i) * 1e-6;
    ps[i].vstart =
        Judged{1.7 + 0.1 * static_cast<double>(i), 1.6, 0.1 + 0.1 * static_cast<double>(i)};
  }
  ps[2].vstart.margin = 0.05;
  ps[2].frame = 3;
  ps[2].role = "bit 4";
  auto w = worst_margins(ps);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].metric, "vstart");
  EXPECT_EQ(w[0].pulse, 2u);
  EXPECT_DOUBLE_EQ(w[0].time, 2e-6);
  EXPECT_EQ(w[0].frame, 3);
  EXPECT_EQ(w[0].role, "bit 4");
}

}  // namespace
}  // namespace isolink::eye
