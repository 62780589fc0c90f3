// isolink's transient against ngspice on the same netlists (ngspice run with tight tolerances).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "analysis/simulate.h"
#include "ngspice_runner.h"

namespace isolink {
namespace {

const std::string kData = ISOLINK_TEST_DATA_DIR;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;

struct Case {
  std::string netlist;
  std::vector<std::string> probes;
  double tolerance;  // V (or A), absolute
};

void compare(const Case& c, IntegrationMethod method) {
  auto netlist = read_spice_file(c.netlist);
  ASSERT_TRUE(netlist.ok()) << netlist.status().message();
  analysis::SimulationRequest req{.probes = c.probes, .method = method, .reltol = 1e-4};
  auto mine = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(mine.ok()) << mine.status().message();
  const std::string work = ::testing::TempDir() + "/ngspice_compare";
  auto ng = testing::run_ngspice(
      c.netlist, c.probes, work,
      std::string(testing::kNgspiceTight) +
          " method=" + std::string(method == IntegrationMethod::Gear2 ? "gear" : "trap"));
  ASSERT_TRUE(ng.ok()) << ng.status().message();
  ASSERT_GT(ng->samples(), 100u);
  for (size_t k = 0; k < c.probes.size(); ++k) {
    double d = testing::max_abs_difference(mine->wave, k, *ng, k);
    EXPECT_LT(d, c.tolerance) << c.netlist << " " << c.probes[k];
    ::testing::Test::RecordProperty(c.probes[k], std::to_string(d));
  }
}

class NgspiceCompare : public ::testing::TestWithParam<IntegrationMethod> {};

TEST_P(NgspiceCompare, RlcLadder) {
  compare({kData + "/rlc_ladder.cir", {"v(b)", "v(d)", "i(l2)"}, 5e-3}, GetParam());
}
TEST_P(NgspiceCompare, CoupledTransformer) {
  compare({kData + "/transformer.cir", {"v(s1,s2)", "v(p1,n1)", "i(lsec)"}, 5e-3}, GetParam());
}
TEST_P(NgspiceCompare, CapacitorIsolatedLinkExample) {
  compare({kExamples + "/cap_link_2m.cir", {"v(rxp,rxn)", "v(txp,txn)"}, 5e-3}, GetParam());
}

INSTANTIATE_TEST_SUITE_P(TrapAndGear, NgspiceCompare,
                         ::testing::Values(IntegrationMethod::Trapezoidal,
                                           IntegrationMethod::Gear2));

// Every example link netlist, isolink with its DEFAULT options (what a user gets from
// `isolink sim`) against ngspice at tight tolerances: v(rxp,rxn) within 10 mV over the run.
// `tstop` (if > 0) shortens both runs, for the largest example only (ngspice-tight on its full
// 52 us takes ~8 s; its error is per edge, not accumulated: the first two frames show it).
void compare_example(const std::string& name, double tstop = 0) {
  const std::string path = kExamples + "/" + name + ".cir";
  const std::vector<std::string> probes = {"v(rxp,rxn)"};
  auto netlist = read_spice_file(path);
  ASSERT_TRUE(netlist.ok()) << netlist.status().message();
  analysis::SimulationRequest req{.probes = probes};
  std::string tran;
  if (tstop > 0) {
    req.tstop = tstop;
    char card[64];
    std::snprintf(card, sizeof card, ".tran %.9g %.9g", netlist->tran->tstep, tstop);
    tran = card;
  }
  auto mine = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(mine.ok()) << mine.status().message();
  const std::string work = ::testing::TempDir() + "/ngspice_examples";
  auto ng = testing::run_ngspice(path, probes, work, testing::kNgspiceTight, tran);
  ASSERT_TRUE(ng.ok()) << ng.status().message();
  ASSERT_GT(ng->samples(), 1000u);
  if (tstop > 0) {
    ASSERT_NEAR(ng->time.back(), tstop, 1e-12);
  }
  ASSERT_NEAR(mine->wave.time.back(), ng->time.back(), 1e-12);
  const double d = testing::max_abs_difference(mine->wave, 0, *ng, 0);
  EXPECT_LE(d, 10e-3) << name << ": max |isolink - ngspice tight| of v(rxp,rxn)";
  ::testing::Test::RecordProperty("max_dev_mV", std::to_string(d * 1e3));
  std::printf("%s: max |dev| %.2f mV over %zu reference points, %zu isolink steps\n", name.c_str(),
              d * 1e3, ng->samples(), mine->wave.samples());
}

TEST(NgspiceExamples, CapLink2m) {
  compare_example("cap_link_2m");
}
TEST(NgspiceExamples, CmcLink5m) {
  compare_example("cmc_link_5m");
}
TEST(NgspiceExamples, HybridXfmrCap3m) {
  compare_example("hybrid_xfmr_cap_3m");
}
TEST(NgspiceExamples, XfmrLink15mFirstTwoFrames) {
  compare_example("xfmr_link_15m", 20.7e-6);
}

}  // namespace
}  // namespace isolink
