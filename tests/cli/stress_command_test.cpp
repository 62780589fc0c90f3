// isolink stress: an exported scenario of each kind replayed in ngspice (the pins' peaks and the
// diodes' currents within 5 % or 0.2 V, issue 42; with traffic, the checker's verdict on ngspice's
// waveform against the scenario's `communicates`), and the command's input errors (a bad stress:
// key at file:line:col, a bad --only or --direction) with exit 2 before any run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/stress.h"
#include "eye/check.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/spice_writer.h"
#include "ngspice_runner.h"
#include "run_isolink.h"

namespace isolink {
namespace {

namespace fs = std::filesystem;
const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;

// Runs scenario `id` of the spec, exports it, replays it in ngspice (reltol 1e-4, its other
// options at their defaults: tighter ones abort on clamp circuits, issue 41) and holds every
// pin's max and min and every diode's peak current to it within 5 % or 0.2 V (0.05 A).
void compare_with_ngspice(const std::string& spec_path, const std::string& id) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(spec_path);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  analysis::StressOptions opt;
  for (const std::string& k : link::stress_kinds())
    if (id.starts_with(k)) opt.only = {k};
  StatusOr<std::vector<analysis::StressScenario>> sc =
      analysis::build_stress_scenarios(*spec, *parts, opt);
  ASSERT_TRUE(sc.ok()) << sc.status().message();
  auto it = std::find_if(sc->begin(), sc->end(),
                         [&](const analysis::StressScenario& s) { return s.id == id; });
  ASSERT_NE(it, sc->end()) << id;
  analysis::StressScenario& s = *it;
  ASSERT_TRUE(analysis::run_stress_scenario(s, *spec, *parts).ok());
  const std::string work = isolink::testing::test_dir();
  const std::string path = work + "/" + id + ".cir";
  { std::ofstream(path) << write_spice(s.link.netlist); }
  std::vector<std::string> probes;
  for (const auto& [node, ground] : s.pin_ground)
    probes.push_back(ground == "0" ? "v(" + node + ")" : "v(" + node + "," + ground + ")");
  for (const analysis::DiodePeak& d : s.diodes) probes.push_back("i(" + d.ammeter + ")");
  if (s.traffic) probes.push_back("v(" + s.receiver_p + "," + s.receiver_n + ")");
  StatusOr<Waveform> ng = testing::run_ngspice(path, probes, work, ".options reltol=1e-4");
  ASSERT_TRUE(ng.ok()) << ng.status().message();
  size_t k = 0;
  for (const auto& [node, peak] : s.peak_pin_v) {
    const std::vector<double>& v = ng->columns[k++];
    const double mx = *std::max_element(v.begin(), v.end());
    const double mn = *std::min_element(v.begin(), v.end());
    EXPECT_NEAR(peak.max, mx, std::max(0.2, 0.05 * std::abs(mx))) << id << " " << node;
    EXPECT_NEAR(peak.min, mn, std::max(0.2, 0.05 * std::abs(mn))) << id << " " << node;
    std::printf("%s %s: max %.4f V (ngspice %.4f), min %.4f V (ngspice %.4f)\n", id.c_str(),
                node.c_str(), peak.max, mx, peak.min, mn);
  }
  for (const analysis::DiodePeak& d : s.diodes) {
    const std::vector<double>& a = ng->columns[k++];
    double mx = 0;
    for (double x : a) mx = std::max(mx, std::abs(x));
    EXPECT_NEAR(d.peak_a, mx, std::max(0.05, 0.05 * mx)) << id << " " << d.diode;
    std::printf("%s %s: peak %.4g A (ngspice %.4g)\n", id.c_str(), d.diode.c_str(), d.peak_a, mx);
  }
  if (!s.traffic) return;
  // The checker on ngspice's receiver waveform gives the scenario's verdict.
  StatusOr<eye::Rules> rules = eye::load_rules(s.rules);
  ASSERT_TRUE(rules.ok());
  eye::CheckOptions co;
  co.expect = s.link.expected;
  StatusOr<eye::CheckResult> check = eye::check_samples(ng->time, ng->columns[k], *rules, co);
  ASSERT_TRUE(check.ok()) << check.status().message();
  ASSERT_TRUE(s.communicates.has_value());
  EXPECT_EQ(check->pass, *s.communicates) << id;
  std::printf("%s: communicates %d (the checker on ngspice's waveform: %d)\n", id.c_str(),
              *s.communicates, check->pass);
}

TEST(StressVsNgspice, EsdIntoTheTvsLink) {
  compare_with_ngspice(kExamples + "/bq79606a_tvs_2m.yaml", "esd_rx_p_pos");
}

TEST(StressVsNgspice, GroundStepDuringTraffic) {
  compare_with_ngspice(kExamples + "/bq79606a_tvs_2m.yaml", "cm_step_tx");
}

TEST(StressVsNgspice, HotPlugPFirst) {
  compare_with_ngspice(kExamples + "/bq79606a_tvs_2m.yaml", "hot_plug_rx_p_first");
}

TEST(StressVsNgspice, InverterSquareDuringTraffic) {
  compare_with_ngspice(kExamples + "/bq79606a_tvs_2m.yaml", "cm_wave_tx");
}

TEST(StressVsNgspice, WireShortToChassisDuringTraffic) {
  compare_with_ngspice(kExamples + "/bq79606a_tvs_2m.yaml", "wire_p_to_chassis_down");
}

TEST(StressCommand, BadInputExitsTwoBeforeAnyRun) {
  const std::string dir = isolink::testing::test_dir();
  const std::string spec = dir + "/bad.yaml";
  std::ofstream(spec) << "name: bad\nstress:\n  esd: 8kV\n  ground_stepp: 60\n";
  auto r = isolink::testing::run_isolink(kBinary, "stress " + spec + " -o " + dir + "/out", "bad");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml:4:3: error"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ground_stepp"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  r = isolink::testing::run_isolink(
      kBinary, "stress " + kExamples + "/cap_2m.yaml --only esd,wires -o " + dir + "/out2", "only");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--only = 'esd,wires': 'wires' is not a scenario kind"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out2"));
  r = isolink::testing::run_isolink(
      kBinary, "stress " + kExamples + "/cap_2m.yaml --direction sideways -o " + dir + "/out3",
      "direction");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--direction = 'sideways': must be down, up or both"), std::string::npos)
      << r.err;
  r = isolink::testing::run_isolink(
      kBinary, "stress " + kExamples + "/cap_2m.yaml -j -1 -o " + dir + "/out4", "jobs");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("-j = -1: must be >= 0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out3"));
  EXPECT_FALSE(fs::exists(dir + "/out4"));
}

}  // namespace
}  // namespace isolink
