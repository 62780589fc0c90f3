// run_link (analysis/link_run.h): a direction that is the same circuit and traffic as one run
// before (link::circuit_key, the same parts at both ends) is not simulated again; its result is
// what simulating it alone gives. Different ends are simulated each way.
#include "analysis/link_run.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "netlists/link/link_spec.h"

namespace isolink::analysis {
namespace {

link::LinkSpec spec_of(const std::string& rx_isolation, const std::string& direction) {
  StatusOr<link::LinkSpec> s = link::read_link_spec_text(
      "name: link-run-test\n"
      "tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}\n"
      "rx: {device: bq7961x, isolation: " +
          rx_isolation +
          "}\n"
          "cable: {length: 2, material: pp, gauge: 24}\n"
          "stimulus: {frames: [\"single-read dev=1 reg=0x0215 n=1\"], direction: " +
          direction + "}\n",
      "link-run-test.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return *s;
}

TEST(LinkRun, MirrorSymmetricDirectionIsSimulatedOnce) {
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  const std::string xfmr = "{type: transformer, part: HMU1228NL}";
  StatusOr<LinkRun> both = run_link(spec_of(xfmr, "both"), *parts);
  ASSERT_TRUE(both.ok()) << both.status().message();
  ASSERT_EQ(both->directions.size(), 2u);
  EXPECT_EQ(both->directions[0].same_as, "");
  EXPECT_EQ(both->directions[1].same_as, "down");
  EXPECT_EQ(both->directions[1].link.direction, link::Direction::kUp);
  EXPECT_EQ(both->directions[1].link.description.rfind("up:", 0), 0u);
  EXPECT_EQ(same_circuits(*both), (std::vector<int>{-1, 0}));
  StatusOr<LinkRun> up = run_link(spec_of(xfmr, "up"), *parts);
  ASSERT_TRUE(up.ok()) << up.status().message();
  ASSERT_TRUE(up->directions[0].data && both->directions[1].data);
  EXPECT_EQ(up->directions[0].sim.wave.columns[0], both->directions[1].sim.wave.columns[0]);
  EXPECT_EQ(*up->directions[0].data->vstart_min(), *both->directions[1].data->vstart_min());
  EXPECT_EQ(up->pass, both->directions[1].pass);

  // The sweep's path: one edge response per direction (the second the first's), the traffic
  // superposed from it, within 1 mV of the simulated run's VSTART.
  std::vector<EdgeResponse> edges;
  StatusOr<LinkRun> from_edges =
      run_link_from_edges(spec_of(xfmr, "both"), *parts, {}, WorstOptions{}, &edges);
  ASSERT_TRUE(from_edges.ok()) << from_edges.status().message();
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_EQ(edges[0].e, edges[1].e);
  ASSERT_EQ(from_edges->directions.size(), 2u);
  EXPECT_EQ(from_edges->directions[1].same_as, "down");
  for (size_t k = 0; k < 2; ++k) {
    ASSERT_TRUE(from_edges->directions[k].data);
    EXPECT_NE(from_edges->directions[k].sim.engine_note.find("synthesized"), std::string::npos);
    EXPECT_NEAR(*from_edges->directions[k].data->vstart_min(),
                *both->directions[k].data->vstart_min(), 1e-3);
    EXPECT_EQ(from_edges->directions[k].pass, both->directions[k].pass);
  }

  StatusOr<LinkRun> asym = run_link(spec_of("{type: cap}", "both"), *parts);
  ASSERT_TRUE(asym.ok()) << asym.status().message();
  ASSERT_EQ(asym->directions.size(), 2u);
  EXPECT_EQ(asym->directions[1].same_as, "");
  EXPECT_EQ(same_circuits(*asym), (std::vector<int>{-1, -1}));
  EXPECT_NE(asym->directions[0].sim.wave.columns[0], asym->directions[1].sim.wave.columns[0]);
}

}  // namespace
}  // namespace isolink::analysis
