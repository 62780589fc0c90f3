// LTI engine against closed-form answers and against the transient engine at tight tolerance.
#include "solver/lti.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "solver/transient.h"
#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

struct Built {
  Circuit circuit;
  std::vector<Probe> probes;
};

std::unique_ptr<Built> make(const std::vector<Card>& cards,
                            const std::vector<std::string>& probes) {
  auto b = std::make_unique<Built>();
  EXPECT_EQ(build(b->circuit, cards), "");
  for (const auto& p : probes) {
    auto probe = parse_probe(b->circuit, p);
    EXPECT_TRUE(probe.ok()) << probe.status().message();
    if (probe) b->probes.push_back(*probe);
  }
  return b;
}

using Method = LtiOptions::Method;
constexpr Method kBoth[] = {Method::March, Method::Reduced};
const char* name(Method m) {
  return m == Method::March ? "march" : "reduced model";
}

LtiResponses responses(const Built& b, double horizon, Method method = Method::March) {
  LtiOptions opt;
  opt.horizon = horizon;
  opt.method = method;
  auto r = LtiResponses::compute(b.circuit, b.probes, opt);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return std::move(*r);
}

// First-order lag (time constant tau): unit-ramp response and unit-step response.
double lag_ramp(double t, double tau) {
  return t <= 0 ? 0 : t - tau * (1 - std::exp(-t / tau));
}
double lag_step(double t, double tau) {
  return t <= 0 ? 0 : 1 - std::exp(-t / tau);
}

TEST(Lti, RcRampAndStepResponsesMatchClosedForm) {
  const double r = 1e3, cap = 1e-9, tau = r * cap;
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-9, 1})}),
                 card("r1", {"in", "out"}, {num(r)}), card("c1", {"out", "0"}, {num(cap)})},
                {"v(out)"});
  for (Method method : kBoth) {
    SCOPED_TRACE(name(method));
    LtiResponses lti = responses(*b, 20e-6, method);
    EXPECT_EQ(lti.stats().method, name(method));
    ASSERT_EQ(lti.source_count(), 1u);
    EXPECT_EQ(lti.source_name(0), "v1");
    double worst_step = 0, worst_ramp = 0;
    for (double t = 1e-9; t < 20e-6; t *= 1.07) {
      worst_step = std::max(worst_step, std::fabs(lti.step_response(0, 0, t) - lag_step(t, tau)));
      // The ramp response in units of tau: its error per unit time is what the output sees.
      worst_ramp =
          std::max(worst_ramp, std::fabs(lti.ramp_response(0, 0, t) - lag_ramp(t, tau)) / tau);
    }
    // step_reltol 1e-5 bounds the error added per unit time; on one time constant it stays near it.
    EXPECT_LT(worst_step, 3e-5);
    EXPECT_LT(worst_ramp, 3e-5);
    EXPECT_NEAR(lti.dc_gain(0, 0), 1.0, 1e-9);
    EXPECT_EQ(lti.ramp_response(0, 0, 0.0), 0.0);
    EXPECT_EQ(lti.ramp_response(0, 0, -1e-9), 0.0);
  }
}

TEST(Lti, RcSettlesEarlyAndExtendsTheRampResponseAsALine) {
  const double tau = 1e-6;
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-9, 1})}),
                 card("r1", {"in", "out"}, {num(1e3)}), card("c1", {"out", "0"}, {num(1e-9)})},
                {"v(out)"});
  LtiResponses lti = responses(*b, 1e-3);
  EXPECT_TRUE(lti.stats().settled);
  // settle_tol 1e-6: exp(-t/tau) < 1e-6 needs t > 13.8 tau.
  EXPECT_GT(lti.stats().settled_at, 13.8 * tau);
  EXPECT_LT(lti.stats().settled_at, 100 * tau);
  // Beyond the march: R(T) + S(T) (t - T), off the exact ramp response by < settle_tol * tau.
  EXPECT_NEAR(lti.ramp_response(0, 0, 500e-6), lag_ramp(500e-6, tau), 2e-6 * tau);
  EXPECT_NEAR(lti.step_response(0, 0, 500e-6), 1.0, 2e-6);
}

