// The transient step-size control against its accuracy promise (docs/solver.md): each step's
// local truncation error stays below trtol * (reltol * peak|x| + vntol), so on a smooth circuit
// the error against the closed form follows the tolerance: below reltol * peak, and shrinking as
// reltol^(2/3) (steps scale as tol^(1/3), the global error of a second-order method as h^2).
// An estimate that understates the truncation error (a wrong constant in transient.cpp) lets the
// steps grow past what the tolerance allows and fails these bounds. The circuit: V1 = sin(2 pi
// 1 MHz t) into 1 kohm and 1 nF (tau = 1 us), 5 us, tmax 100 ns so that the error control alone
// sets the steps (17 ns at reltol 1e-3).
#include "solver/step_control.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "solver/transient.h"
#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

struct Measured {
  double max_err = 0;  // V, worst |simulated - closed form| over the run
  double peak = 0;     // V, largest |closed form|
  long steps = 0;
};

// V1 = sin(2 pi f t) from t = 0 into R then C to ground: v(out) from rest.
double rc_sine(double t, double tau, double w) {
  const double wt = w * tau;
  return (std::sin(w * t) - wt * std::cos(w * t) + wt * std::exp(-t / tau)) / (1 + wt * wt);
}

Measured rc_sine_run(IntegrationMethod m, double reltol) {
  const double r = 1e3, cap = 1e-9, tau = r * cap, f = 1e6, w = 2 * std::numbers::pi * f;
  const double tstop = 5e-6;
  Circuit c;
  EXPECT_EQ(build(c, {card("v1", {"in", "0"}, {call("sin", {0, 1, f})}),
                      card("r1", {"in", "out"}, {num(r)}), card("c1", {"out", "0"}, {num(cap)})}),
            "");
  auto probe = parse_probe(c, "v(out)");
  EXPECT_TRUE(probe.ok());
  // tmax = tstop / 50 = 100 ns, far above the steps the tolerance allows: the error control
  // alone sets the step.
  TransientOptions opt{.tstep = tstop / 50, .tstop = tstop, .method = m, .reltol = reltol};
  TransientStats stats;
  auto wave = run_transient(c, opt, {*probe}, &stats);
  EXPECT_TRUE(wave.ok()) << wave.status().message();
  Measured out;
  if (!wave.ok()) return out;
  for (size_t i = 0; i < wave->samples(); ++i) {
    const double exact = rc_sine(wave->time[i], tau, w);
    out.peak = std::max(out.peak, std::fabs(exact));
    out.max_err = std::max(out.max_err, std::fabs(wave->columns[0][i] - exact));
  }
  out.steps = stats.accepted;
  return out;
}

// Local error of every accepted step on R-C driven by sin(w t): the exact flow from the
// simulated v_k at t_k over h is v_p(t_k + h) + (v_k - v_p(t_k)) e^{-h/tau}, v_p the steady state.
// Returns the worst |v_{k+1} - flow| / (trtol (reltol peak_k + vntol)), peak_k = max |v| so far,
// over the steps after the first three (the error estimate needs four points).
double rc_local_error_ratio(IntegrationMethod m, double reltol, long* steps = nullptr) {
  const double r = 1e3, cap = 1e-9, tau = r * cap, f = 1e6, w = 2 * std::numbers::pi * f;
  const double tstop = 5e-6;
  Circuit c;
  EXPECT_EQ(build(c, {card("v1", {"in", "0"}, {call("sin", {0, 1, f})}),
                      card("r1", {"in", "out"}, {num(r)}), card("c1", {"out", "0"}, {num(cap)})}),
            "");
  auto probe = parse_probe(c, "v(out)");
  EXPECT_TRUE(probe.ok());
  TransientOptions opt{.tstep = tstop / 50, .tstop = tstop, .method = m, .reltol = reltol};
  TransientStats stats;
  auto wave = run_transient(c, opt, {*probe}, &stats);
  EXPECT_TRUE(wave.ok()) << wave.status().message();
  if (!wave.ok()) return 0;
  const double wt = w * tau;
  auto vp = [&](double t) { return (std::sin(w * t) - wt * std::cos(w * t)) / (1 + wt * wt); };
  double worst = 0, peak = 0;
  const auto& t = wave->time;
  const auto& v = wave->columns[0];
  for (size_t k = 0; k + 1 < t.size(); ++k) {
    peak = std::max(peak, std::fabs(v[k]));
    if (k < 3) continue;
    const double h = t[k + 1] - t[k];
    const double flow = vp(t[k + 1]) + (v[k] - vp(t[k])) * std::exp(-h / tau);
    const double tol = opt.trtol * (opt.reltol * peak + opt.vntol);
    worst = std::max(worst, std::fabs(v[k + 1] - flow) / tol);
  }
  if (steps) *steps = stats.accepted;
  return worst;
}

