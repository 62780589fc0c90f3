// The edge response (analysis/edge_response.h):
// - the sweep's path (synthesize_drive of a link's own drive, scored) against the LTI engine's
//   simulated run of the same link; off the grid, synthesis is refused;
// - the reduced model's closed-form tail is the sampled record, and superposition with it is the
//   exact sum of a made-up response, also past the record;
// - the reduced model's edge response against the transient's.
// The worst-case search that stands on it is tests/analysis/worst_test.cpp.
#include "analysis/edge_response.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "eye/check.h"
#include "netlists/link/link_spec.h"

namespace isolink::analysis {
namespace {

// A 2 m transformer hop (worst_test.cpp's): short cable (a fast edge response) and a long
// memory (the transformer's magnetizing current).
const char* kLink = R"(name: worst-test
tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
rx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
cable: {length: 2, material: pp, gauge: 24}
stimulus: {frames: ["stack-write reg=0x0100 data=02B778BC"], direction: down}
)";

struct Fixture {
  link::LinkSpec spec;
  link::PartLibrary parts;
  EdgeResponse edge;
  EdgeResponseOptions opt;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    StatusOr<link::LinkSpec> spec = link::read_link_spec_text(kLink, "worst-test.yaml");
    EXPECT_TRUE(spec.ok()) << spec.status().message();
    x.spec = *spec;
    StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
    EXPECT_TRUE(parts.ok()) << parts.status().message();
    x.parts = std::move(*parts);
    StatusOr<EdgeResponse> e = edge_response(x.spec, x.parts, link::Direction::kDown, x.opt);
    EXPECT_TRUE(e.ok()) << e.status().message();
    x.edge = std::move(*e);
    return x;
  }();
  return f;
}

// The sweep's path for the spec traffic (run_direction_synthesized): v(rxp,rxn) superposed from
// the edge response on its 1 ns grid, scored like the simulated run. Against the LTI engine's own
// run of the same link (its 1 mV output grid): the same verdict and bytes, every metric within
// 1 mV and 25 ps (the 1 ns samples can miss a peak by a fraction of a mV).
TEST(EdgeResponse, SynthesizedRunMatchesTheSimulatedRun) {
  const Fixture& f = fixture();
  link::LinkSpec spec = f.spec;
  spec.stimulus.frames = {"stack-write reg=0x0100 data=02B778BC", "broadcast-read reg=0x0200 n=2"};
  StatusOr<link::ExpandedLink> ex =
      link::expand_link(spec, f.parts, link::Direction::kDown, f.opt.expand);
  ASSERT_TRUE(ex.ok()) << ex.status().message();
  ASSERT_TRUE(on_grid(ex->drive, f.edge.dt));
  StatusOr<DirectionRun> syn = run_direction_synthesized(*ex, f.edge);
  ASSERT_TRUE(syn.ok()) << syn.status().message();
  RunOptions ro;
  ro.engine = Engine::Lti;
  StatusOr<DirectionRun> sim = run_direction(*ex, ro);
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  ASSERT_TRUE(syn->data && sim->data);
  const eye::CheckResult& a = *syn->data;
  const eye::CheckResult& b = *sim->data;
  EXPECT_EQ(a.pass, b.pass);
  EXPECT_EQ(a.pulses.size(), b.pulses.size());
  EXPECT_TRUE(a.expect_match);
  EXPECT_EQ(a.frames.size(), b.frames.size());
  EXPECT_NEAR(*a.vstart_min(), *b.vstart_min(), 1e-3);
  EXPECT_NEAR(*a.vend_min(), *b.vend_min(), 1e-3);
  EXPECT_NEAR(*a.width_min(), *b.width_min(), 25e-12);
  EXPECT_NEAR(*a.width_max(), *b.width_max(), 25e-12);
  EXPECT_NEAR(*a.edge_max(), *b.edge_max(), 25e-12);
  EXPECT_NEAR(syn->sim.wave.time.back(), sim->sim.wave.time.back(), 1e-9);
  // Off the grid, synthesis is refused rather than snapped.
  traffic::Drive shifted = ex->drive;
  for (traffic::DriveSegment& g : shifted.segments) g.start += 0.3e-9, g.end += 0.3e-9;
  shifted.segments.front().start = 0;
  EXPECT_FALSE(on_grid(shifted, f.edge.dt));
  EXPECT_NE(synthesize_drive(f.edge, shifted, 1e-4).status().message().find("off the 1 ns grid"),
            std::string::npos);
}

// The reduced model's edge response carries its closed form past the driver's ramp
// (EdgeResponse::tail), and that closed form is the record: every 997th sample from its start
// to the record's end, within 1 nV.
TEST(EdgeResponse, TailIsTheSampledRecord) {
  const Fixture& f = fixture();
  ASSERT_TRUE(f.edge.tail.has_value()) << f.edge.engine;
  const EdgeResponse::Tail& t = *f.edge.tail;
  EXPECT_GE(t.start, 0);
  EXPECT_LE(static_cast<double>(t.start) * f.edge.dt, 10e-9);  // the ramp's second half: 5 ns
  const long n = static_cast<long>(f.edge.e.size()) - f.edge.pre;
  double worst = 0;
  for (long q = 0; t.start + q < n; q += 997) {
    double v = t.constant[0];
    for (size_t i = 0; i < t.z.size(); ++i)
      v += (t.amplitude[0][i] * std::pow(t.z[i], static_cast<double>(q))).real();
    worst = std::max(worst, std::abs(v - f.edge.e[static_cast<size_t>(f.edge.pre + t.start + q)]));
  }
  EXPECT_LT(worst, 1e-9);
}

