// isolink stress (analysis/stress.h): the IEC 61000-4-2 current against the standard's table,
// an ESD scenario against its closed form (the discharge's charge on a large Y cap: V = Q / C),
// a hot-plug against charge conservation across the first contact, the limits' verdict in words,
// the scenario set per kind and direction, and the stress: block's errors at file:line:col.
#include "analysis/stress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

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

// Hot-plug onto a cap link whose far end has a 100 nF Y cap per line. The plugged (tx) module's
// connector P sits at V = 2 V (its bleed to its own ground), the cable and the far end at 0. When
// P's contact closes, the charge C_a (V - V_j) leaves the plugged isolation cap (C_a = 2.2 nF, its
// board side back at its DC level once the board settles) and lands on the far side's
// C_b = 100 nF + 2.2 nF (the Y cap and the far isolation cap): Q = V C_a C_b / (C_a + C_b) =
// 4.307 nC through the contact, the junction at V_j = V C_a / (C_a + C_b) = 42.1 mV. 2 V keeps
// every clamp off; the cable's own capacitance (tens of pF) moves both by under 0.1 %.
constexpr const char* kHotPlugLink = R"(name: hotplug
tx: {device: bq79600}
rx: {device: bq7961x, y_cap: 100n}
cable: {length: 2}
stress: {only: [hot_plug], hot_plug_v: 2, hot_plug_gap: 3u}
)";

TEST(Stress, HotPlugMovesTheSeriesCapsCharge) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(kHotPlugLink, "hp.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<std::vector<StressScenario>> sc = build_stress_scenarios(*spec, *parts);
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  ASSERT_EQ(sc->size(), 4u);  // 2 ends x P or N first
  StressScenario& s = sc->front();
  ASSERT_EQ(s.id, "hot_plug_tx_p_first");
  const double v = 2, ca = 2.2e-9, cb = 102.2e-9;
  const double q = v * ca * cb / (ca + cb), vj = v * ca / (ca + cb);
  // Up to just before the second contact, at the engine's default tolerance (the charge is
  // conserved by the formula at any tolerance): seconds instead of minutes.
  SimulationRequest req{
      .probes = {"i(vcontactpam)", "v(tx_c1p)"}, .tstop = s.t_start + 2.95e-6, .reltol = 1e-3};
  StatusOr<SimulationResult> r = simulate_netlist(s.link.netlist, req);
  ASSERT_TRUE(r.ok()) << r.status().message();
  const Waveform& w = r->wave;
  double charge = 0, junction = 0;
  const double t1 = s.t_start, t_settled = t1 + 2.9e-6;  // the second contact closes at t1 + 3 us
  for (size_t j = 1; j < w.samples(); ++j) {
    if (w.time[j] <= t_settled)
      charge += 0.5 * (w.columns[0][j] + w.columns[0][j - 1]) * (w.time[j] - w.time[j - 1]);
    if (w.time[j - 1] <= t_settled) junction = w.columns[1][j];
  }
  // Into the module: negative (the cable pulls the connector down).
  EXPECT_NEAR(-charge, q, 0.01 * q);
  EXPECT_NEAR(junction, vj, 0.02 * vj);
  std::printf("hot plug: charge %.4g C (closed form %.4g), junction %.4g V (%.4g)\n", -charge, q,
              junction, vj);
  EXPECT_EQ(s.pin_ground.at("txp"), "gplug");
  EXPECT_EQ(s.pin_ground.at("rxp"), "0");
  // The whole scenario as stress runs it, both contacts closed and settled: the lines end
  // alike (the common mode's final state), so each contact has moved the same q out of the
  // module over the record (contacts' charge_C, positive into the module).
  ASSERT_TRUE(run_stress_scenario(s, *spec, *parts).ok());
  ASSERT_EQ(s.contacts.size(), 2u);
  EXPECT_EQ(s.contacts[0].contact, "scontactp");  // P first
  EXPECT_EQ(s.contacts[1].contact, "scontactn");
  for (const ContactPeak& c : s.contacts) {
    EXPECT_NEAR(-c.charge_c, q, 0.02 * q) << c.contact;
    // The inrush is at least the mean current that moves q within the settling (under 3 us).
    EXPECT_GT(c.peak_1ns_a, q / 3e-6) << c.contact;
    std::printf("%s: %.4g C (closed form %.4g), inrush %.4g A over 1 ns\n", c.contact.c_str(),
                -c.charge_c, q, c.peak_1ns_a);
  }
}

