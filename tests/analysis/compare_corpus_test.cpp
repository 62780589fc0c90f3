// isolink compare's fit is global (issue 43): a seeded corpus of synthetic captures, generated
// here, whose truths lie anywhere in the fit's bounds, not near the design.
// - Links: cap, cap + choke, transformer and hybrid (BQ79600 transformer to BQ7961x cap), both
//   directions; one to three keys at a time among cable lengths, isolation caps, terminations,
//   magnetising and leakage inductances (two isolation caps in series are never drawn together:
//   only their series value shows, CompareFit.TwoProportionalParametersAreNotIdentifiable covers
//   that report).
// - Truths: log-uniform over each key's bounds (the defaults: R and C 1/10..10x, L 1/10..2x; the
//   cable 0.3..30 m, given as --bounds), at least 25 % from the design.
// - Scope: 1.25-2.5 GS/s, 200-350 MHz, 5-15 mV per channel, 8 or 12 bits, trigger -5..+5 us, in
//   the Keysight, Rigol, PicoScope and Saleae layouts `check` reads (synthetic_capture.h).
// - Passing: at least 95 % of the captures recovered (every key within 10 % for caps and lengths,
//   20 % for inductances and terminations), and every miss explained: each key that misses is
//   reported at its bound, or as one of a pair too correlated to separate, or not identifiable
//   (the Jacobian's rank, or another point of the bounds that explains the capture within its
//   noise: FitKey::alternatives); never a confident wrong value.
// The whole corpus (60 captures, 40-80 min on the shared 2-core machine) is its own ctest entry,
// labelled slow (tests/analysis/CMakeLists.txt); a fixed subset of two runs in the default suite.
// Another seed set: ISOLINK_CORPUS_SEED_BASE=N runs seeds N..N+59 (the same links, keys and
// scope ranges; the figures in bench/README.md are for the default, 0).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "analysis/compare.h"
#include "analysis/compare_model.h"
#include "base/file_io.h"
#include "reports/compare_report.h"
#include "tests/analysis/synthetic_capture.h"

namespace isolink::analysis {
namespace {

struct CorpusLink {
  const char* name;
  const char* yaml;
  const char* kind;  // cap | capchoke | xfmr | hybrid
};

// Short links and a four-byte stimulus keep each transient capture to a few seconds.
const CorpusLink kLinks[] = {
    {"cap", R"(name: corpus-cap
tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
cable: {length: 2, material: pp, gauge: 24}
stimulus: {frames: ["raw 80 5A C3 nocrc"]}
)",
     "cap"},
    {"capchoke", R"(name: corpus-capchoke
tx: {device: bq7961x, isolation: {type: capchoke, cap: 2.2n, chokes: [ACT45B-510-2P-TL003]}}
rx: {device: bq7961x, isolation: {type: capchoke, cap: 2.2n, chokes: [ACT45B-510-2P-TL003]}}
cable: {length: 3, material: pp, gauge: 24}
stimulus: {frames: ["raw 80 5A C3 nocrc"]}
)",
     "capchoke"},
    {"xfmr", R"(name: corpus-xfmr
tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
rx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
cable: {length: 2, material: pp, gauge: 24}
stimulus: {frames: ["raw 80 5A C3 nocrc"]}
)",
     "xfmr"},
    {"hybrid", R"(name: corpus-hybrid
tx: {device: bq79600, series_r: 49, bypass_c: 100p, termination: 1k,
     isolation: {type: transformer, part: HMU1228NL}}
rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
cable: {length: 3, material: pp, gauge: 24}
stimulus: {frames: ["raw 80 5A C3 nocrc"]}
)",
     "hybrid"},
};

constexpr double kCableLow = 0.3, kCableHigh = 30;

// The keys a case may draw on a link, probed end `e` (rx down, tx up), far end `f`.
std::vector<std::string> keys_of(const std::string& kind, bool up) {
  const std::string e = up ? "tx" : "rx", f = up ? "rx" : "tx";
  if (kind == "cap" || kind == "capchoke")
    return {"cable.length", e + ".isolation.cap", f + ".isolation.cap", e + ".termination"};
  if (kind == "xfmr")
    return {"cable.length", e + ".isolation.inductance", e + ".isolation.leakage",
            e + ".termination"};
  return {"cable.length", "rx.isolation.cap", "tx.isolation.leakage", "tx.isolation.inductance",
          e + ".termination"};
}

