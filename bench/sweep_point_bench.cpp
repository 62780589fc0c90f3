// Where a sweep point's time goes (issue 12), on the 12 m two-frame transformer link of
// bench/links/xfmr_12m_two_frames.yaml, one direction (the link is the same circuit both ways):
//   - BM_ExpandLink: the link spec to a netlist (cable model included);
//   - BM_EdgeResponse: the edge response (reduced model, sampled until settled);
//   - BM_WorstSearch: the worst-case search over all traffic from that edge response;
//   - BM_SweepPoint: what `isolink sweep` does per point with `outputs: [worst]` (the spec's
//     traffic from the edge responses, then the worst case).
// Run from the repository root: build/bench/sweep_point_bench
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "analysis/link_run.h"
#include "analysis/worst.h"
#include "eye/rules.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace {

using namespace isolink;

struct Fixture {
  link::LinkSpec spec;
  link::PartLibrary parts;
  analysis::WorstOptions wopt;
  eye::Rules rules;
  analysis::EdgeResponse edge;
};

[[noreturn]] void die(const Status& s) {
  std::fprintf(stderr, "sweep_point_bench: %s\n", s.message().c_str());
  std::exit(2);
}

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture x;
    StatusOr<link::LinkSpec> spec =
        link::read_link_spec_file("bench/links/xfmr_12m_two_frames.yaml");
    if (!spec) die(spec.status());
    spec->stimulus.directions = {link::Direction::kDown};
    x.spec = *spec;
    StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
    if (!parts) die(parts.status());
    x.parts = *parts;
    StatusOr<link::ExpandedLink> ex =
        link::expand_link(x.spec, x.parts, link::Direction::kDown, x.wopt.expand);
    if (!ex) die(ex.status());
    StatusOr<eye::Rules> rules = eye::load_rules(ex->rules);
    if (!rules) die(rules.status());
    x.rules = *rules;
    StatusOr<analysis::EdgeResponse> e =
        analysis::edge_response(x.spec, x.parts, link::Direction::kDown, x.wopt);
    if (!e) die(e.status());
    x.edge = *e;
    return x;
  }();
  return f;
}

void BM_ExpandLink(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    StatusOr<link::ExpandedLink> ex =
        link::expand_link(f.spec, f.parts, link::Direction::kDown, f.wopt.expand);
    if (!ex) die(ex.status());
    benchmark::DoNotOptimize(ex->netlist.cards.size());
  }
}
BENCHMARK(BM_ExpandLink)->Unit(benchmark::kMillisecond);

void BM_EdgeResponse(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    StatusOr<analysis::EdgeResponse> e =
        analysis::edge_response(f.spec, f.parts, link::Direction::kDown, f.wopt);
    if (!e) die(e.status());
    benchmark::DoNotOptimize(e->e.back());
  }
}
BENCHMARK(BM_EdgeResponse)->Unit(benchmark::kMillisecond);

void BM_WorstSearch(benchmark::State& state) {
  const Fixture& f = fixture();
  for (auto _ : state) {
    StatusOr<analysis::DirectionWorst> w = analysis::worst_case_direction(f.edge, f.rules, f.wopt);
    if (!w) die(w.status());
    state.counters["scored"] = static_cast<double>(w->scored);
  }
}
BENCHMARK(BM_WorstSearch)->Unit(benchmark::kMillisecond);

void BM_SweepPoint(benchmark::State& state) {
  const Fixture& f = fixture();
  link::LinkSpec spec = f.spec;
  spec.stimulus.directions = {link::Direction::kDown, link::Direction::kUp};
  for (auto _ : state) {
    std::vector<analysis::EdgeResponse> edges;
    StatusOr<analysis::LinkRun> run =
        analysis::run_link_from_edges(spec, f.parts, {}, f.wopt, &edges);
    if (!run) die(run.status());
    StatusOr<analysis::WorstResult> w = analysis::worst_case(spec, f.parts, f.wopt, edges);
    if (!w) die(w.status());
    benchmark::DoNotOptimize(w->pass);
  }
}
BENCHMARK(BM_SweepPoint)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  // The allocator setting of cli/main.cpp, so that the figures are the CLI's.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