// Superposition with a closed-form tail (synthesize_drive on an EdgeResponse with `tail`): a
// made-up response of a 30 MHz ring (40 ns), a 20 us lag and a 2 ms lag, recorded for 40 us, and
// 240 edges of +-2 over 60 us on a 100 us record. Against the exact sum of the closed form, edge
// by edge: within synthesize_drive's 20 uV everywhere, also past the response's record, where the
// record alone (no tail: its last sample held) is off by the 2 ms lag's drift.
TEST(EdgeResponse, SynthesisWithTheClosedFormTailIsTheExactSum) {
  const double dt = 0.25e-9;
  EdgeResponse e;
  e.dt = dt;
  e.pre = 200;
  e.v_idle = 0.3;
  EdgeResponse::Tail t;
  t.start = 20;
  const std::vector<std::complex<double>> poles = {
      {-1 / 40e-9, 2 * std::numbers::pi * 30e6}, {-1 / 20e-6, 0}, {-1 / 2e-3, 0}};
  t.amplitude = {{{0.3, -0.2}, {-0.25, 0}, {0.05, 0}}};
  t.constant = {0.9};
  for (const auto& p : poles) t.z.push_back(std::exp(p * dt));
  auto exact = [&](long n) {  // samples after the corner
    if (n < t.start) {        // the ramp: a line from 0 at -20 to the tail's start
      if (n <= -20) return 0.0;
      double at_start = t.constant[0];
      for (const auto& a : t.amplitude[0]) at_start += a.real();
      return at_start * static_cast<double>(n + 20) / static_cast<double>(t.start + 20);
    }
    double v = t.constant[0];
    for (size_t i = 0; i < poles.size(); ++i)
      v +=
          (t.amplitude[0][i] * std::exp(poles[i] * (static_cast<double>(n - t.start) * dt))).real();
    return v;
  };
  const long record = static_cast<long>(40e-6 / dt);
  for (long i = 0; i < e.pre + record; ++i) e.e.push_back(exact(i - e.pre));
  traffic::Drive drive;
  std::mt19937 rng(28);
  std::uniform_int_distribution<int> gap(240 / 4, 400 / 4);  // 60-100 ns, on the 1 ns grid
  double at = 1e-6;
  int level = 0;
  drive.segments.push_back({0.0, at, 0});
  std::vector<std::pair<long, int>> edges;
  for (int j = 0; j < 240; ++j) {
    const int next = level == 1 ? -1 : 1;
    const double end = at + gap(rng) * 4 * dt;
    drive.segments.push_back({at, end, next});
    edges.push_back({std::lround(at / dt), next - level});
    level = next, at = end;
  }
  drive.segments.back().end = 100e-6;
  auto worst_against_exact = [&](const EdgeResponse& r, long from, long to) {
    StatusOr<Waveform> w = synthesize_drive(r, drive, 100e-6);
    EXPECT_TRUE(w.ok()) << w.status().message();
    if (!w) return 1.0;
    double worst = 0;
    for (long i = from; i < to; i += 101) {
      double v = e.v_idle;
      for (const auto& [edge, dl] : edges) v += dl * exact(i - edge);
      worst = std::max(worst, std::abs(w->columns[0][static_cast<size_t>(i)] - v));
    }
    return worst;
  };
  const long within = static_cast<long>(40.9e-6 / dt);  // every lag inside the record
  const long end = static_cast<long>(100e-6 / dt);
  e.tail = t;
  EXPECT_LT(worst_against_exact(e, 0, end), 20e-6);
  EdgeResponse record_only = e;
  record_only.tail.reset();
  EXPECT_LT(worst_against_exact(record_only, 0, within), 20e-6);
  EXPECT_GT(worst_against_exact(record_only, within, end), 100e-6);
}

// The edge response from the reduced model (the default) against the transient at reltol 1e-6:
// the same record within 0.2 mV (the worst-case search adds up at most a few dozen edges, and
// the examples' worst values agree within 0.11 mV and 1 ps, bench/README.md).
TEST(EdgeResponse, ReducedModelMatchesTheTransient) {
  const Fixture& f = fixture();
  EXPECT_NE(f.edge.engine.find("reduced model"), std::string::npos) << f.edge.engine_note;
  EdgeResponseOptions o = f.opt;
  o.edge_engine = EdgeResponseOptions::EdgeEngine::Transient;
  StatusOr<EdgeResponse> t = edge_response(f.spec, f.parts, link::Direction::kDown, o);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_NE(t->engine.find("transient"), std::string::npos);
  EXPECT_NEAR(f.edge.v_idle, t->v_idle, 1e-6);
  double dev = 0, peak = 0;
  const long n = static_cast<long>(std::min(f.edge.e.size(), t->e.size())) - f.edge.pre;
  for (long i = -f.edge.pre; i < n; ++i) {
    dev = std::max(dev, std::abs(f.edge.at(i) - t->at(i)));
    peak = std::max(peak, std::abs(t->at(i)));
  }
  EXPECT_GT(peak, 1.0);  // a real edge (V)
  EXPECT_LT(dev, 0.2e-3);
}

}  // namespace
}  // namespace isolink::analysis