double tolerance_of(const std::string& key) {
  const std::string last = key.substr(key.rfind('.') + 1);
  return last == "cap" || last == "length" ? 0.10 : 0.20;
}

struct Case {
  uint64_t seed = 0;
  const CorpusLink* link = nullptr;
  bool up = false;
  std::vector<std::string> keys;
  std::vector<double> truth;  // SI
  testing::ScopeModel scope;
};

const link::PartLibrary& parts() {
  static const link::PartLibrary lib = *link::PartLibrary::load({});
  return lib;
}

std::string tmp_dir() {
  const std::string d = (std::filesystem::temp_directory_path() /
                         fmt::format("isolink_compare_corpus_{}", ::getpid()))
                            .string();
  std::filesystem::create_directories(d);
  return d;
}

CompareOptions options_of(const Case& c) {
  CompareOptions opt;
  opt.direction = c.up ? link::Direction::kUp : link::Direction::kDown;
  opt.fit = c.keys;
  for (const std::string& k : c.keys)
    if (k == "cable.length") opt.bounds[k] = {kCableLow, kCableHigh};
  return opt;
}

// Case `seed`: its link, direction, keys, truths and scope, all from the seed.
Case make_case(uint64_t seed) {
  std::mt19937_64 rng(seed * 7919 + 17);
  auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  Case c;
  c.seed = seed;
  c.link = &kLinks[seed % 4];
  c.up = (seed / 4) % 2 == 1;
  std::vector<std::string> pool = keys_of(c.link->kind, c.up);
  const size_t nk = 1 + static_cast<size_t>(rng() % 3);
  std::shuffle(pool.begin(), pool.end(), rng);
  for (const std::string& k : pool) {
    if (c.keys.size() >= nk) break;
    const bool cap = k.find("isolation.cap") != std::string::npos;
    bool other_cap = false;
    for (const std::string& have : c.keys)
      other_cap = other_cap || (cap && have.find("isolation.cap") != std::string::npos);
    if (!other_cap) c.keys.push_back(k);
  }
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(c.link->yaml, "corpus.yaml");
  const CompareOptions opt = options_of(c);
  for (const std::string& k : c.keys) {
    const double design = design_value(*spec, parts(), k)->value;
    const auto [lo, hi] = *compare_detail::fit_bounds(opt, k, design);
    double x = design;
    while (std::abs(std::log(x / design)) < std::log(1.25))
      x = lo * std::exp(u(0, 1) * std::log(hi / lo));
    c.truth.push_back(x);
  }
  static const char* const kLayouts[] = {"keysight", "rigol", "picoscope", "saleae"};
  c.scope.sample_rate = u(1.25e9, 2.5e9);
  c.scope.bandwidth = u(200e6, 350e6);
  c.scope.noise_v = u(5e-3, 15e-3);
  c.scope.bits = rng() % 2 ? 12 : 8;
  c.scope.trigger = u(-5e-6, 5e-6);
  c.scope.seed = seed;
  c.scope.layout = kLayouts[(seed / 8) % 4];
  c.scope.up = c.up;
  return c;
}

eye::CsvColumns columns_of(const testing::ScopeModel& s) {
  if (s.layout == "rigol") return {.p = "CH1", .n = "CH2"};
  if (s.layout == "picoscope") return {.p = "Channel A", .n = "Channel B"};
  if (s.layout == "saleae") return {.p = "Channel 0", .n = "Channel 1"};
  return {};
}

enum class Outcome { kRecovered, kExplainedMiss, kUnexplainedMiss };

struct CaseResult {
  Outcome outcome = Outcome::kUnexplainedMiss;
  std::string line;  // for the log
};

// A key that misses is explained when the fit says it is at its bound, not identifiable (rank
// deficient, or with alternatives: other values explain the capture as well), or one of a pair
// too correlated to separate.
bool miss_explained(const CompareResult& r, const FitKey& k) {
  if (!k.at_bound.empty() || !k.identifiable || !k.alternatives.empty()) return true;
  if (k.multiple_correlation > KeyCorrelation::kInseparable) return true;
  for (const KeyCorrelation& c : r.correlations)
    if ((c.a == k.key || c.b == k.key) && !c.separable()) return true;
  return false;
}

