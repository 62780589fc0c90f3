// isolink stress (analysis/stress.h): the IEC 61000-4-2 current against the standard's table,
// an ESD scenario against its closed form (the discharge's charge on a large Y cap: V = Q / C),
// the limits' verdict in words, and the stress: block's errors at file:line:col.
#include "analysis/stress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {
namespace {

TEST(EsdCurrent, MatchesTheStandardsTable) {
  // IEC 61000-4-2:2008 table 3 at 8 kV: first peak 30 A +-15 %, rise 0.6-1 ns (10-90 %),
  // 16 A +-30 % at 30 ns, 8 A +-30 % at 60 ns. The Annex B formula lands close to the centres.
  double peak = 0, t_peak = 0;
  for (double t = 1e-12; t < 5e-9; t += 1e-12)
    if (esd_current(t, 8e3) > peak) peak = esd_current(t, 8e3), t_peak = t;
  EXPECT_NEAR(peak, 30.0, 0.5);  // 29.84 A
  EXPECT_NEAR(t_peak, 1.46e-9, 0.02e-9);
  double t10 = 0, t90 = 0;
  for (double t = 1e-12; t < t_peak; t += 1e-12) {
    if (t10 == 0 && esd_current(t, 8e3) > 0.1 * peak) t10 = t;
    if (t90 == 0 && esd_current(t, 8e3) > 0.9 * peak) t90 = t;
  }
  EXPECT_GT(t90 - t10, 0.6e-9);
  EXPECT_LT(t90 - t10, 1.0e-9);
  EXPECT_NEAR(esd_current(30e-9, 8e3), 16.0, 0.2);
  EXPECT_NEAR(esd_current(60e-9, 8e3), 8.0, 0.2);
  EXPECT_DOUBLE_EQ(esd_current(30e-9, -8e3), -esd_current(30e-9, 8e3));
  EXPECT_EQ(esd_current(0, 8e3), 0.0);
  // The PWL follows the function within 0.5 % of the peak between its points.
  const std::vector<double> pwl = esd_pwl(8e3, 20e-9, 280e-9);
  double worst = 0;
  for (size_t i = 2; i + 1 < pwl.size(); i += 2) {
    const double tm = 0.5 * (pwl[i - 2] + pwl[i]);
    const double lin = 0.5 * (pwl[i - 1] + pwl[i + 1]);
    worst = std::max(worst, std::abs(lin - esd_current(tm - 20e-9, 8e3)));
  }
  EXPECT_LT(worst, 0.005 * peak);
  // Nothing flows before the discharge: the PWL is 0 up to t0 (a ramp from (0, 0) to the first
  // point after t0 charged the line by 0.7 nC before the discharge, 3 V on the pins).
  ASSERT_GE(pwl.size(), 4u);
  EXPECT_EQ(pwl[2], 20e-9);
  EXPECT_EQ(pwl[3], 0.0);
}

// The discharge's charge (1.169 uC at 8 kV) lands on a 1 uF Y cap at the zapped connector: the
// connector peaks at Q / C = 1.169 V (the isolation cap's series path, 2.2 nF, and the cable's
// 100 pF add at most 0.25 %), below any clamp. 1 uF keeps every diode off: closed form.
constexpr const char* kYCapLink = R"(name: ycap
tx: {device: bq79600, y_cap: 1u}
rx: {device: bq7961x}
cable: {length: 2}
stress: {only: [esd]}
)";

double esd_charge(double level) {
  double q = 0;
  const double dt = 1e-12;
  for (double t = dt; t < 300e-9; t += dt) q += esd_current(t, level) * dt;
  return q;
}