TEST(Lti, PulseTrainThroughRcIsTheSumOfRampsAtExactCorners) {
  // PULSE(0 5 TD=13.3n TR=7n TF=11n PW=93n PER=250n NP=3): corners off any grid.
  const double tau = 47e-9;
  auto b = make(
      {card("v1", {"in", "0"}, {call("pulse", {0, 5, 13.3e-9, 7e-9, 11e-9, 93e-9, 250e-9, 3})}),
       card("r1", {"in", "out"}, {num(47)}), card("c1", {"out", "0"}, {num(1e-9)})},
      {"v(out)", "v(in)"});
  for (auto& e : b->circuit.elements()) e->bind_time(1e-9, 1e-6);
  for (Method method : kBoth) {
    SCOPED_TRACE(name(method));
    LtiResponses lti = responses(*b, 1e-6, method);
    const auto inputs = lti.netlist_inputs(1e-6);
    ASSERT_EQ(inputs.size(), 1u);
    EXPECT_EQ(inputs[0].ramps.size(), 12u);  // 4 corners per pulse
    auto exact = [&](double t) {
      double y = 0;
      for (int k = 0; k < 3; ++k) {
        const double t0 = 13.3e-9 + k * 250e-9;
        y += 5 / 7e-9 * (lag_ramp(t - t0, tau) - lag_ramp(t - t0 - 7e-9, tau));
        y -= 5 / 11e-9 * (lag_ramp(t - t0 - 100e-9, tau) - lag_ramp(t - t0 - 111e-9, tau));
      }
      return y;
    };
    double worst = 0;
    for (double t = 0; t < 1e-6; t += 0.737e-9)
      worst = std::max(worst, std::fabs(lti.value(0, t, inputs) - exact(t)));
    EXPECT_LT(worst, 50e-6);  // V, on a 5 V pulse
    // The source itself comes back (a probe on the driven node): exactly from the march, to
    // rounding (measured 2e-9 V) from the reduced model, whose modes carry it in part.
    EXPECT_NEAR(lti.value(1, 13.3e-9 + 3.5e-9, inputs), 2.5, 1e-8);
    EXPECT_NEAR(lti.value(1, 13.3e-9 + 50e-9, inputs), 5.0, 1e-8);
    // The batch evaluation (one pass over times and corners) gives the same values.
    std::vector<double> times;
    for (double t = 0; t < 1e-6; t += 0.737e-9) times.push_back(t);
    const auto batch = lti.values(inputs, times);
    double batch_dev = 0;
    for (size_t j = 0; j < times.size(); ++j)
      batch_dev = std::max(batch_dev, std::fabs(batch[0][j] - lti.value(0, times[j], inputs)));
    EXPECT_LT(batch_dev, 1e-9);
  }
}

// The reduced model's batch evaluation long after the last corner, where it lets the modes that
// have decayed go (the worst-case search's edge response: 160,000 samples after one edge): the
// same values as the closed form per ramp (value()), with a fast mode (10 ns), one that decays
// within the record (50 us) and one that does not (1 ms: the tail marches it exactly), on a
// uniform grid (taken mode by mode) and at times off it.
TEST(Lti, BatchValuesLongAfterTheLastCornerEqualTheClosedForm) {
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 10e-9, 1})}),
                 card("r1", {"in", "a"}, {num(1e3)}), card("c1", {"a", "0"}, {num(10e-12)}),
                 card("r2", {"in", "b"}, {num(10e3)}), card("c2", {"b", "0"}, {num(5e-9)}),
                 card("r3", {"in", "c"}, {num(100e3)}), card("c3", {"c", "0"}, {num(10e-9)})},
                {"v(a)", "v(b)", "v(a,b)", "v(in)", "v(c)"});
  LtiResponses lti = responses(*b, 200e-6, Method::Reduced);
  const auto inputs = lti.netlist_inputs(200e-6);
  std::vector<double> times;
  for (int i = 0; i <= 100'000; ++i) times.push_back(i * 1e-9);
  for (double t : {100.0003e-6, 100.7e-6, 131e-6, 199.9e-6}) times.push_back(t);
  const auto batch = lti.values(inputs, times);
  for (size_t p = 0; p < 5; ++p) {
    SCOPED_TRACE(lti.probe_labels()[p]);
    double dev = 0;
    for (size_t j = 0; j < times.size(); ++j)
      dev = std::max(dev, std::fabs(batch[p][j] - lti.value(p, times[j], inputs)));
    EXPECT_LT(dev, 1e-9);
  }
  // And the circuit's own answer: two first-order lags of a 10 ns ramp (the model's check
  // tolerance, 2e-5 of the peak, bounds the difference).
  auto lag = [](double t, double tau) {
    return (lag_ramp(t, tau) - lag_ramp(t - 10e-9, tau)) / 10e-9;
  };
  for (size_t j = 0; j < times.size(); j += 997) {
    EXPECT_NEAR(batch[0][j], lag(times[j], 10e-9), 2e-5);
    EXPECT_NEAR(batch[1][j], lag(times[j], 50e-6), 2e-5);
    EXPECT_NEAR(batch[4][j], lag(times[j], 1e-3), 2e-5);
  }
  EXPECT_NEAR(batch[1].back(), 1 - std::exp(-(199.9e-6 - 5e-9) / 50e-6), 2e-5);
  // The driven node itself (partly the model's direct term): the source, to rounding.
  for (size_t j = 20; j < times.size(); j += 997) EXPECT_NEAR(batch[3][j], 1.0, 1e-8);
}