CaseResult run_case(uint64_t seed) {
  const Case c = make_case(seed);
  const auto start = std::chrono::steady_clock::now();
  std::vector<sweep::Assignment> truth;
  for (size_t j = 0; j < c.keys.size(); ++j)
    truth.push_back({c.keys[j], fmt::format("{:.6g}", c.truth[j]), true});
  const std::string dir = tmp_dir();
  const std::string spec = dir + fmt::format("/corpus_{}.yaml", seed);
  const std::string cap = dir + fmt::format("/corpus_{}.csv", seed);
  EXPECT_TRUE(write_file_atomic(spec, c.link->yaml).ok());
  Status s = testing::write_synthetic_capture(c.link->yaml, spec, truth, c.scope, cap);
  EXPECT_TRUE(s.ok()) << s.message();
  CompareInput in{.files = {cap}, .cols = columns_of(c.scope), .spec_path = spec};
  StatusOr<CompareResult> r = compare_capture(in, parts(), options_of(c));
  EXPECT_TRUE(r.ok()) << r.status().message();
  CaseResult out;
  std::string line = fmt::format("seed {:2} {:8} {:4} {:9}", seed, c.link->name,
                                 c.up ? "up" : "down", c.scope.layout);
  if (!r.ok() || r->fit.size() != c.keys.size())
    return {Outcome::kUnexplainedMiss, line + " error"};
  bool all = true, explained = true;
  for (size_t j = 0; j < c.keys.size(); ++j) {
    const FitKey& k = r->fit[j];
    const bool ok = std::abs(k.value / c.truth[j] - 1) <= tolerance_of(k.key);
    all = all && ok;
    if (!ok) explained = explained && miss_explained(*r, k);
    line += fmt::format(" | {} {:.4g} fit {:.4g}{}{}{}", k.key, c.truth[j], k.value,
                        k.at_bound.empty() ? "" : " at-bound",
                        k.alternatives.empty()
                            ? (k.identifiable ? "" : " unidentifiable")
                            : fmt::format(" or {:.4g}", fmt::join(k.alternatives, "/")),
                        ok ? "" : " MISS");
  }
  out.outcome = all         ? Outcome::kRecovered
                : explained ? Outcome::kExplainedMiss
                            : Outcome::kUnexplainedMiss;
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  line += fmt::format(" | {} {:.1f} s (compare {:.1f} s, {} simulations, {})",
                      out.outcome == Outcome::kRecovered       ? "recovered"
                      : out.outcome == Outcome::kExplainedMiss ? "explained miss"
                                                               : "UNEXPLAINED MISS",
                      secs, r->seconds, r->evaluations, r->search.scanned ? "scanned" : "local");
  out.line = line;
  if (out.outcome == Outcome::kUnexplainedMiss) out.line += "\n" + reports::compare_text(*r);
  return out;
}

// The corpus: at least 95 % recovered, no miss unexplained.
void run_corpus(const std::vector<uint64_t>& seeds, double min_rate) {
  size_t recovered = 0, unexplained = 0;
  for (uint64_t seed : seeds) {
    const CaseResult cr = run_case(seed);
    std::printf("%s\n", cr.line.c_str());
    std::fflush(stdout);
    recovered += cr.outcome == Outcome::kRecovered;
    unexplained += cr.outcome == Outcome::kUnexplainedMiss;
    EXPECT_NE(cr.outcome, Outcome::kUnexplainedMiss) << cr.line;
  }
  const double rate = static_cast<double>(recovered) / static_cast<double>(seeds.size());
  std::printf("corpus: %zu of %zu recovered (%.1f %%), %zu unexplained misses\n", recovered,
              seeds.size(), rate * 100, unexplained);
  EXPECT_GE(rate, min_rate);
  EXPECT_EQ(unexplained, 0u);
}

// Issue 43's bar. bench/README.md has the figures and each miss with its report.
TEST(CompareCorpus, SixtySeededCapturesAreRecoveredOrHonestlyMissed) {
  const char* base_env = std::getenv("ISOLINK_CORPUS_SEED_BASE");
  const uint64_t base = base_env ? std::stoull(base_env) : 0;
  std::vector<uint64_t> seeds;
  for (uint64_t s = base; s < base + 60; ++s) seeds.push_back(s);
  run_corpus(seeds, 0.95);
}

// The fixed subset of the default suite: one far-from-design key on a cap link (up) and on a
// transformer link (down), two scope layouts.
TEST(CompareCorpus, FixedSubsetIsRecovered) {
  run_corpus({4, 18}, 1.0);
}

}  // namespace
}  // namespace isolink::analysis