TEST(Stress, EsdOnALargeYCapGivesChargeOverCapacitance) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(kYCapLink, "ycap.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<std::vector<StressScenario>> sc = build_stress_scenarios(*spec, *parts);
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  ASSERT_EQ(sc->size(), 8u);  // esd only: 2 ends x 2 lines x 2 polarities
  const double q = esd_charge(8e3);
  EXPECT_NEAR(q, 1.169e-6, 0.002e-6);
  for (StressScenario& s : *sc) {
    if (s.end != "tx" || s.line != "p") continue;
    SimulationRequest req{.probes = {"v(tx_c1p)"}, .reltol = kStressReltol};
    StatusOr<SimulationResult> r = simulate_netlist(s.link.netlist, req);
    ASSERT_TRUE(r.ok()) << r.status().message();
    const std::vector<double>& v = r->wave.columns[0];
    const double peak = s.id.ends_with("pos") ? *std::max_element(v.begin(), v.end())
                                              : -*std::min_element(v.begin(), v.end());
    EXPECT_NEAR(peak, q / 1e-6, 0.01 * q / 1e-6) << s.id;
    // The scenario's own verdict: a volt at the connector harms nothing.
    if (!s.id.ends_with("pos")) continue;
    ASSERT_TRUE(run_stress_scenario(s, *spec, *parts).ok());
    EXPECT_TRUE(s.survives) << s.id << ": " << s.first_broken;
    EXPECT_FALSE(s.communicates.has_value());
    ASSERT_EQ(s.caps.size(), 4u);
    EXPECT_GT(s.peak_pin_v.at("txp").max, 2.4);  // the idle 2.5 V
    EXPECT_LT(s.peak_pin_v.at("txp").max, 3.7);
  }
}

TEST(Stress, ABrokenLimitIsNamedWithItsSource) {
  std::string text = kYCapLink;
  text.replace(text.find("stress: {only: [esd]}"), 21, "stress: {only: [esd], pin_abs_max: 1}");
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(text, "ycap.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<std::vector<StressScenario>> sc = build_stress_scenarios(*spec, *parts);
  ASSERT_TRUE(sc.ok());
  StressScenario& s = sc->front();
  ASSERT_TRUE(run_stress_scenario(s, *spec, *parts).ok());
  EXPECT_FALSE(s.survives);
  EXPECT_NE(s.first_broken.find("beyond the pin limit +-1 V (stress.pin_abs_max in the spec"),
            std::string::npos)
      << s.first_broken;
}

TEST(StressSpec, DefaultsAndErrorsAtTheValue) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text("name: a\n", "a.yaml");
  ASSERT_TRUE(spec.ok());
  EXPECT_EQ(spec->stress.esd_v, 8e3);
  EXPECT_EQ(spec->stress.step_v, 60);
  EXPECT_EQ(spec->stress.step_rise, 1e-6);
  EXPECT_EQ(spec->stress.pin_cm_limit, 20);
  EXPECT_EQ(spec->stress.cap_rating, 2e3);
  spec = link::read_link_spec_text(
      "name: a\nstress: {esd: 4kV, ground_step: 400, "
      "ground_rise: 200n}\n",
      "a.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  EXPECT_EQ(spec->stress.esd_v, 4e3);
  EXPECT_EQ(spec->stress.step_v, 400);
  EXPECT_DOUBLE_EQ(spec->stress.step_rise, 200e-9);
  const std::pair<const char*, const char*> bad[] = {
      {"name: a\nstress: {bogus: 1}\n", "a.yaml:2:"},
      {"name: a\nstress:\n  only: [esd, wire]\n", "a.yaml:3:15: error: key 'stress.only' = 'wire'"},
      {"name: a\nstress: {esd: 40kV}\n", "a.yaml:2:15: error: key 'stress.esd' = 40000 V"},
      {"name: a\nstress: {ground_rise: 1s}\n", "a.yaml:2:23: error: key 'stress.ground_rise'"},
      {"name: a\nstress: {esd: 8kA}\n", "a.yaml:2:15: error"},
  };
  for (auto [text, want] : bad) {
    StatusOr<link::LinkSpec> s = link::read_link_spec_text(text, "a.yaml");
    ASSERT_FALSE(s.ok()) << text;
    EXPECT_NE(s.status().message().find(want), std::string::npos) << s.status().message();
  }
}

}  // namespace
}  // namespace isolink::analysis
