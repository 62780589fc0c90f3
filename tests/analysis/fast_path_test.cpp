// The sweep's fast path (run_link_from_edges, analysis/link_run.h) against run_link, point by
// point, on a fixed subset of the seeded random link corpus (tools/link_corpus.py --seed 1):
// asymmetric and symmetric links, every isolation type, 1 k and 10 k terminations, X and Y caps,
// PP and PVC, 0.1-100 m, both directions, each with two frames (a stack write and a broadcast
// read of 12 bytes). The guarantee in analysis/README.md: the same verdicts and the same margins
// within 1 mV and 25 ps, the pins within 1 mV (the noise analysis reads them), and every point
// on the fast path (none silently simulated).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "analysis/worst.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {
namespace {

namespace fs = std::filesystem;

constexpr double kVolts = 1e-3;      // margins and pins (V)
constexpr double kSeconds = 25e-12;  // widths and edges (s)

// Specs first..first+count-1 of the corpus with seed 1, in a fresh folder.
std::vector<fs::path> corpus(int first, int count) {
  const fs::path dir =
      fs::temp_directory_path() /
      ("isolink_fast_path_" + std::to_string(::getpid()) + "_" + std::to_string(first));
  fs::remove_all(dir);
  const std::string cmd = "python3 " ISOLINK_SOURCE_DIR "/tools/link_corpus.py --seed 1 --first " +
                          std::to_string(first) + " --count " + std::to_string(count) + " --out " +
                          dir.string();
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::vector<fs::path> out;
  for (int i = first; i < first + count; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "link_%03d.yaml", i);
    out.push_back(dir / name);
  }
  return out;
}

double max_abs(const Waveform& w, size_t col) {
  double m = 0;
  for (double v : w.columns.at(col)) m = std::max(m, std::abs(v));
  return m;
}

// a and b within tol, or both absent (both paths measure the same pulses).
void expect_close(const std::optional<double>& a, const std::optional<double>& b, double tol,
                  const std::string& what) {
  ASSERT_EQ(a.has_value(), b.has_value()) << what;
  if (a) {
    EXPECT_NEAR(*a, *b, tol) << what;
  }
}

void compare_one(const fs::path& path, const link::PartLibrary& parts) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(path.string());
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  spec->stimulus.frames = {"stack-write reg=0x0100 data=02B778BC",
                           "broadcast-read reg=0x0200 n=12"};
  WorstOptions wopt;
  wopt.more_probes.assign(run_probes().begin() + 1, run_probes().end());
  std::vector<EdgeResponse> edges;
  StatusOr<LinkRun> fast = run_link_from_edges(*spec, parts, {}, wopt, &edges);
  ASSERT_TRUE(fast.ok()) << path << ": " << fast.status().message();
  RunOptions ro;
  ro.engine = Engine::Lti;
  StatusOr<LinkRun> sim = run_link(*spec, parts, ro);
  ASSERT_TRUE(sim.ok()) << path << ": " << sim.status().message();
  EXPECT_EQ(simulated_note(*fast), "") << path;
  EXPECT_EQ(edges.size(), fast->directions.size()) << path;
  ASSERT_EQ(fast->directions.size(), sim->directions.size());
  for (size_t d = 0; d < fast->directions.size(); ++d) {
    const DirectionRun& a = fast->directions[d];
    const DirectionRun& b = sim->directions[d];
    const std::string what = path.filename().string() + " " + a.link.description + " " +
                             engine_name(b.sim.engine) + " " + b.sim.engine_note;
    ASSERT_EQ(a.sim.wave.columns.size(), b.sim.wave.columns.size()) << what;
    EXPECT_NEAR(max_abs(a.sim.wave, 1), max_abs(b.sim.wave, 1), kVolts) << what << " v(rxp)";
    EXPECT_NEAR(max_abs(a.sim.wave, 2), max_abs(b.sim.wave, 2), kVolts) << what << " v(rxn)";
    ASSERT_TRUE(a.data && b.data) << what;
    const eye::CheckResult& x = *a.data;
    const eye::CheckResult& y = *b.data;
    expect_close(x.vstart_min(), y.vstart_min(), kVolts, what + " vstart");
    expect_close(x.vend_min(), y.vend_min(), kVolts, what + " vend");
    expect_close(x.width_min(), y.width_min(), kSeconds, what + " width_min");
    expect_close(x.width_max(), y.width_max(), kSeconds, what + " width_max");
    expect_close(x.edge_max(), y.edge_max(), kSeconds, what + " edge");
    // The same worst margins per metric (the sweep's margin columns), and the same verdict unless
    // a margin lies within the tolerance of its limit (then either verdict is within it).
    bool near_limit = false;
    ASSERT_EQ(x.worst.size(), y.worst.size()) << what;
    for (size_t m = 0; m < x.worst.size(); ++m) {
      ASSERT_EQ(x.worst[m].metric, y.worst[m].metric) << what;
      ASSERT_EQ(x.worst[m].j.judged(), y.worst[m].j.judged()) << what << " " << x.worst[m].metric;
      if (!x.worst[m].j.judged()) continue;
      const std::string& metric = x.worst[m].metric;
      const double tol = metric == "width" || metric == "edge" ? kSeconds : kVolts;
      EXPECT_NEAR(x.worst[m].j.margin, y.worst[m].j.margin, tol)
          << what << " " << x.worst[m].metric;
      near_limit = near_limit || std::abs(y.worst[m].j.margin) <= tol;
    }
    if (!near_limit) {
      EXPECT_EQ(x.pass, y.pass) << what;
      EXPECT_EQ(a.pass, b.pass) << what;
      EXPECT_EQ(x.bytes, y.bytes) << what;
    }
  }
}

void compare_corpus(int first, int count) {
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  for (const fs::path& p : corpus(first, count)) {
    SCOPED_TRACE(p.string());
    compare_one(p, *parts);
  }
}

// Three links (an asymmetric bridge-to-stack transformer pair, a transformer to a 31 m cap +
// choke hop, a cap + choke to transformer link): the non-slow suite.
TEST(FastPath, MatchesTheSimulatedRunOnThreeCorpusLinks) {
  compare_corpus(2, 3);
}

// Sixteen more, the 100 m and 0.1 m links among them (slow label: 318 s under load 14 on the
// shared 2-core machine).
TEST(FastPath, MatchesTheSimulatedRunOnSixteenCorpusLinks) {
  compare_corpus(0, 2);
  compare_corpus(5, 14);
}

}  // namespace
}  // namespace isolink::analysis
