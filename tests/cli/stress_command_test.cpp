// isolink stress: an exported scenario of each kind replayed in ngspice (the pins' peaks and the
// diodes' currents within 5 % or 0.2 V, issue 42; with traffic, the checker's verdict on ngspice's
// waveform against the scenario's `communicates`), and the command's input errors (a bad stress:
// key at file:line:col, a bad --only or --direction) with exit 2 before any run.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "netlists/link/link_spec.h"
#include "run_isolink.h"
#include "stress_ngspice.h"

namespace isolink {
namespace {

namespace fs = std::filesystem;
const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;

// The scenario replayed in ngspice, its peaks and verdict held to it (stress_ngspice.h).
void compare_with_ngspice(const std::string& spec_path, const std::string& id) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(spec_path);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  (void)testing::stress_vs_ngspice(*spec, id);
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