// Every accepted trapezoidal step keeps its local error within its tolerance, from loose to
// tight reltol. Bound 2: the estimate is a divided difference over the last four points, not
// the exact third derivative (measured 1.0-1.5). With the truncation constant a tenth of the
// trapezoidal rule's 1/12 the steps grow by 10^(1/3) and the ratio reaches about 10.
TEST(StepControl, TrapezoidalLocalErrorStaysWithinItsTolerance) {
  for (double reltol : {1e-2, 1e-3, 1e-4, 1e-5}) {
    long steps = 0;
    const double ratio = rc_local_error_ratio(IntegrationMethod::Trapezoidal, reltol, &steps);
    std::printf("trap reltol %g: worst local error / tolerance %.2f over %ld steps\n", reltol,
                ratio, steps);
    EXPECT_LT(ratio, 2.0) << "reltol " << reltol;
    EXPECT_GT(ratio, 0.1) << "reltol " << reltol << ": the steps are far smaller than needed";
  }
}

// The global error against the closed form follows the tolerance: at most reltol x peak, and it
// shrinks as reltol^(2/3) (steps ~ tol^(1/3), error ~ h^2): 10^(2/3) = 4.6 per decade, taken
// as 3..7. (Below reltol 1e-4 the error of the Backward-Euler start step, which the control
// does not judge, dominates: 4.8e-4 x peak on this circuit; the local test above covers those
// tolerances.) With the truncation constant a tenth of 1/12 the error is 4.6 times larger and
// exceeds reltol x peak.
TEST(StepControl, TrapezoidalGlobalErrorFollowsReltol) {
  const Measured loose = rc_sine_run(IntegrationMethod::Trapezoidal, 1e-2);
  const Measured tight = rc_sine_run(IntegrationMethod::Trapezoidal, 1e-3);
  std::printf("trap: max |v - exact| / peak %.3g at reltol 1e-2 (%ld steps), %.3g at 1e-3 (%ld)\n",
              loose.max_err / loose.peak, loose.steps, tight.max_err / tight.peak, tight.steps);
  EXPECT_LT(loose.max_err, 1e-2 * loose.peak);
  EXPECT_LT(tight.max_err, 1e-3 * tight.peak);
  const double shrink = loose.max_err / tight.max_err;
  EXPECT_GT(shrink, 3.0);
  EXPECT_LT(shrink, 7.0);
  // Steps ~ tol^(-1/3): 2.15 times as many per decade (ladder rounding: 1.5..3).
  const double more = static_cast<double>(tight.steps) / static_cast<double>(loose.steps);
  EXPECT_GT(more, 1.5);
  EXPECT_LT(more, 3.0);
}

// The shared rules of solver/step_control.h, against their closed forms.

// Rungs hmax / 2^k: the largest not above h; an exact rung maps to itself.
TEST(StepControl, LadderGivesTheLargestRungNotAboveTheStep) {
  const StepControl control{.hmax = 1e-9, .hmin = 1e-21, .error_order = 3};
  EXPECT_EQ(control.ladder(5e-9), 1e-9);
  EXPECT_EQ(control.ladder(1e-9), 1e-9);
  EXPECT_EQ(control.ladder(0.3e-9), 0.25e-9);
  EXPECT_EQ(control.ladder(0.25e-9), 0.25e-9);
  EXPECT_EQ(control.ladder(0.7e-9), 0.5e-9);
  EXPECT_EQ(control.ladder(1e-9 / 1024 * 1.5), 1e-9 / 1024);
}