TEST(Stress, ScenarioSetPerKindAndDirection) {
  StatusOr<link::LinkSpec> spec =
      link::read_link_spec_file(std::string(ISOLINK_EXAMPLES_DIR) + "/bq79606a_tvs_2m.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StressOptions opt;
  StatusOr<std::vector<StressScenario>> all = build_stress_scenarios(*spec, *parts, opt);
  ASSERT_TRUE(all.ok()) << all.status().message();
  // 2 cm_step + 2 cm_wave + 8 esd + 4 hot_plug + 9 faults x 2 directions.
  EXPECT_EQ(all->size(), 2u + 2u + 8u + 4u + 18u);
  opt.directions = {link::Direction::kUp};
  opt.only = {"wire", "cm_wave"};
  StatusOr<std::vector<StressScenario>> up = build_stress_scenarios(*spec, *parts, opt);
  ASSERT_TRUE(up.ok());
  ASSERT_EQ(up->size(), 10u);
  for (const StressScenario& s : *up) {
    EXPECT_EQ(s.direction, "up") << s.id;
    EXPECT_EQ(s.tx_end, "rx") << s.id;
    EXPECT_EQ(s.receiver_p, "rxp");
  }
  // The wire faults going up sit at the netlist's tx side (the spec's rx end), its module on
  // its own ground: the open line's cable end is moved off the connector.
  const StressScenario& open = (*up)[1];
  ASSERT_EQ(open.id, "wire_open_p_up");
  EXPECT_EQ(open.pin_ground.at("txp"), "gfault");
  bool moved = false;
  for (const Card& c : open.link.netlist.cards)
    for (const std::string& n : c.nodes) moved = moved || n == "open_p";
  EXPECT_TRUE(moved);
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
  EXPECT_EQ(spec->stress.hot_plug_v, 60);
  EXPECT_EQ(spec->stress.hot_plug_gap, 5e-6);
  EXPECT_EQ(spec->stress.wave_v, 50);
  EXPECT_EQ(spec->stress.wave_f, 20e3);
  EXPECT_EQ(spec->stress.wave_shape, "square");
  EXPECT_EQ(spec->stress.wave_dvdt, 2);
  EXPECT_EQ(spec->stress.leak_ohms, 1e3);
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
      {"name: a\nstress:\n  only: [esd, wires]\n",
       "a.yaml:3:15: error: key 'stress.only' = 'wires'"},
      {"name: a\nstress: {hot_plug_v: 3kV}\n",
       "a.yaml:2:22: error: key 'stress.hot_plug_v' = 3000: must be at most 2 kV"},
      {"name: a\nstress: {hot_plug_gap: 2m}\n",
       "a.yaml:2:24: error: key 'stress.hot_plug_gap' = 0.002: must be from 1 ns to 1 ms"},
      {"name: a\nstress: {wave_shape: triangle}\n",
       "a.yaml:2:22: error: key 'stress.wave_shape': expected square | sine, found 'triangle'"},
      {"name: a\nstress: {wave_f: 10meg}\n",
       "a.yaml:2:18: error: key 'stress.wave_f' = 1e+07: must be from 1 kHz to 1 MHz"},
      {"name: a\nstress: {wave_v: 500, wave_dvdt: 0.01}\n",
       "a.yaml:2:34: error: key 'stress.wave_dvdt' = 0.01 V/ns: the square's edge"},
      {"name: a\nstress: {leak_ohms: 0.1}\n",
       "a.yaml:2:21: error: key 'stress.leak_ohms' = 0.1: must be from 1 ohm to 1 Gohm"},
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
