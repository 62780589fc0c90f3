// isolink's transient against ngspice on the same netlists (ngspice run with tight tolerances).
#include <filesystem>

#include <gtest/gtest.h>

#include "cli/simulate.h"
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
  cli::SimulationRequest req{.probes = c.probes, .method = method, .reltol = 1e-4};
  auto mine = cli::simulate_netlist(*netlist, req);
  ASSERT_TRUE(mine.ok()) << mine.status().message();
  const std::string work = ::testing::TempDir() + "/ngspice_compare";
  auto ng = testing::run_ngspice(c.netlist, c.probes, work,
                                 ".options reltol=1e-6 abstol=1e-12 vntol=1e-9 rshunt=1e12 method=" +
                                     std::string(method == IntegrationMethod::Gear2 ? "gear" : "trap"));
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
                         ::testing::Values(IntegrationMethod::Trapezoidal, IntegrationMethod::Gear2));

}  // namespace
}  // namespace isolink