// The closed form past the last corner (modal_tail) is the model that values() steps through:
// every probe, from t0 to far past it, and each lag's settled value. Refused before the last
// corner, while a slope goes on, and without the reduced model.
TEST(Lti, ModalTailIsTheModelPastTheLastCorner) {
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 10e-9, 1})}),
                 card("r1", {"in", "a"}, {num(1e3)}), card("c1", {"a", "0"}, {num(10e-12)}),
                 card("r2", {"in", "b"}, {num(10e3)}), card("c2", {"b", "0"}, {num(5e-9)}),
                 card("r3", {"in", "c"}, {num(100e3)}), card("c3", {"c", "0"}, {num(10e-9)}),
                 card("r4", {"in", "d"}, {num(10)}), card("l4", {"d", "e"}, {num(1e-6)}),
                 card("c4", {"e", "0"}, {num(1e-9)})},  // and a ring: Q 3.2 at 5 MHz
                {"v(a)", "v(b)", "v(c)", "v(e)"});
  LtiResponses lti = responses(*b, 200e-6, Method::Reduced);
  const auto inputs = lti.netlist_inputs(200e-6);
  const double t0 = 20e-9;
  const std::optional<LtiResponses::ModalTail> tail = lti.modal_tail(inputs, t0);
  ASSERT_TRUE(tail.has_value());
  EXPECT_EQ(tail->t0, t0);
  std::vector<double> times;
  for (double dt : {0.0, 1e-9, 37e-9, 1e-6, 50e-6, 180e-6}) times.push_back(t0 + dt);
  const auto v = lti.values(inputs, times);
  for (size_t p = 0; p < 4; ++p) {
    SCOPED_TRACE(lti.probe_labels()[p]);
    for (size_t j = 0; j < times.size(); ++j) {
      double closed = tail->constant[p];
      for (size_t i = 0; i < tail->poles.size(); ++i)
        closed += (tail->amplitude[p][i] * std::exp(tail->poles[i] * (times[j] - t0))).real();
      EXPECT_NEAR(closed, v[p][j], 1e-9) << times[j];
    }
    EXPECT_NEAR(tail->constant[p], 1.0, 2e-5);  // every lag settles at the source's 1 V
  }
  // v(a) at t0 from the amplitudes alone: its 10 ns lag's response to the ramp, closed form.
  double at_t0 = tail->constant[0];
  for (const auto& a : tail->amplitude[0]) at_t0 += a.real();
  EXPECT_NEAR(at_t0, (lag_ramp(t0, 10e-9) - lag_ramp(t0 - 10e-9, 10e-9)) / 10e-9, 2e-5);
  EXPECT_FALSE(lti.modal_tail(inputs, 5e-9).has_value());  // inside the ramp
  std::vector<SourceInput> open = inputs;                  // the ramp never ends
  open[0].ramps.pop_back();
  EXPECT_FALSE(lti.modal_tail(open, t0).has_value());
  EXPECT_FALSE(responses(*b, 200e-6, Method::March).modal_tail(inputs, t0).has_value());
}

