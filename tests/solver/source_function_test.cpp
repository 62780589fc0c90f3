#include "solver/elements/source_function.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

SourceFunction parse(std::vector<CardArg> args) {
  auto f = SourceFunction::Parse(card("v1", {"a", "0"}, std::move(args)));
  EXPECT_TRUE(f.ok()) << f.status().message();
  return *f;
}

TEST(SourceFunction, PulseShapeAndCorners) {
  SourceFunction f = parse({call("pulse", {0, 5, 10e-9, 2e-9, 4e-9, 20e-9, 50e-9})});
  f.bind_time(1e-9, 100e-9);
  EXPECT_DOUBLE_EQ(f.value(5e-9), 0.0);
  EXPECT_NEAR(f.value(11e-9), 2.5, 1e-12);  // half way up the 2 ns rise
  EXPECT_DOUBLE_EQ(f.value(20e-9), 5.0);
  EXPECT_NEAR(f.value(34e-9), 2.5, 1e-12);  // half way down: 10+2+20 = 32, +2 of 4 ns
  EXPECT_NEAR(f.value(61e-9), 2.5, 1e-9);   // second period
  std::vector<double> bp;
  f.breakpoints(100e-9, bp);
  std::vector<double> want{10e-9, 12e-9, 32e-9, 36e-9, 60e-9, 62e-9, 82e-9, 86e-9};
  ASSERT_EQ(bp.size(), want.size());
  for (size_t i = 0; i < bp.size(); ++i) EXPECT_NEAR(bp[i], want[i], 1e-18);
}

TEST(SourceFunction, PulseDefaultsFollowNgspice) {
  SourceFunction f = parse({call("pulse", {1, 2})});
  f.bind_time(1e-9, 1e-6);  // TR = TF = TSTEP, PW = PER = TSTOP
  EXPECT_DOUBLE_EQ(f.value(0.5e-9), 1.5);
  EXPECT_DOUBLE_EQ(f.value(0.5e-6), 2.0);
}

// EXP(V1 V2 TD1 TAU1 TD2 TAU2), ngspice's formula, and its TSTEP defaults.
TEST(SourceFunction, ExpRisesAndFallsExponentially) {
  SourceFunction f = parse({call("exp", {0, 2, 1e-6, 1e-6, 3e-6, 0.5e-6})});
  f.bind_time(1e-9, 10e-6);
  EXPECT_DOUBLE_EQ(f.value(0.5e-6), 0.0);
  EXPECT_NEAR(f.value(2e-6), 2 * (1 - std::exp(-1.0)), 1e-12);
  EXPECT_NEAR(f.value(4e-6), 2 * (1 - std::exp(-3.0)) - 2 * (1 - std::exp(-2.0)), 1e-12);
  std::vector<double> bp;
  f.breakpoints(10e-6, bp);
  ASSERT_EQ(bp.size(), 2u);
  EXPECT_EQ(bp[0], 1e-6);
  EXPECT_EQ(bp[1], 3e-6);
  SourceFunction d = parse({call("exp", {1, 0})});  // TD1 0, TAU1 = TD2 = TAU2 = TSTEP
  d.bind_time(1e-6, 10e-6);
  EXPECT_NEAR(d.value(0.5e-6), std::exp(-0.5), 1e-12);
  EXPECT_NEAR(d.value(2e-6), std::exp(-2.0) + (1 - std::exp(-1.0)), 1e-12);
}

// PWL td= delays the whole list; r= repeats from that time point to the last, for ever.
TEST(SourceFunction, PwlDelayAndRepeat) {
  auto c = card("v1", {"a", "0"}, {call("pwl", {0, 0, 1e-6, 1, 2e-6, 0})});
  c.params.emplace_back("td", num(0.5e-6));
  c.params.emplace_back("r", num(0));
  auto f = SourceFunction::Parse(c);
  ASSERT_TRUE(f) << f.status().message();
  EXPECT_DOUBLE_EQ(f->value(0.25e-6), 0.0);  // before td: the first value
  EXPECT_NEAR(f->value(1e-6), 0.5, 1e-12);
  EXPECT_NEAR(f->value(3e-6), 0.5, 1e-12);  // 2.5 us into the list: 0.5 us into the repeat
  EXPECT_NEAR(f->value(4e-6), 0.5, 1e-12);  // 3.5 us: 1.5 us into the 2 us period
  std::vector<double> bp;
  f->breakpoints(5e-6, bp);
  const std::vector<double> want{0.5e-6, 1.5e-6, 2.5e-6, 3.5e-6, 4.5e-6};
  ASSERT_EQ(bp.size(), want.size());
  for (size_t i = 0; i < bp.size(); ++i) EXPECT_NEAR(bp[i], want[i], 1e-18);
  c.params.back().second = num(1.5e-6);  // not one of the times
  auto bad = SourceFunction::Parse(c);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("must be one of the PWL's times"), std::string::npos);
}

