// S (the voltage-controlled switch, solver/elements/switch.cpp): a 10 V source closing onto
// 1 nF + 1 Mohm through a 100 ohm contact at 1 us and opening at 2 us, against the RC closed form
// and ngspice (its SW model, the same netlist), on both engines that run a switch: auto takes the
// port model (the switch's control is a PWL source of its own, read directly) and the full
// transient when asked; the model's refusals at file:line:col.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "analysis/simulate.h"
#include "netlists/spice_reader.h"
#include "ngspice_runner.h"

namespace isolink {
namespace {

const std::string kData = std::string(ISOLINK_TEST_DATA_DIR) + "/nonlinear";

double at_time(const Waveform& w, size_t k, double t) {
  auto it = std::lower_bound(w.time.begin(), w.time.end(), t);
  const size_t j = std::clamp<size_t>(it - w.time.begin(), 1, w.time.size() - 1);
  const double f = (t - w.time[j - 1]) / (w.time[j] - w.time[j - 1]);
  return w.columns[k][j - 1] + f * (w.columns[k][j] - w.columns[k][j - 1]);
}

class SwitchEngines : public ::testing::TestWithParam<analysis::Engine> {};

TEST_P(SwitchEngines, ClosesAnRcAgainstTheClosedFormAndNgspice) {
  const std::string path = kData + "/switch_rc.cir";
  auto netlist = read_spice_file(path);
  ASSERT_TRUE(netlist.ok()) << netlist.status().message();
  const std::vector<std::string> probes{"v(c)", "i(vam)"};
  analysis::SimulationRequest req{.probes = probes, .reltol = 1e-6, .engine = GetParam()};
  auto r = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->engine, GetParam() == analysis::Engine::Auto ? analysis::Engine::PortModel
                                                            : analysis::Engine::Transient)
      << r->engine_note;
  // Closed form. Off (1e12 ohm against 1 Mohm): v = 10 V * 1e6 / (1e6 + 1e12) = 10 uV. From
  // t0 = 1 us (the control crosses 0.5 V 0.5 ps later) through 100 ohm || 1 Mohm:
  // v = v_inf + (v0 - v_inf) e^(-(t - t0) / tau), v_inf = 10 * 1e6 / (1e6 + 100), tau = C R || R.
  const double t0 = 1e-6, rp = 100.0 * 1e6 / (100.0 + 1e6), tau = 1e-9 * rp;
  const double v_inf = 10 * 1e6 / (1e6 + 100), v0 = 10 * 1e6 / (1e6 + 1e12);
  auto closed = [&](double t) {
    if (t <= t0) return v0;
    const double tc = std::min(t, 2e-6);
    const double v = v_inf + (v0 - v_inf) * std::exp(-(tc - t0) / tau);
    return v * std::exp(-(t - tc) / 1e-3);  // open again: 1 nF through 1 Mohm
  };
  double worst = 0;
  for (double t : {0.5e-6, 1.02e-6, 1.05e-6, 1.1e-6, 1.2e-6, 1.5e-6, 1.99e-6, 2.5e-6, 3e-6}) {
    const double v = at_time(r->wave, 0, t);
    worst = std::max(worst, std::abs(v - closed(t)));
    EXPECT_NEAR(v, closed(t), 2e-3) << t;
  }
  // The peak current: 10 V over 100 ohm at the closing; the charge moved: C (v(2 us) - v0).
  const std::vector<double>& i = r->wave.columns[1];
  const double peak = *std::max_element(i.begin(), i.end());
  EXPECT_NEAR(peak, 0.1, 1e-4);
  double q = 0;
  for (size_t j = 1; j < r->wave.samples(); ++j)
    if (r->wave.time[j] <= 2e-6)
      q += 0.5 * (i[j] + i[j - 1]) * (r->wave.time[j] - r->wave.time[j - 1]);
  // The charge into the cap plus what the 1 Mohm drained (< 1 us * 10 uA = 10 pC).
  EXPECT_NEAR(q, 1e-9 * (closed(2e-6) - v0), 0.02e-9);
  auto ng = testing::run_ngspice(path, probes, ::testing::TempDir() + "/switch_rc",
                                 ".options reltol=1e-6 abstol=1e-12 vntol=1e-9");
  ASSERT_TRUE(ng.ok()) << ng.status().message();
  const double dv = testing::max_abs_difference(*ng, 0, r->wave, 0);
  const double di = testing::max_abs_difference(*ng, 1, r->wave, 1, 1.01e-6);
  double ng_peak = 0;
  for (double x : ng->columns[1]) ng_peak = std::max(ng_peak, x);
  EXPECT_LT(dv, 5e-3);
  EXPECT_NEAR(ng_peak, peak, 1e-3);
  std::printf(
      "switch_rc (%s): closed form within %.3f mV; ngspice v(c) within %.3f mV, i(vam) %.3f mA "
      "after 1.01 us, peak %.5f A (ngspice %.5f A)\n",
      analysis::engine_name(r->engine), worst * 1e3, dv * 1e3, di * 1e3, peak, ng_peak);
}

INSTANTIATE_TEST_SUITE_P(Engines, SwitchEngines,
                         ::testing::Values(analysis::Engine::Auto, analysis::Engine::Transient),
                         [](const ::testing::TestParamInfo<analysis::Engine>& param) {
                           return std::string(analysis::engine_name(param.param));
                         });

TEST(Switch, RefusesHysteresisAndBadResistances) {
  const std::pair<const char*, const char*> bad[] = {
      {"s1 a 0 c 0 m\nr1 a 0 1\nv1 c 0 1\n.model m sw(vt=0.5 vh=0.1)\n.tran 1n 1u\n.end\n",
       "s.cir:5:20: error: switch model m: vh = 0.1: must be 0"},
      {"s1 a 0 c 0 m\nr1 a 0 1\nv1 c 0 1\n.model m sw(ron=0)\n.tran 1n 1u\n.end\n",
       "s.cir:5:13: error: switch model m: ron = 0: must be positive"},
      {"s1 a 0 c 0 m\nr1 a 0 1\nv1 c 0 1\n.model m sw(vx=1)\n.tran 1n 1u\n.end\n",
       "s.cir:5:13: error: unknown switch model parameter 'vx'"},
  };
  for (auto [text, want] : bad) {
    auto n = read_spice_text(std::string("* s\n") + text, "s.cir");
    std::string message;
    if (!n.ok()) {
      message = n.status().message();
    } else {
      auto r = analysis::simulate_netlist(*n, {.probes = {"v(a)"}});
      ASSERT_FALSE(r.ok()) << text;
      message = r.status().message();
    }
    EXPECT_NE(message.find(want), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace isolink