// A differential driver's two lines (p: 0 -> 5 V, n: 5 -> 0 V, the same corners), each into a
// lag (100 ns and 300 ns) and a 30-section RC ladder, and a third source on corners of its own
// into a lag of its own (a part of the circuit the others never reach). With tie_sources the n
// line shares p's model input (LtiOptions): the model's order nearly halves, yet every probe
// keeps the closed form (the lags) and the untied model's values (the ladders); an input that
// breaks the tie cannot be evaluated (NaN, no tail).
TEST(Lti, TiedSourcesShareOneModelInputAndKeepTheClosedForm) {
  const double tr = 10e-9, t1 = 2e-6;
  std::vector<Card> cards = {
      card("vp", {"p", "0"}, {call("pwl", {0, 0, tr, 5, t1, 5, t1 + tr, 0})}),
      card("vn", {"n", "0"}, {call("pwl", {0, 5, tr, 0, t1, 0, t1 + tr, 5})}),
      card("vq", {"q", "0"}, {call("pwl", {0, 0, 3 * tr, 1})}),
      card("rp", {"p", "a"}, {num(1e3)}),
      card("cp", {"a", "0"}, {num(100e-12)}),
      card("rn", {"n", "b"}, {num(1e3)}),
      card("cn", {"b", "0"}, {num(300e-12)}),
      card("rq", {"q", "c"}, {num(1e3)}),
      card("cq", {"c", "0"}, {num(50e-12)})};
  for (const std::string line : {"p", "n"})
    for (int i = 1; i <= 30; ++i) {
      const std::string from = i == 1 ? line : line + "l" + std::to_string(i - 1),
                        to = line + "l" + std::to_string(i);
      cards.push_back(card("r" + to, {from, to}, {num(100)}));
      cards.push_back(card("c" + to, {to, "0"}, {num(10e-12)}));
    }
  auto b = make(cards, {"v(a,b)", "v(pl30,nl30)", "v(c)"});
  auto model = [&](bool tie) {
    LtiOptions opt;
    opt.horizon = 10e-6;
    opt.method = Method::Reduced;
    opt.tie_sources = tie;
    auto r = LtiResponses::compute(b->circuit, b->probes, opt);
    EXPECT_TRUE(r.ok()) << r.status().message();
    return std::move(*r);
  };
  const LtiResponses tied = model(true), free = model(false);
  EXPECT_LT(tied.stats().model.order, free.stats().model.order * 3 / 4)
      << tied.stats().model.order << " vs " << free.stats().model.order;
  const auto inputs = tied.netlist_inputs(10e-6);
  std::vector<double> times;
  for (int i = 0; i <= 400; ++i) times.push_back(i * 10e-9);
  const auto v = tied.values(inputs, times), w = free.values(inputs, times);
  auto pulse = [&](double t, double tau) {  // a 0 -> 1 -> 0 pulse through a lag
    return (lag_ramp(t, tau) - lag_ramp(t - tr, tau) - lag_ramp(t - t1, tau) +
            lag_ramp(t - t1 - tr, tau)) /
           tr;
  };
  for (size_t j = 0; j < times.size(); ++j) {
    const double t = times[j];
    SCOPED_TRACE(t);
    // The model's check bounds each edge's response by 0.095 mV per volt (5 V edges here).
    EXPECT_NEAR(v[0][j], 5 * pulse(t, 100e-9) - (5 - 5 * pulse(t, 300e-9)), 1e-3);
    EXPECT_NEAR(v[1][j], w[1][j], 1e-3);
    EXPECT_NEAR(v[2][j], (lag_ramp(t, 50e-9) - lag_ramp(t - 3 * tr, 50e-9)) / (3 * tr), 2e-4);
  }
  // The tied line's own responses are carried by p's.
  EXPECT_EQ(tied.step_response(1, 0, 1e-6), 0.0);
  std::vector<SourceInput> broken = inputs;
  broken[1].ramps.back().slope *= 2;
  EXPECT_TRUE(std::isnan(tied.values(broken, {1e-6})[0][0]));
  EXPECT_TRUE(std::isnan(tied.value(0, 1e-6, broken)));
  EXPECT_FALSE(tied.modal_tail(broken, 5e-6).has_value());
  EXPECT_TRUE(tied.modal_tail(inputs, 5e-6).has_value());
  EXPECT_FALSE(std::isnan(free.values(broken, {1e-6})[0][0]));
}

// Series RLC, underdamped: v(c) for a unit step, the closed form.
TEST(Lti, UnderdampedRlcStepResponseMatchesClosedForm) {
  const double r = 10, l = 1e-6, cap = 1e-9;
  const double alpha = r / (2 * l), w0 = 1 / std::sqrt(l * cap),
               wd = std::sqrt(w0 * w0 - alpha * alpha);
  auto b = make(
      {card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-9, 1})}), card("r1", {"in", "a"}, {num(r)}),
       card("l1", {"a", "c"}, {num(l)}), card("c1", {"c", "0"}, {num(cap)})},
      {"v(c)", "i(l1)"});
  for (Method method : kBoth) {
    SCOPED_TRACE(name(method));
    LtiResponses lti = responses(*b, 5e-6, method);
    double worst = 0;
    for (double t = 1e-9; t < 5e-6; t += 3.1e-9) {
      const double exact =
          1 - std::exp(-alpha * t) * (std::cos(wd * t) + alpha / wd * std::sin(wd * t));
      worst = std::max(worst, std::fabs(lti.step_response(0, 0, t) - exact));
    }
    EXPECT_LT(worst,
              1e-4);  // V per V of step: 1e-5 per unit time accumulated over 16 periods, Q 3.2
  }
}

