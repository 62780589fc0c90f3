// run_link (analysis/link_run.h): a direction that is the same circuit and traffic as one run
// before (link::circuit_key, the same parts at both ends) is not simulated again; its result is
// what simulating it alone gives. Different ends are simulated each way.
#include "analysis/link_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// RunOptions::record_tol: past record_full_rows the record keeps only the engine's rows that
// linear interpolation needs; every engine row (a run keeping them all) is then within the
// tolerance of the kept rows' interpolation, on every probe, and the run says so.
TEST(LinkRun, ALongRecordIsThinnedWithinItsStatedTolerance) {
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(
      "name: thinned\ncable: {length: 2}\nstimulus: {direction: down, frames: [\"stack-write "
      "reg=0x0100 data=02B778BC\", \"stack-write reg=0x0100 data=02B778BC\"]}\n",
      "thinned.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  RunOptions all;
  all.record_tol = 0;
  RunOptions thin;
  thin.record_tol = 1e-3;
  thin.record_full_rows = 10'000;
  thin.threads = 2;
  StatusOr<LinkRun> a = run_link(*spec, *parts, all);
  StatusOr<LinkRun> b = run_link(*spec, *parts, thin);
  ASSERT_TRUE(a.ok() && b.ok());
  const SimulationResult& full = a->directions[0].sim;
  const SimulationResult& kept = b->directions[0].sim;
  ASSERT_EQ(full.engine, Engine::Lti);
  EXPECT_EQ(full.record_tol, 0.0);
  EXPECT_EQ(kept.record_tol, 1e-3);
  EXPECT_EQ(full.grid.rows, kept.grid.rows);  // the same engine rows, made either way
  EXPECT_EQ(full.wave.time.size(), static_cast<size_t>(full.grid.rows));
  EXPECT_LT(kept.wave.time.size(), full.wave.time.size() * 6 / 10);
  EXPECT_GT(kept.wave.time.size(), 10'000u);
  bool noted = false;
  for (const std::string& w : kept.warnings)
    noted = noted || w.rfind("note: the record keeps", 0) == 0;
  EXPECT_TRUE(noted);
  // Every engine row against the kept rows' linear interpolation.
  ASSERT_EQ(kept.wave.time.front(), full.wave.time.front());
  ASSERT_EQ(kept.wave.time.back(), full.wave.time.back());
  double worst = 0;
  size_t k = 0;
  for (size_t i = 0; i < full.wave.time.size(); ++i) {
    const double t = full.wave.time[i];
    while (k + 2 < kept.wave.time.size() && kept.wave.time[k + 1] <= t) ++k;
    const double t0 = kept.wave.time[k], t1 = kept.wave.time[k + 1];
    const double f = (t - t0) / (t1 - t0);
    for (size_t c = 0; c < full.wave.columns.size(); ++c) {
      const double lin = (1 - f) * kept.wave.columns[c][k] + f * kept.wave.columns[c][k + 1];
      worst = std::max(worst, std::fabs(lin - full.wave.columns[c][i]));
    }
  }
  EXPECT_LE(worst, 1e-3 * (1 + 1e-9));
  EXPECT_GT(worst, 0.5e-3);  // thinned as far as the tolerance allows, not further
  // The checks read the kept rows: the same verdict and bytes, the voltages within the
  // tolerance plus what a moved sampling instant adds.
  const eye::CheckResult& x = *a->directions[0].data;
  const eye::CheckResult& y = *b->directions[0].data;
  EXPECT_EQ(x.pass, y.pass);
  EXPECT_EQ(x.bytes, y.bytes);
  EXPECT_NEAR(*x.vstart_min(), *y.vstart_min(), 2e-3);
  EXPECT_NEAR(*x.vend_min(), *y.vend_min(), 2e-3);
}

}  // namespace
}  // namespace isolink::analysis