// corner_count: the length of breakpoints' list, counted in closed form (the engines are refused a
// run whose corners do not fit before they list them: analysis/simulate.cpp). Each case by hand.
TEST(SourceFunction, CornerCountIsTheBreakpointsUncounted) {
  auto listed = [](const SourceFunction& f, double tstop) {
    std::vector<double> bp;
    f.breakpoints(tstop, bp);
    return static_cast<double>(bp.size());
  };
  struct Case {
    std::vector<double> pulse;
    double tstop;
    double corners;  // by hand
  };
  const std::vector<Case> cases{
      // 2 whole periods of 4 corners (PulseShapeAndCorners' list).
      {{0, 5, 10e-9, 2e-9, 4e-9, 20e-9, 50e-9}, 100e-9, 8},
      // The third period starts at 110 ns, before tstop, its rise ends after it: 8 + 1.
      {{0, 5, 10e-9, 2e-9, 4e-9, 20e-9, 50e-9}, 111e-9, 9},
      // TD 0: periods at 0, 2, 4, 6 us, the corner at 0 is not one of the run: 3 + 3 x 4.
      {{0, 1, 0, 1e-9, 1e-9, 1e-6, 2e-6}, 7.3e-6, 15},
      // NP 3 stops it after 3 periods: 3 + 2 x 4.
      {{0, 1, 0, 1e-9, 1e-9, 1e-6, 2e-6, 3}, 100e-6, 11},
      // Nothing before TD.
      {{0, 1, 5e-6, 1e-9, 1e-9, 1e-6, 2e-6}, 4e-6, 0},
  };
  for (const Case& c : cases) {
    SourceFunction f = parse({call("pulse", c.pulse)});
    f.bind_time(1e-9, c.tstop);
    EXPECT_EQ(f.corner_count(c.tstop), c.corners) << c.tstop;
    EXPECT_EQ(f.corner_count(c.tstop), listed(f, c.tstop)) << c.tstop;
  }
  // PWL with td= and an r= repeat (PwlDelayAndRepeat's list: 0.5, 1.5, 2.5, then 3.5, 4.5 us).
  auto pwl = card("v1", {"a", "0"}, {call("pwl", {0, 0, 1e-6, 1, 2e-6, 0})});
  pwl.params.emplace_back("td", num(0.5e-6));
  pwl.params.emplace_back("r", num(0));
  auto p = SourceFunction::Parse(pwl);
  ASSERT_TRUE(p) << p.status().message();
  EXPECT_EQ(p->corner_count(5e-6), 5);
  EXPECT_EQ(p->corner_count(5e-6), listed(*p, 5e-6));
  // 100 us: 3, then 3.5 + 2 j us for j = 0..48 (49) and 4.5 + 2 j us for j = 0..47 (48).
  EXPECT_EQ(p->corner_count(100e-6), 100);
  EXPECT_EQ(p->corner_count(100e-6), listed(*p, 100e-6));
  // Issue 41's source over 1000 s: 5e8 periods of 4 corners (the one at 0 is not a corner of the
  // run, the one at 1000 s is), counted without the 16 GB list.
  SourceFunction big = parse({call("pulse", {0, 1, 0, 1e-9, 1e-9, 1e-6, 2e-6})});
  big.bind_time(1e-12, 1000);
  EXPECT_NEAR(big.corner_count(1000), 2e9, 2);
}

TEST(SourceFunction, PwlInterpolatesAndHoldsEnds) {
  SourceFunction f = parse({call("pwl", {1e-9, 1, 3e-9, 5})});
  EXPECT_DOUBLE_EQ(f.value(0), 1.0);
  EXPECT_DOUBLE_EQ(f.value(2e-9), 3.0);
  EXPECT_DOUBLE_EQ(f.value(1), 5.0);
}

TEST(SourceFunction, SinWithDelayDampingAndPhase) {
  SourceFunction f = parse({call("sin", {1, 2, 1e6, 1e-6, 1e5, 90})});
  EXPECT_DOUBLE_EQ(f.value(0), 3.0);  // before TD: VO + VA sin(phase)
  const double t = 1.3e-6, tt = 0.3e-6;
  EXPECT_NEAR(f.value(t), 1 + 2 * std::exp(-tt * 1e5) * std::sin(2 * M_PI * 1e6 * tt + M_PI / 2),
              1e-12);
}

TEST(SourceFunction, DcForms) {
  EXPECT_DOUBLE_EQ(parse({num(2.5)}).value(1.0), 2.5);
  EXPECT_DOUBLE_EQ(parse({word("dc"), num(-1)}).value(1.0), -1.0);
  EXPECT_DOUBLE_EQ(
      parse({word("dc"), num(0), word("ac"), num(1), call("pwl", {0, 0, 1, 4})}).value(0.5), 2.0);
}

TEST(SourceFunction, BadFormsAreErrors) {
  auto bad = [](std::vector<CardArg> args) {
    return SourceFunction::Parse(card("v1", {"a", "0"}, std::move(args))).status().message();
  };
  EXPECT_NE(bad({call("pwl", {0, 1, 1e-9})}).find("PWL takes time/value pairs"), std::string::npos);
  EXPECT_NE(bad({call("pulse", {0})}).find("PULSE takes 2 to 8 values"), std::string::npos);
  EXPECT_NE(bad({call("foo", {0, 1})}).find("unknown source function 'foo'"), std::string::npos);
  EXPECT_NE(bad({word("dc")}).find("expected a number after DC"), std::string::npos);
}

}  // namespace
}  // namespace isolink