// The output grid: linear interpolation between rows within 1 mV of the exact value anywhere, and
// the whole waveform within 0.5 mV of the transient engine at reltol 1e-7.
TEST(Lti, GridRuleAndTransientCrossCheckOnRlcBurst) {
  std::vector<Card> cards{card("v1", {"in", "0"},
                               {call("pwl", {0, 0, 100e-9, 0, 110e-9, 5, 350e-9, 5, 360e-9, -5,
                                             600e-9, -5, 610e-9, 0})}),
                          card("r1", {"in", "a"}, {num(20)}), card("l1", {"a", "c"}, {num(1e-6)}),
                          card("c1", {"c", "0"}, {num(1e-9)}), card("r2", {"c", "0"}, {num(200)})};
  auto b = make(cards, {"v(c)", "i(l1)"});
  for (Method method : kBoth) {
    SCOPED_TRACE(name(method));
    LtiResponses lti = responses(*b, 3e-6, method);
    const auto inputs = lti.netlist_inputs(3e-6);
    LtiResponses::GridInfo info;
    // The rule on v(c) only (a current probe's 1 uA would make this grid much finer).
    Waveform w = lti.waveform(inputs, {.tstop = 3e-6, .grid_probes = {true, false}}, &info);
    EXPECT_EQ(info.warning, "");
    EXPECT_EQ(info.corners, 6);
    EXPECT_GT(w.samples(), 100u);
    EXPECT_NEAR(w.time.back(), 3e-6, 1e-15);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> when(0, 3e-6);
    double worst = 0;
    for (int i = 0; i < 5000; ++i) {
      const double t = when(rng);
      worst = std::max(worst, std::fabs(w.value_at(0, t) - lti.value(0, t, inputs)));
    }
    EXPECT_LT(worst, 1e-3);
    EXPECT_GT(worst, 1e-5);  // the grid is not absurdly fine

    TransientOptions topt{.tstep = 1e-9, .tstop = 3e-6, .reltol = 1e-7};
    topt.tmax = 1e-9;
    auto tr = run_transient(b->circuit, topt, b->probes);
    ASSERT_TRUE(tr.ok()) << tr.status().message();
    double dev = 0, dev_i = 0;
    for (size_t i = 0; i < tr->samples(); ++i) {
      dev = std::max(dev, std::fabs(tr->columns[0][i] - lti.value(0, tr->time[i], inputs)));
      dev_i = std::max(dev_i, std::fabs(tr->columns[1][i] - lti.value(1, tr->time[i], inputs)));
    }
    EXPECT_LT(dev, 0.5e-3);
    EXPECT_LT(dev_i, 5e-6);
  }
}

TEST(Lti, DcSourcesAndNewInitialValuesShiftByTheDcGain) {
  // Divider: out = (v1 + v2) / 2 at DC, C across the bottom.
  auto b = make({card("v1", {"a", "0"}, {call("pwl", {0, 1, 1e-6, 3})}),
                 card("v2", {"b", "0"}, {word("dc"), num(2)}), card("r1", {"a", "out"}, {num(1e3)}),
                 card("r2", {"b", "out"}, {num(1e3)}), card("c1", {"out", "0"}, {num(1e-12)})},
                {"v(out)"});
  for (Method method : kBoth) {
    SCOPED_TRACE(name(method));
    LtiResponses lti = responses(*b, 10e-6, method);
    ASSERT_EQ(lti.source_count(), 1u);  // the DC source is in the operating point
    const auto in = lti.netlist_inputs(10e-6);
    EXPECT_NEAR(lti.value(0, 0.0, in), 1.5, 1e-9);
    EXPECT_NEAR(lti.value(0, 9e-6, in), 2.5, 1e-6);
    EXPECT_NEAR(lti.dc_gain(0, 0), 0.5, 1e-9);
    SourceInput other = pwl_input({0, 1e-6}, {-1, -1});  // constant -1 V
    EXPECT_TRUE(other.ramps.empty());
    EXPECT_NEAR(lti.value(0, 5e-6, {other}), 0.5, 1e-9);
  }
}

TEST(Lti, PwlInputGivesTheSourceFunctionsRamps) {
  SourceInput in = pwl_input({1e-9, 2e-9, 5e-9, 6e-9}, {0, 1, 1, 0});
  ASSERT_EQ(in.ramps.size(), 4u);
  EXPECT_DOUBLE_EQ(in.ramps[0].t, 1e-9);
  EXPECT_NEAR(in.ramps[0].slope, 1e9, 1e-3);
  EXPECT_NEAR(in.ramps[1].slope, -1e9, 1e-3);
  EXPECT_NEAR(in.ramps[2].slope, -1e9, 1e-3);
  EXPECT_NEAR(in.ramps[3].slope, 1e9, 1e-3);
  auto f = SourceFunction::Parse(
      card("v1", {"a", "0"}, {call("pwl", {1e-9, 0, 2e-9, 1, 5e-9, 1, 6e-9, 0})}));
  ASSERT_TRUE(f.ok());
  auto ramps = f->ramps(10e-9);
  ASSERT_EQ(ramps.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(ramps[i].t, in.ramps[i].t, 1e-20);
    EXPECT_NEAR(ramps[i].slope, in.ramps[i].slope, 1e-3);
  }
}

