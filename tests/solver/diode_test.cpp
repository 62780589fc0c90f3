// The diode (solver/elements/diode.cpp) and Newton's iteration (solver/newton.cpp) against
// closed forms: the DC I-V curve in all three regions, the breakdown knee at -BV, the series
// resistance, a clipper's knee on a slow ramp, a half-wave rectifier's ripple and discharge, and
// the junction charge a linear capacitor hands over (charge conservation).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "solver/transient.h"
#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

constexpr double kVt = 1.38064852e-23 * 300.15 / 1.6021766208e-19;  // kT/q at 27 degC
constexpr double kGmin = 1e-12;

std::shared_ptr<const CardModel> model(std::vector<std::pair<std::string, double>> params) {
  auto m = std::make_shared<CardModel>();
  m->name = "dtest";
  m->type = "d";
  for (const auto& [k, v] : params) m->params.emplace_back(k, num(v));
  return m;
}

Card diode(std::string name, std::vector<std::string> nodes, std::shared_ptr<const CardModel> m,
           std::vector<CardArg> args = {}) {
  Card c = card(std::move(name), std::move(nodes), std::move(args));
  c.model = std::move(m);
  return c;
}

// Root of f on [a, b] by bisection (f(a), f(b) of opposite signs): the tests' own solver.
double bisect(const std::function<double(double)>& f, double a, double b) {
  double fa = f(a);
  for (int i = 0; i < 200; ++i) {
    const double m = 0.5 * (a + b), fm = f(m);
    if ((fm < 0) == (fa < 0))
      a = m, fa = fm;
    else
      b = m;
  }
  return 0.5 * (a + b);
}

// The DC current into the diode's anode with a source v across it: -i(v1).
double dc_diode_current(std::shared_ptr<const CardModel> m, double v) {
  Circuit c;
  const std::string err = build(c, {card("v1", {"a", "0"}, {num(v)}), diode("d1", {"a", "0"}, m)});
  EXPECT_EQ(err, "");
  StatusOr<std::vector<double>> x = dc_operating_point(c);
  EXPECT_TRUE(x.ok()) << x.status().message();
  if (!x) return NAN;
  return -(*x)[c.unknown_count()];  // the source's branch current, the last unknown
}

TEST(Diode, DcCurrentIsShockleyForwardAndReverse) {
  auto m = model({{"is", 2e-14}, {"n", 1.5}});
  const double vte = 1.5 * kVt;
  for (double v : {0.3, 0.55, 0.7, 0.8}) {
    const double expect = 2e-14 * (std::exp(v / vte) - 1) + kGmin * v;
    EXPECT_NEAR(dc_diode_current(m, v), expect, 1e-9 * expect) << v;
  }
  // Reverse beyond -3 n vt: SPICE's -is (1 + (3 n vt / (v e))^3).
  for (double v : {-0.2, -5.0}) {
    const double a = 3 * vte / (v * std::exp(1.0));
    const double expect = -2e-14 * (1 + a * a * a) + kGmin * v;
    EXPECT_NEAR(dc_diode_current(m, v), expect, 1e-9 * std::fabs(expect)) << v;
  }
}

TEST(Diode, BreakdownCarriesIbvAtMinusBv) {
  // ngspice fits the knee so that the current at -BV is -IBV (to its reltol, 1e-3).
  auto m = model({{"is", 1e-14}, {"bv", 27}, {"ibv", 1e-3}});
  EXPECT_NEAR(dc_diode_current(m, -27.0), -1e-3, 2e-6);
  // Deeper in, the current grows by e every n vt.
  const double i1 = dc_diode_current(m, -27.1), i2 = dc_diode_current(m, -27.1 - kVt);
  EXPECT_NEAR(i2 / i1, std::exp(1.0), 1e-6);
  // Well above the knee it is the plain reverse current.
  EXPECT_NEAR(dc_diode_current(m, -20.0), -1e-14 - 20 * kGmin, 1e-15);
}

TEST(Diode, SeriesResistanceAddsIrDrop) {
  auto m = model({{"is", 1e-14}, {"rs", 10}});
  const double v = 1.0;
  const double i = dc_diode_current(m, v);
  // v = i rs + vt ln(i / is + 1) (gmin's share at the junction, ~1e-12 A, is below the check).
  const double expect =
      bisect([&](double ii) { return ii * 10 + kVt * std::log(ii / 1e-14 + 1) - v; }, 1e-9, 0.1);
  EXPECT_NEAR(i, expect, 1e-8 * expect);
  // The area factor divides rs and multiplies is: area 2 at 2 v... carries twice the current.
  Circuit c;
  ASSERT_EQ(build(c, {card("v1", {"a", "0"}, {num(v)}), diode("d1", {"a", "0"}, m, {num(2)})}), "");
  auto x = dc_operating_point(c);
  ASSERT_TRUE(x.ok()) << x.status().message();
  const double i2 = -(*x)[c.unknown_count()];
  const double expect2 =
      bisect([&](double ii) { return ii * 5 + kVt * std::log(ii / 2e-14 + 1) - v; }, 1e-9, 0.1);
  EXPECT_NEAR(i2, expect2, 1e-8 * expect2);
}

