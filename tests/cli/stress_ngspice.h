// A stress scenario replayed in ngspice (issue 42): the scenario built from a spec, run by
// isolink, exported, simulated by ngspice at reltol 1e-4 (its other options at their defaults:
// tighter ones abort on clamp circuits, issue 41), and every pin's max and min and every diode's
// peak current held to ngspice's within 5 % or 0.2 V (0.05 A); a scenario with traffic has its
// `communicates` held to the checker's verdict on ngspice's receiver waveform. Shared by the
// command's tests and the seeded corpus (stress_command_test.cpp, stress_corpus_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "analysis/stress.h"
#include "eye/check.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/spice_writer.h"
#include "ngspice_runner.h"
#include "run_isolink.h"

namespace isolink::testing {

// The largest |isolink - ngspice| over the pins, relative to the allowance (<= 1 passes).
struct StressAgreement {
  double worst_pin_v = 0;      // V
  double worst_pin_share = 0;  // of its allowance
  double worst_diode_a = 0;    // A
  bool communicates = false;   // the scenario's verdict (traffic scenarios; checked equal to
                               // the checker's on ngspice's waveform)
};

inline StressAgreement stress_vs_ngspice(const link::LinkSpec& spec, const std::string& id) {
  StressAgreement out;
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  EXPECT_TRUE(parts.ok());
  if (!parts) return out;
  analysis::StressOptions opt;
  for (const std::string& kind : link::stress_kinds())  // the scenario's kind: its id's prefix
    if (id.starts_with(kind + "_")) opt.only = {kind};
  StatusOr<std::vector<analysis::StressScenario>> sc =
      analysis::build_stress_scenarios(spec, *parts, opt);
  EXPECT_TRUE(sc.ok()) << sc.status().message();
  if (!sc) return out;
  auto it = std::find_if(sc->begin(), sc->end(),
                         [&](const analysis::StressScenario& s) { return s.id == id; });
  EXPECT_NE(it, sc->end()) << id;
  if (it == sc->end()) return out;
  analysis::StressScenario& s = *it;
  const Status run = analysis::run_stress_scenario(s, spec, *parts);
  EXPECT_TRUE(run.ok()) << run.message();
  if (!run.ok()) return out;
  const std::string work = test_dir();
  const std::string path = work + "/" + id + ".cir";
  { std::ofstream(path) << write_spice(s.link.netlist); }
  std::vector<std::string> probes;
  for (const auto& [node, ground] : s.pin_ground)
    probes.push_back(ground == "0" ? "v(" + node + ")" : "v(" + node + "," + ground + ")");
  for (const analysis::DiodePeak& d : s.diodes) probes.push_back("i(" + d.ammeter + ")");
  for (const analysis::ContactPeak& c : s.contacts) probes.push_back("i(" + c.ammeter + ")");
  if (s.traffic) probes.push_back("v(" + s.receiver_p + "," + s.receiver_n + ")");
  StatusOr<Waveform> ng = run_ngspice(path, probes, work, ".options reltol=1e-4");
  EXPECT_TRUE(ng.ok()) << ng.status().message();
  if (!ng) return out;
  size_t k = 0;
  for (const auto& [node, peak] : s.peak_pin_v) {
    const std::vector<double>& v = ng->columns[k++];
    const double mx = *std::max_element(v.begin(), v.end());
    const double mn = *std::min_element(v.begin(), v.end());
    for (auto [mine, theirs] : {std::pair{peak.max, mx}, std::pair{peak.min, mn}}) {
      const double allow = std::max(0.2, 0.05 * std::abs(theirs));
      EXPECT_NEAR(mine, theirs, allow) << id << " " << node;
      out.worst_pin_v = std::max(out.worst_pin_v, std::abs(mine - theirs));
      out.worst_pin_share = std::max(out.worst_pin_share, std::abs(mine - theirs) / allow);
    }
    std::printf("%s %s: max %.4f V (ngspice %.4f), min %.4f V (ngspice %.4f)\n", id.c_str(),
                node.c_str(), peak.max, mx, peak.min, mn);
  }
  for (const analysis::DiodePeak& d : s.diodes) {
    const std::vector<double>& a = ng->columns[k++];
    double mx = 0;
    for (double x : a) mx = std::max(mx, std::abs(x));
    EXPECT_NEAR(d.peak_a, mx, std::max(0.05, 0.05 * mx)) << id << " " << d.diode;
    out.worst_diode_a = std::max(out.worst_diode_a, std::abs(d.peak_a - mx));
    std::printf("%s %s: peak %.4g A (ngspice %.4g)\n", id.c_str(), d.diode.c_str(), d.peak_a, mx);
  }
  for (const analysis::ContactPeak& c : s.contacts) {  // hot_plug: inrush and charge moved
    const std::vector<double>& a = ng->columns[k++];
    const std::vector<double>& t = ng->time;
    std::vector<double> q(a.size(), 0.0);  // ngspice's running charge
    for (size_t j = 1; j < a.size(); ++j)
      q[j] = q[j - 1] + 0.5 * (a[j] + a[j - 1]) * (t[j] - t[j - 1]);
    double mx = 0;  // the largest |charge| over 1 ns, from each sample to 1 ns later
    for (size_t j = 0, e = 0; j < a.size() && t[j] + 1e-9 <= t.back(); ++j) {
      while (e + 1 < a.size() && t[e + 1] < t[j] + 1e-9) ++e;
      const double qe = q[e] + (t[j] + 1e-9 - t[e]) / (t[e + 1] - t[e]) * (q[e + 1] - q[e]);
      mx = std::max(mx, std::abs(qe - q[j]) / 1e-9);
    }
    EXPECT_NEAR(c.peak_1ns_a, mx, 0.05 * mx) << id << " " << c.contact;
    EXPECT_NEAR(c.charge_c, q.back(), 0.05 * std::abs(q.back())) << id << " " << c.contact;
    std::printf("%s %s: inrush %.4g A over 1 ns (ngspice %.4g), charge %.4g C (ngspice %.4g)\n",
                id.c_str(), c.contact.c_str(), c.peak_1ns_a, mx, c.charge_c, q.back());
  }
  if (!s.traffic) return out;
  // The checker on ngspice's receiver waveform gives the scenario's verdict.
  StatusOr<eye::Rules> rules = eye::load_rules(s.rules);
  EXPECT_TRUE(rules.ok());
  if (!rules) return out;
  eye::CheckOptions co;
  co.expect = s.link.expected;
  StatusOr<eye::CheckResult> check = eye::check_samples(ng->time, ng->columns[k], *rules, co);
  EXPECT_TRUE(check.ok()) << check.status().message();
  EXPECT_TRUE(s.communicates.has_value());
  if (!check || !s.communicates) return out;
  EXPECT_EQ(check->pass, *s.communicates) << id;
  out.communicates = *s.communicates;
  std::printf("%s: communicates %d (the checker on ngspice's waveform: %d)\n", id.c_str(),
              *s.communicates, check->pass);
  return out;
}

}  // namespace isolink::testing