TEST(Lti, RefusesASinSourceNamingIt) {
  auto b = make(
      {card("vsin", {"in", "0"}, {call("sin", {0, 1, 1e6})}), card("r1", {"in", "0"}, {num(1e3)})},
      {"v(in)"});
  Status s = check_lti(b->circuit);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'vsin'"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("not a continuous piecewise-linear"), std::string::npos)
      << s.message();
  LtiOptions opt;
  opt.horizon = 1e-6;
  EXPECT_FALSE(LtiResponses::compute(b->circuit, b->probes, opt).ok());
}

TEST(Lti, RefusesExpAndAJumpingPwlRepeatButTakesAContinuousOne) {
  auto refused = [](std::vector<CardArg> args, const char* name) {
    auto b = make({card(name, {"in", "0"}, std::move(args)), card("r1", {"in", "0"}, {num(1e3)})},
                  {"v(in)"});
    Status s = check_lti(b->circuit);
    return !s.ok() && s.message().find(std::string("'") + name + "'") != std::string::npos;
  };
  EXPECT_TRUE(refused({call("exp", {0, 1, 0, 1e-9, 5e-9, 1e-9})}, "vexp"));
  // r=0: repeats from t=0 (value 0) after t=1u (value 1): a jump of 1 V every microsecond.
  Card jump = card("vjump", {"in", "0"}, {call("pwl", {0, 0, 1e-6, 1})});
  CardArg r0 = num(0.0);
  jump.params.emplace_back("r", r0);
  auto bj = make({jump, card("r1", {"in", "0"}, {num(1e3)})}, {"v(in)"});
  EXPECT_FALSE(check_lti(bj->circuit).ok());
  // A triangle that ends where it starts repeats without a jump: a sum of ramps.
  Card tri = card("vtri", {"in", "0"}, {call("pwl", {0, 0, 1e-6, 1, 2e-6, 0})});
  tri.params.emplace_back("r", r0);
  auto bt = make({tri, card("r1", {"in", "0"}, {num(1e3)})}, {"v(in)"});
  EXPECT_TRUE(check_lti(bt->circuit).ok()) << check_lti(bt->circuit).message();
}

TEST(Lti, RefusesAnInductorOpenedForTheDcPoint) {
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-9, 1})}),
                 card("l1", {"in", "0"}, {num(1e-6)})},
                {"i(l1)"});
  Status s = check_lti(b->circuit);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("opened for the DC"), std::string::npos) << s.message();
}

// The superposition's predicted cost is probes x sum over ramps of the rows inside the march
// window; over max_evaluations the rule stops with an empty waveform (auto then runs the
// transient).
TEST(Lti, GridPredictsItsEvaluationsAndStopsOverBudget) {
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 10e-9, 1, 1e-6, 1})}),
                 card("r1", {"in", "out"}, {num(1e3)}), card("c1", {"out", "0"}, {num(1e-9)})},
                {"v(out)", "v(in)"});
  LtiResponses lti = responses(*b, 2e-6);
  const double end = lti.stats().settled_at;
  ASSERT_GT(end, 0.0);
  LtiResponses::GridOptions grid;
  grid.tstop = 2e-6;
  grid.step = 1e-8;
  LtiResponses::GridInfo info;
  // Ramps at 0, 10 ns (end of the rise) and 1 us (a slope change of 0: none).
  const auto inputs = lti.netlist_inputs(2e-6);
  ASSERT_EQ(inputs.size(), 1u);
  ASSERT_EQ(inputs[0].ramps.size(), 2u);
  const double expected =
      2.0 * (std::min(2e-6, end) + std::min(2e-6 - 10e-9, end)) / 1e-8;  // 2 probes
  Waveform w = lti.waveform(inputs, grid, &info);
  EXPECT_FALSE(info.over_budget);
  EXPECT_NEAR(info.evaluations, expected, 1e-6 * expected);
  EXPECT_EQ(w.samples(), 201u);
  grid.max_evaluations = 0.5 * expected;
  w = lti.waveform(inputs, grid, &info);
  EXPECT_TRUE(info.over_budget);
  EXPECT_EQ(w.samples(), 0u);
}