TEST(Diode, ClipperFollowsItsKneeOnASlowRamp) {
  // A 0 -> 5 V ramp over 1 ms through 1 kohm into a diode to ground; no capacitance, so each
  // row is the DC solution: v = vd with (vin - vd) / r = is (e^(vd / vt) - 1) + gmin vd.
  auto m = model({{"is", 1e-14}});
  Circuit c;
  ASSERT_EQ(build(c, {card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-3, 5})}),
                      card("r1", {"in", "out"}, {num(1e3)}), diode("d1", {"out", "0"}, m)}),
            "");
  auto pin = parse_probe(c, "v(in)"), pout = parse_probe(c, "v(out)");
  ASSERT_TRUE(pin.ok() && pout.ok());
  TransientOptions opt{.tstep = 10e-6, .tstop = 1e-3};
  auto w = run_transient(c, opt, {*pin, *pout});
  ASSERT_TRUE(w.ok()) << w.status().message();
  ASSERT_GT(w->samples(), 50u);
  double worst = 0;
  for (size_t k = 0; k < w->samples(); ++k) {
    const double vin = w->columns[0][k];
    const double vd = bisect(
        [&](double x) { return (vin - x) / 1e3 - 1e-14 * (std::exp(x / kVt) - 1) - kGmin * x; }, -1,
        std::max(vin, 0.0) + 1e-9);
    worst = std::max(worst, std::fabs(w->columns[1][k] - vd));
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_NEAR(w->columns[1].back(), 0.6929, 1e-3);  // the knee at 4.31 mA, hand-checked
}