// h = 0 (or a subnormal h) made log2 infinite and its conversion to int undefined (UBSan): the
// rung exponent is clamped at 1100, which gives 0 or a subnormal, below any floor.
TEST(StepControl, LadderClampsAZeroOrSubnormalStepBelowTheFloor) {
  const StepControl control{.hmax = 1.0, .hmin = 1e-18, .error_order = 3};
  EXPECT_EQ(control.ladder(0.0), std::ldexp(1.0, -1100));  // 0 in double
  const double tiny = control.ladder(std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(std::isfinite(tiny));
  EXPECT_LT(tiny, control.hmin);
  EXPECT_EQ(control.ladder(1e-300), std::ldexp(1.0, -997));  // 2^-997 < 1e-300 < 2^-996
}

// Rejection: step * max(0.25, 0.9 ratio^(-1/order)); order 3 takes the cube root (the transient's
// local error), order 2 the square root (the march's error per unit time).
TEST(StepControl, ShrinkScalesByTheRootOfTheErrorOrder) {
  const StepControl third{.hmax = 1.0, .hmin = 1e-18, .error_order = 3};
  const StepControl second{.hmax = 1.0, .hmin = 1e-18, .error_order = 2};
  EXPECT_DOUBLE_EQ(third.shrink(1e-9, 8.0), 0.45e-9);    // 0.9 / 2
  EXPECT_DOUBLE_EQ(second.shrink(1e-9, 4.0), 0.45e-9);   // 0.9 / 2
  EXPECT_DOUBLE_EQ(third.shrink(1e-9, 27.0), 0.3e-9);    // 0.9 / 3
  EXPECT_DOUBLE_EQ(second.shrink(1e-9, 27.0), 0.25e-9);  // 0.9 / 5.2 = 0.17: the floor
  EXPECT_DOUBLE_EQ(third.shrink(1e-9, 1e6), 0.25e-9);    // floor
  // The transient's backward-Euler start step: order 2, floor 0.1.
  EXPECT_DOUBLE_EQ(StepControl::shrink_by_order(1e-9, 4.0, 2, 0.1), 0.45e-9);
  EXPECT_DOUBLE_EQ(StepControl::shrink_by_order(1e-9, 400.0, 2, 0.1), 0.1e-9);  // 0.045: floor
}

// Growth: by 0.9 ratio^(-1/order), at most 2x (and 2x when no error was estimated), at least
// 0.5x, at least hmin, then down to a rung.
TEST(StepControl, GrowIsBoundedAndLandsOnARung) {
  const double hmax = 1.0;
  const StepControl third{.hmax = hmax, .hmin = 1e-12, .error_order = 3};
  const StepControl second{.hmax = hmax, .hmin = 1e-12, .error_order = 2};
  EXPECT_EQ(third.grow(0.125, 0.0), 0.25);        // no estimate: 2x
  EXPECT_EQ(third.grow(0.125, 1e-9), 0.25);       // capped at 2x
  EXPECT_EQ(third.grow(0.125, 1.0 / 8), 0.125);   // 1.8x = 0.225: rung 0.125
  EXPECT_EQ(second.grow(0.125, 1.0 / 4), 0.125);  // 1.8x likewise
  EXPECT_EQ(third.grow(0.125, 1.0), 0.0625);      // 0.9x = 0.1125: rung 0.0625
  EXPECT_EQ(second.grow(0.125, 1.0), 0.0625);
  EXPECT_EQ(third.grow(0.5, 1.0), 0.25);   // 0.45: rung 0.25
  EXPECT_EQ(third.grow(0.75, 0.0), hmax);  // 1.5: the top rung
  // Never below hmin: a step under the floor grows to the rung at or below hmin, not under it
  // by more than a factor 2.
  EXPECT_EQ(third.grow(1e-15, 1.0), third.ladder(1e-12));
  EXPECT_GT(third.grow(1e-15, 1.0), 0.5e-12);
}

}  // namespace
}  // namespace isolink