// The output grid rule holds its 1 uA promise in the cell just after a corner too: an RL lag
// of tau = 0.5 ns, driven by a 10 ns ramp whose end is inside the first 20 ns cell, read by
// linear interpolation between the rows against the closed-form ramp response.
TEST(Lti, GridRuleMeetsItsToleranceRightAfterACorner) {
  const double r = 2e3, l = 1e-6, tau = l / r, a = 1.0 / 10e-9;  // input slope V/s
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 10e-9, 1, 1e-6, 1})}),
                 card("r1", {"in", "x"}, {num(r)}), card("l1", {"x", "0"}, {num(l)})},
                {"i(l1)"});
  for (Method method : kBoth) {
    SCOPED_TRACE(name(method));
    LtiResponses lti = responses(*b, 1e-6, method);
    LtiResponses::GridOptions grid;
    grid.tstop = 1e-6;
    Waveform w = lti.waveform(lti.netlist_inputs(1e-6), grid);
    auto exact = [&](double t) {  // i = (a / r) * (lag_ramp(t) - lag_ramp(t - 10 ns))
      return a / r * (lag_ramp(t, tau) - lag_ramp(t - 10e-9, tau));
    };
    double worst = 0;
    for (size_t i = 0; i + 1 < w.time.size(); ++i)
      for (double f : {0.25, 0.5, 0.75}) {
        const double t = w.time[i] + f * (w.time[i + 1] - w.time[i]);
        const double lin = w.columns[0][i] + f * (w.columns[0][i + 1] - w.columns[0][i]);
        worst = std::max(worst, std::fabs(lin - exact(t)));
      }
    EXPECT_LT(worst, 1.2e-6) << "rows: " << w.time.size();  // 1 uA target, 20 % for the march
  }
}

// Slow circuits (issue 28): the output grid is sized from the run, not from nanoseconds. Each
// circuit's response through the reduced model's grid rule, checked against its closed form at
// every row and between rows (linear interpolation within the 1 mV rule), with a bounded row
// count. Lag responses to a ramp input rising over tr from t0.
double lag_edge(double t, double t0, double tr, double tau) {
  return (lag_ramp(t - t0, tau) - lag_ramp(t - t0 - tr, tau)) / tr;
}
double edge(double t, double t0, double tr) {
  return std::clamp((t - t0) / tr, 0.0, 1.0);
}
void expect_grid_matches(const Built& b, double tstop, size_t probe,
                         const std::function<double(double)>& exact, double tol, long max_rows,
                         Method method = Method::Reduced) {
  LtiResponses lti = responses(b, tstop, method);
  LtiResponses::GridOptions grid;
  grid.tstop = tstop;
  LtiResponses::GridInfo info;
  const Waveform w = lti.waveform(lti.netlist_inputs(tstop), grid, &info);
  EXPECT_EQ(info.warning, "");
  EXPECT_LE(static_cast<long>(w.time.size()), max_rows);
  double at_rows = 0, between = 0;
  for (size_t i = 0; i < w.time.size(); ++i) {
    at_rows = std::max(at_rows, std::fabs(w.columns[probe][i] - exact(w.time[i])));
    if (i + 1 == w.time.size()) continue;
    for (double f : {0.25, 0.5, 0.75}) {  // linear interpolation inside each cell
      const double t = w.time[i] + f * (w.time[i + 1] - w.time[i]);
      const double lin = (1 - f) * w.columns[probe][i] + f * w.columns[probe][i + 1];
      between = std::max(between, std::fabs(lin - exact(t)));
    }
  }
  EXPECT_LT(at_rows, tol) << w.time.size() << " rows";
  EXPECT_LT(between, 1e-3) << w.time.size() << " rows";  // the grid rule's 1 mV
}