TEST(Diode, HalfWaveRectifierRippleAndDischarge) {
  // 10 V, 1 kHz into a diode, 1 kohm || 100 uF: the capacitor discharges through R alone between
  // peaks (exp(-t / RC) exactly, the diode reverse-biased), and the ripple is close to
  // vpeak / (f R C).
  auto m = model({{"is", 1e-14}, {"rs", 1}});
  Circuit c;
  ASSERT_EQ(
      build(c, {card("v1", {"in", "0"}, {call("sin", {0, 10, 1e3})}), diode("d1", {"in", "out"}, m),
                card("r1", {"out", "0"}, {num(1e3)}), card("c1", {"out", "0"}, {num(100e-6)})}),
      "");
  auto pout = parse_probe(c, "v(out)"), pin = parse_probe(c, "v(in)");
  ASSERT_TRUE(pout.ok() && pin.ok());
  TransientOptions opt{.tstep = 1e-6, .tstop = 20e-3, .tstart = 0, .tmax = 2e-6, .reltol = 1e-4};
  auto w = run_transient(c, opt, {*pout, *pin});
  ASSERT_TRUE(w.ok()) << w.status().message();
  // The last period: 19 ms .. 20 ms; the peak of v(out) and the following discharge.
  size_t peak = 0;
  double vmax = -1, vmin = 1e9;
  for (size_t k = 0; k < w->samples(); ++k) {
    if (w->time[k] < 18.9e-3) continue;
    if (w->columns[0][k] > vmax) vmax = w->columns[0][k], peak = k;
    vmin = std::min(vmin, w->columns[0][k]);
  }
  const double ripple = vmax - vmin, estimate = vmax / (1e3 * 1e3 * 100e-6);
  EXPECT_NEAR(ripple, estimate, 0.1 * estimate);
  EXPECT_GT(vmax, 8.9);  // 10 V less a diode drop at ~10 mA (plus rs)
  EXPECT_LT(vmax, 9.4);
  // Discharge: from 0.1 ms after the peak until the input comes back within 1 V of the output.
  double worst = 0;
  const double t0 = w->time[peak], v0 = w->columns[0][peak];
  for (size_t k = peak; k < w->samples(); ++k) {
    const double t = w->time[k];
    if (t < t0 + 0.1e-3) continue;
    if (w->columns[1][k] > w->columns[0][k] - 1.0) break;
    worst = std::max(worst, std::fabs(w->columns[0][k] - v0 * std::exp(-(t - t0) / 0.1)) / v0);
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(Diode, JunctionChargeIsConserved) {
  // A 1 nF capacitor charged to 20 V (UIC) shares its charge through 1 kohm with a diode's
  // reverse-biased junction (CJO 200 pF, VJ 0.7, M 0.4, anode grounded). At the end both sit
  // at vf with 1 nF (20 - vf) = Qj(vf), Qj the depletion charge VJ CJO (1 - (1 + vf / VJ)^(1 - M))
  // / (1 - M) taken at v = -vf: a charge-conserving integration lands there exactly.
  const double cjo = 200e-12, vj = 0.7, mg = 0.4, c1 = 1e-9, v0 = 20;
  auto m = model({{"is", 1e-14}, {"cjo", cjo}, {"vj", vj}, {"m", mg}});
  Card cap = card("c1", {"top", "0"}, {num(c1)});
  cap.params.emplace_back("ic", num(v0));
  Circuit c;
  ASSERT_EQ(build(c, {cap, card("r1", {"top", "k"}, {num(1e3)}), diode("d1", {"0", "k"}, m)}), "");
  auto pk = parse_probe(c, "v(k)");
  ASSERT_TRUE(pk.ok());
  TransientOptions opt{.tstep = 1e-9, .tstop = 20e-6, .uic = true};
  auto w = run_transient(c, opt, {*pk});
  ASSERT_TRUE(w.ok()) << w.status().message();
  auto qj = [&](double vf) { return vj * cjo * (1 - std::pow(1 + vf / vj, 1 - mg)) / (1 - mg); };
  // Charge on the junction's cathode side is -Qj(-vf) = -qj(vf) (qj < 0 for reverse bias).
  const double vf = bisect([&](double v) { return c1 * (v0 - v) + qj(v); }, 0, v0);
  EXPECT_NEAR(w->columns[0].back(), vf, 1e-4);
  EXPECT_GT(v0 - vf, 1.0);  // the junction took a visible share
}

TEST(Diode, BadModelValuesAreRefusedWithTheirName) {
  Circuit c;
  EXPECT_NE(
      build(c, {card("v1", {"a", "0"}, {num(1)}), diode("d1", {"a", "0"}, model({{"is", -1e-14}}))})
          .find("is = -1e-14 must be positive"),
      std::string::npos);
  Circuit c2;
  EXPECT_NE(build(c2, {diode("d1", {"a", "0"}, model({{"bogus", 1}}))})
                .find("unknown diode model parameter 'bogus'"),
            std::string::npos);
  Circuit c3;
  EXPECT_NE(build(c3, {diode("d1", {"a", "0"}, model({{"m", 1.5}}))}).find("m = 1.5"),
            std::string::npos);
  Circuit c4;
  EXPECT_NE(build(c4, {diode("d1", {"a", "0"}, nullptr)}).find("names no .model"),
            std::string::npos);
}

// A saturation current so large that vcrit = vte ln(vte / (sqrt(2) IS)) is negative (IS 0.11 A,
// found by fuzz_model): SPICE's limiting would take log(vnew / vt) of a negative vnew. Every
// limited voltage stays finite and keeps its side of 0 V, and the DC point still solves.
TEST(Diode, NegativeCriticalVoltageLimitsToFiniteValues) {
  Circuit c;
  const auto m = model({{"is", 0.11}, {"n", 1.1}, {"bv", 27}});
  ASSERT_EQ(build(c, {card("v1", {"a", "0"}, {num(0.3)}), diode("d1", {"a", "0"}, m)}), "");
  const Element& d = *c.elements()[1];
  for (double v_old : {-30.0, -5.0, -0.5, 0.0})
    for (double v_new : {-0.04, -0.01, 0.0, 0.01, 0.5}) {
      bool limited = false;
      const double v = d.limit_port(0, v_new, v_old, &limited);
      EXPECT_TRUE(std::isfinite(v)) << v_new << " from " << v_old;
      if (v_new <= 0) {
        EXPECT_LE(v, 0.0) << v_new << " from " << v_old;
      }
    }
  // 0.3 V on IS 0.11 A, n 1.1: i = IS (e^(0.3 / (n Vt)) - 1), hundreds of amps, closed form.
  const double expected = 0.11 * std::expm1(0.3 / (1.1 * kVt)) + kGmin * 0.3;
  EXPECT_NEAR(dc_diode_current(m, 0.3) / expected, 1.0, 1e-6);
}

TEST(Diode, LtiEngineRefusesIt) {
  Circuit c;
  ASSERT_EQ(build(c, {card("v1", {"a", "0"}, {num(1)}), diode("d1", {"a", "0"}, model({}))}), "");
  EXPECT_FALSE(c.elements()[1]->linear_time_invariant());
}

}  // namespace
}  // namespace isolink