TEST(LtiSlowCircuits, RcWithOneSecondTimeConstantOverSevenSeconds) {
  // ngspice's tests/general/rc.cir: 1 ohm, 1 F, PULSE(0 1) (rise = TSTEP = 0.1 s), .tran 0.1 7.
  // At 20 ns a row this was 350 million rows (21 GB); sized from the run it is 65,537.
  auto b = make({card("v1", {"1", "0"}, {call("pwl", {0, 0, 0.1, 1})}),
                 card("r1", {"1", "2"}, {num(1)}), card("c1", {"2", "0"}, {num(1)})},
                {"v(2)"});
  expect_grid_matches(
      *b, 7, 0, [](double t) { return lag_edge(t, 0, 0.1, 1.0); }, 1e-6, 70'000);
}

TEST(LtiSlowCircuits, RlWithTenMillisecondTimeConstant) {
  // 10 mH into 1 ohm: the resistor's voltage follows a 1 us edge with tau = 10 ms. The source
  // drives the inductor directly (no resistor at its node), which made the reduced model's
  // projection singular in both sign forms until the source's own branch joined the basis.
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-3, 0, 1.001e-3, 1})}),
                 card("l1", {"in", "x"}, {num(10e-3)}), card("r1", {"x", "0"}, {num(1)})},
                {"v(x)", "i(l1)", "v(in)"});
  const auto exact = [](double t) { return lag_edge(t, 1e-3, 1e-6, 10e-3); };
  expect_grid_matches(*b, 60e-3, 0, exact, 1e-6, 70'000);
  // The inductor's current (1 ohm: the same curve in A) and the driven node, from the model.
  LtiResponses lti = responses(*b, 60e-3, Method::Reduced);
  EXPECT_EQ(lti.stats().method, "reduced model");
  const auto in = lti.netlist_inputs(60e-3);
  for (double t : {0.5e-3, 1.0005e-3, 2e-3, 11e-3, 45e-3}) {
    EXPECT_NEAR(lti.value(1, t, in), exact(t), 1e-6) << t;
    EXPECT_NEAR(lti.value(2, t, in), edge(t, 1e-3, 1e-6), 1e-9) << t;
  }
}

TEST(LtiSlowCircuits, CouplingCapWithTenMegohmBleederIdlingFourMilliseconds) {
  // 2.2 nF into 10 Mohm (tau 22 ms): a 10 ns edge passes and then droops over 4 ms of idle.
  auto b = make({card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-6, 0, 1.01e-6, 1})}),
                 card("c1", {"in", "x"}, {num(2.2e-9)}), card("r1", {"x", "0"}, {num(10e6)})},
                {"v(x)"});
  expect_grid_matches(
      *b, 4e-3, 0, [](double t) { return edge(t, 1e-6, 10e-9) - lag_edge(t, 1e-6, 10e-9, 22e-3); },
      1e-6, 70'000);
}

TEST(LtiSlowCircuits, NanosecondAndMillisecondTimeConstantsInOneCircuit) {
  // One source, two RC sections: 1 ohm / 1 nF (tau 1 ns) and 1 kohm / 1 uF (tau 1 ms), a 1 ns
  // edge up at 1 us and down at 2.5 ms, over 5 ms. Uniform halving went to its 4,000,000-row
  // limit for the 1 ns section; the locally refined grid keeps 65,537 first-level rows and
  // refines only after the two edges.
  auto b = make({card("v1", {"in", "0"},
                      {call("pwl", {0, 0, 1e-6, 0, 1.001e-6, 1, 2.5e-3, 1, 2.500001e-3, 0})}),
                 card("r1", {"in", "a"}, {num(1)}), card("c1", {"a", "0"}, {num(1e-9)}),
                 card("r2", {"in", "b"}, {num(1e3)}), card("c2", {"b", "0"}, {num(1e-6)})},
                {"v(a)", "v(b)"});
  auto pulse = [](double t, double tau) {
    return lag_edge(t, 1e-6, 1e-9, tau) - lag_edge(t, 2.5e-3, 1e-9, tau);
  };
  // Each section against its closed form, at and between rows (the 1 mV rule), rows bounded.
  expect_grid_matches(
      *b, 5e-3, 0, [&](double t) { return pulse(t, 1e-9); }, 1e-6, 70'000);
  expect_grid_matches(
      *b, 5e-3, 1, [&](double t) { return pulse(t, 1e-3); }, 1e-6, 70'000);
  // The nanosecond response is resolved where it happens: rows within 10 ns after each edge.
  LtiResponses lti = responses(*b, 5e-3, Method::Reduced);
  LtiResponses::GridInfo info;
  const Waveform w = lti.waveform(lti.netlist_inputs(5e-3), {.tstop = 5e-3}, &info);
  for (double edge_at : {1.001e-6, 2.500001e-3}) {
    const auto rows_in = std::count_if(
        w.time.begin(), w.time.end(), [&](double t) { return t > edge_at && t < edge_at + 10e-9; });
    EXPECT_GE(rows_in, 5) << edge_at;
  }
  EXPECT_LT(info.step, 1e-9);                          // refined below the fast time constant
  EXPECT_NEAR(info.coarse_step, 5e-3 / 65536, 1e-15);  // and coarse elsewhere
}

TEST(Lti, OptionsAreValidatedByName) {
  LtiOptions opt;
  Status s = opt.validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("horizon = 0"), std::string::npos) << s.message();
  opt.horizon = 1e-6;
  opt.step_reltol = 2;
  EXPECT_NE(opt.validate().message().find("step_reltol = 2"), std::string::npos);
}

}  // namespace
}  // namespace isolink
