// The worst case over all legal traffic (analysis/worst.h):
// - superposition of the edge response reproduces the transient engine's waveform of real traffic
//   (so the driver's edges are amplitude-independent and P/N complementary, as the method needs);
// - the search equals an independent brute force over a reduced set of bytes and gaps;
// - random legal traffic (>= 200 byte frames, random commands and gaps) never beats it;
// - each metric's `reproduce` object from worst_json, pasted as JSON into a spec's `stimulus:`,
//   read and run through the transient engine (`isolink run`'s path), shows the worst value
//   within 10 mV (1 ns for times).
#include "analysis/worst.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "base/hex.h"
#include "eye/check.h"
#include "netlists/link/link_spec.h"
#include "netlists/traffic/command.h"
#include "netlists/traffic/encoding.h"
#include "reports/worst_report.h"

namespace isolink::analysis {
namespace {

// A 2 m transformer hop: short cable (a fast edge response), and a memory (the transformer's
// magnetizing current) long enough that the previous byte matters at the 3.8 us gap.
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
  eye::Rules rules;
  WorstOptions opt;
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
    StatusOr<eye::Rules> r = eye::load_rules("bq7961x");
    EXPECT_TRUE(r.ok());
    x.rules = *r;
    return x;
  }();
  return f;
}

// Per metric, the "key" the search minimises, computed here from the checker's pulses.
struct Keys {
  double vstart = 1e9, vend = 1e9, width_lo = 1e9, width_hi = 1e9, edge = -1e9;
  bool pass = true;
};

Keys keys_of(const eye::CheckResult& c, const eye::Rules& r) {
  Keys k;
  k.pass = c.pass;
  if (c.vstart_min()) k.vstart = *c.vstart_min();
  if (c.vend_min()) k.vend = *c.vend_min();
  if (c.edge_max()) k.edge = *c.edge_max();
  for (const eye::PulseMetrics& p : c.pulses) {
    if (p.truncated || p.idle || !p.width.measured()) continue;
    const eye::WidthWindow* w = r.window(std::clamp(p.k, 1, 2));
    if (w == nullptr) {
      ADD_FAILURE() << "no width window for class " << p.k;
      continue;
    }
    k.width_lo = std::min(k.width_lo, p.width.value - w->min);
    k.width_hi = std::min(k.width_hi, w->max - p.width.value);
  }
  return k;
}

Keys keys_of_traffic(const Traffic& t, double from, double to) {
  const Fixture& f = fixture();
  Waveform w = synthesize(f.edge, t, f.opt.expand.stimulus.encoding, from, to);
  StatusOr<eye::CheckResult> c = eye::check_waveform(w, f.rules);
  EXPECT_TRUE(c.ok());
  return keys_of(*c, f.rules);
}

std::string traffic_text_for_test(const Traffic& t) {
  std::string s;
  for (size_t i = 0; i < t.frames.size(); ++i)
    s += fmt::format("{:.0f}ns {:02X}{} ", t.gaps[i] * 1e9, t.frames[i].byte,
                     t.frames[i].error_bit ? "e" : "");
  return s;
}

TEST(WorstCase, EdgeResponseSettlesAndSuperposesLikeTheTransient) {
  const Fixture& f = fixture();
  EXPECT_LE(f.edge.drift, f.opt.settle_tol);
  EXPECT_NEAR(f.edge.v_idle, 0.0, 1e-6);  // symmetric pins at idle
  // A stack-write (9 byte frames) with uneven gaps, synthesized and simulated.
  const std::vector<uint8_t> bytes =
      *traffic::command_bytes("stack-write reg=0x0100 data=02B778BC");
  Traffic t;
  link::LinkSpec spec = f.spec;
  spec.stimulus.frames.clear();
  for (size_t i = 0; i < bytes.size(); ++i) {
    t.frames.push_back({bytes[i], i == 3 ? 1 : 0});
    t.gaps.push_back(i == 0 ? 1e-6 : 3.8e-6 + 50e-9 * static_cast<double>(i));
    spec.stimulus.frames.push_back(std::string("raw ") + to_hex(std::vector<uint8_t>{bytes[i]}) +
                                   " nocrc" + (i == 3 ? " err" : ""));
  }
  spec.stimulus.gaps = t.gaps;
  spec.sim.reltol = 1e-6;
  StatusOr<LinkRun> run = run_link(spec, f.parts);
  ASSERT_TRUE(run.ok()) << run.status().message();
  const Waveform& sim = run->directions[0].sim.wave;
  const Waveform syn = synthesize(f.edge, t, f.opt.expand.stimulus.encoding, 0, sim.time.back());
  // Compared on the synthesis grid (1 ns): between its samples a 10 ns edge is only linearly
  // interpolated (up to ~4 mV on the steepest ringing), the transient's own steps are finer.
  double worst = 0;
  for (size_t i = 0; i < syn.time.size(); ++i)
    worst = std::max(worst, std::abs(syn.columns[0][i] - sim.value_at(0, syn.time[i])));
  EXPECT_LT(worst, 2e-3) << "superposition vs transient, max |dv| = " << worst * 1e3 << " mV";
}

TEST(WorstCase, TailBoundCoversTheResponse) {
  const Fixture& f = fixture();
  const double T = 250e-9;
  // B(0) bounds one half bit's own response, B is the sum over a decreasing envelope.
  double peak = 0;
  for (long n = 0; n < static_cast<long>(f.edge.e.size()); ++n)
    peak = std::max(peak, std::abs(f.edge.at(n) - f.edge.at(n - 250)));
  EXPECT_GE(tail_bound(f.edge, T, 0), peak);
  EXPECT_GE(tail_bound(f.edge, T, 1e-6), tail_bound(f.edge, T, 5e-6));
  EXPECT_NEAR(tail_bound(f.edge, T, f.edge.span + 1e-6), 0.0, 1e-12);
}

// A reduced set: 16 target patterns, 8 previous ones, gaps every 250 ns: the search (first-order
// ranking, `verify` exact scores) and the exhaustive mode equal a brute force written here.
TEST(WorstCase, SearchEqualsBruteForceOnAReducedSet) {
  const Fixture& f = fixture();
  WorstOptions opt = f.opt;
  opt.gap_step = 250e-9;
  for (int p : {0x00, 0xFF, 0xAA, 0x55, 0x0F, 0xF0, 0x33, 0xCC})
    opt.targets.push_back(p), opt.targets.push_back(p | 0x100);
  opt.previous = {0x00, 0xFF, 0x155, 0xAA, 0x1F0, 0x0F, 0x133, 0xCC};
  StatusOr<DirectionWorst> fast = worst_case_direction(f.edge, f.rules, opt);
  ASSERT_TRUE(fast.ok()) << fast.status().message();
  ASSERT_GT(fast->previous_bound, opt.tail_tol) << "the test link must have a memory past 3.8 us";
  opt.exhaustive = true;
  StatusOr<DirectionWorst> full = worst_case_direction(f.edge, f.rules, opt);
  ASSERT_TRUE(full.ok());

  // Brute force: every target after idle and after every previous byte at every gap.
  const double D = 6.5e-6, pre = 300e-9, post = 1.5e-6;
  Keys bf;
  auto fold = [&](const Keys& k) {
    bf.vstart = std::min(bf.vstart, k.vstart);
    bf.vend = std::min(bf.vend, k.vend);
    bf.width_lo = std::min(bf.width_lo, k.width_lo);
    bf.width_hi = std::min(bf.width_hi, k.width_hi);
    bf.edge = std::max(bf.edge, k.edge);
  };
  long combos = 0;
  std::vector<double> gaps;
  for (double g = 3.8e-6; g <= fast->gap_max + 1e-9; g += 250e-9) gaps.push_back(g);
  for (int t : opt.targets) {
    const ByteFrame tf{static_cast<uint8_t>(t & 0xFF), t >> 8};
    fold(keys_of_traffic({{tf}, {1e-6}}, 1e-6 - pre, 1e-6 + D + post));
    for (int q : opt.previous)
      for (double g : gaps) {
        const ByteFrame qf{static_cast<uint8_t>(q & 0xFF), q >> 8};
        const double start = 1e-6 + D + g;
        fold(keys_of_traffic({{qf, tf}, {1e-6, g}}, start - pre, start + D + post));
        ++combos;
      }
  }
  EXPECT_GT(combos, 1000);
  for (const DirectionWorst* d : {&*fast, &*full}) {
    EXPECT_NEAR(d->metric("vstart")->value, bf.vstart, 1e-9);
    EXPECT_NEAR(d->metric("vend")->value, bf.vend, 1e-9);
    EXPECT_NEAR(d->metric("width_min")->margin, bf.width_lo, 1e-15);
    EXPECT_NEAR(d->metric("width_max")->margin, bf.width_hi, 1e-15);
    EXPECT_NEAR(d->metric("edge")->value, bf.edge, 1e-15);
  }
  EXPECT_LT(fast->scored, full->scored / 4) << "the search should score far fewer waveforms";
}

// With every previous pattern allowed, the ranking enumerates each model's best patterns from
// its per-bit coefficients instead of trying all 512 (worst.cpp): the same histories must come
// out as when each pattern is tried in turn (the same 512 listed out of order take that path).
TEST(WorstCase, RankingByBitsEqualsRankingEachPattern) {
  const Fixture& f = fixture();
  WorstOptions opt = f.opt;
  opt.targets = {0x00, 0x1FF, 0xA5, 0x15A, 0x0F, 0x3C};
  StatusOr<DirectionWorst> by_bits = worst_case_direction(f.edge, f.rules, opt);
  ASSERT_TRUE(by_bits.ok()) << by_bits.status().message();
  for (int p = 511; p >= 0; --p) opt.previous.push_back(p);
  StatusOr<DirectionWorst> each = worst_case_direction(f.edge, f.rules, opt);
  ASSERT_TRUE(each.ok()) << each.status().message();
  EXPECT_EQ(by_bits->scored, each->scored);
  EXPECT_GT(by_bits->scored, static_cast<long>(opt.targets.size()))
      << "histories must have been scored, not only the targets after idle";
  ASSERT_EQ(by_bits->metrics.size(), each->metrics.size());
  for (size_t m = 0; m < each->metrics.size(); ++m) {
    const WorstMetric& a = by_bits->metrics[m];
    const WorstMetric& b = each->metrics[m];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.value, b.value);
    EXPECT_EQ(traffic_text_for_test(a.traffic), traffic_text_for_test(b.traffic));
  }
}

const DirectionWorst& full_worst() {
  static const DirectionWorst w = [] {
    StatusOr<DirectionWorst> d =
        worst_case_direction(fixture().edge, fixture().rules, fixture().opt);
    EXPECT_TRUE(d.ok()) << d.status().message();
    return *d;
  }();
  return w;
}

TEST(WorstCase, RandomLegalTrafficNeverBeatsIt) {
  const Fixture& f = fixture();
  const DirectionWorst& w = full_worst();
  ASSERT_EQ(w.metrics.size(), 5u);
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<int> byte(0, 255), kind(0, 3), len(1, 8), coin(0, 9);
  std::uniform_int_distribution<int> byte_gap(0, 60), frame_gap(0, 400);  // 50 ns steps
  Traffic t;
  size_t frames = 0;
  while (frames < 240) {
    std::string text;
    std::string data;
    for (int i = len(rng); i > 0; --i) data += fmt::format("{:02X}", byte(rng));
    switch (kind(rng)) {
      case 0:
        text = fmt::format("single-read dev={} reg={} n={}", byte(rng) % 64, byte(rng), len(rng));
        break;
      case 1:
        text = fmt::format("stack-write reg={} data={}", byte(rng) * 256 + byte(rng), data);
        break;
      case 2:
        text = fmt::format("broadcast-write reg={} data={}", byte(rng), data);
        break;
      default:
        text = fmt::format("raw {} nocrc", data);
        break;
    }
    StatusOr<std::vector<uint8_t>> b = traffic::command_bytes(text);
    ASSERT_TRUE(b.ok()) << text << ": " << b.status().message();
    for (size_t i = 0; i < b->size(); ++i) {
      t.frames.push_back({(*b)[i], coin(rng) == 0 ? 1 : 0});  // 1 in 10 resent (error bit)
      const double g = i == 0 ? (t.gaps.empty() ? 1e-6 : 3.8e-6 + 50e-9 * frame_gap(rng))
                              : 3.8e-6 + 50e-9 * byte_gap(rng);
      t.gaps.push_back(g);
      ++frames;
    }
  }
  const double end = t.frame_start(t.frames.size() - 1, 6.5e-6) + 6.5e-6 + 5e-6;
  const Waveform wave = synthesize(f.edge, t, f.opt.expand.stimulus.encoding, 0, end);
  StatusOr<eye::CheckResult> c = eye::check_waveform(wave, f.rules);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->frames.size(), frames);
  const Keys k = keys_of(*c, f.rules);
  const double tol = 1e-9;
  EXPECT_GE(k.vstart, w.metric("vstart")->value - w.metric("vstart")->bound - tol);
  EXPECT_GE(k.vend, w.metric("vend")->value - w.metric("vend")->bound - tol);
  EXPECT_GE(k.width_lo, w.metric("width_min")->margin - w.metric("width_min")->bound - 1e-12);
  EXPECT_GE(k.width_hi, w.metric("width_max")->margin - w.metric("width_max")->bound - 1e-12);
  EXPECT_LE(k.edge, w.metric("edge")->value + w.metric("edge")->bound + 1e-12);
  if (w.pass) {
    EXPECT_TRUE(k.pass) << "the worst case passes, so must any traffic";
  }
}

// The path a user takes: worst_json's `reproduce` object, written as JSON (a YAML flow map) into
// the spec's `stimulus:` key, read by the link-spec reader and run (`isolink run`'s run_link).
TEST(WorstCase, ReproduceBlocksShowTheWorstValueInTheTransient) {
  const Fixture& f = fixture();
  const DirectionWorst& w = full_worst();
  WorstResult all;
  all.directions = {w};
  const nlohmann::ordered_json j = reports::worst_json(all);
  const std::string base(kLink);
  const std::string head = base.substr(0, base.find("stimulus:"));
  for (const WorstMetric& m : w.metrics) {
    const nlohmann::ordered_json& rep = j["directions"][0]["worst"][m.name]["reproduce"];
    std::vector<std::string> keys;
    for (const auto& [key, value] : rep.items()) keys.push_back(key);
    EXPECT_EQ(keys, (std::vector<std::string>{"frames", "gaps", "direction"}));
    const std::string text = head + "stimulus: " + rep.dump() + "\nsim: {reltol: 1e-5}\n";
    SCOPED_TRACE(m.name + ": " + text);
    StatusOr<link::LinkSpec> spec = link::read_link_spec_text(text, "reproduce.yaml");
    ASSERT_TRUE(spec.ok()) << spec.status().message();
    // The reader's stimulus is the searched traffic: same frames, gaps within 1 fs.
    const link::StimulusSpec want = reproduce_spec(m, link::Direction::kDown);
    EXPECT_EQ(spec->stimulus.frames, want.frames);
    ASSERT_EQ(spec->stimulus.gaps.size(), m.traffic.gaps.size());
    for (size_t i = 0; i < m.traffic.gaps.size(); ++i)
      EXPECT_NEAR(spec->stimulus.gaps[i], m.traffic.gaps[i], 1e-15);
    EXPECT_EQ(spec->stimulus.directions, std::vector<link::Direction>{link::Direction::kDown});
    StatusOr<LinkRun> run = run_link(*spec, f.parts);
    ASSERT_TRUE(run.ok()) << run.status().message();
    ASSERT_EQ(run->directions.size(), 1u);
    ASSERT_TRUE(run->directions[0].data.has_value());
    const Keys k = keys_of(*run->directions[0].data, f.rules);
    if (m.name == "vstart") {
      EXPECT_NEAR(k.vstart, m.value, 10e-3);
    }
    if (m.name == "vend") {
      EXPECT_NEAR(k.vend, m.value, 10e-3);
    }
    if (m.name == "width_min") {
      EXPECT_NEAR(k.width_lo, m.margin, 1e-9);
    }
    if (m.name == "width_max") {
      EXPECT_NEAR(k.width_hi, m.margin, 1e-9);
    }
    if (m.name == "edge") {
      EXPECT_NEAR(k.edge, m.value, 1e-9);
    }
  }
}

// The same parts at both ends make the same circuit both ways: worst_case computes it once and
// says so (same_as); different ends are computed each way, and their results differ.
TEST(WorstCase, MirrorSymmetricLinkIsComputedOnce) {
  const Fixture& f = fixture();
  link::LinkSpec spec = f.spec;
  spec.stimulus.directions = {link::Direction::kDown, link::Direction::kUp};
  WorstOptions opt = f.opt;
  opt.targets = {0x00, 0x1FF, 0xA5};
  StatusOr<WorstResult> sym = worst_case(spec, f.parts, opt);
  ASSERT_TRUE(sym.ok()) << sym.status().message();
  ASSERT_EQ(sym->directions.size(), 2u);
  EXPECT_EQ(sym->directions[0].same_as, "");
  EXPECT_EQ(sym->directions[1].same_as, "down");
  EXPECT_EQ(sym->directions[1].direction, link::Direction::kUp);
  EXPECT_EQ(sym->directions[1].description.rfind("up:", 0), 0u);
  // The match given by the caller (a run's same_circuits) instead of found here: the same result;
  // told that the directions differ, each is computed; a match with a later direction is refused.
  StatusOr<WorstResult> told = worst_case(spec, f.parts, opt, {}, {-1, 0});
  ASSERT_TRUE(told.ok()) << told.status().message();
  EXPECT_EQ(told->directions[1].same_as, "down");
  StatusOr<WorstResult> apart = worst_case(spec, f.parts, opt, {}, {-1, -1});
  ASSERT_TRUE(apart.ok()) << apart.status().message();
  EXPECT_EQ(apart->directions[1].same_as, "");
  EXPECT_GT(apart->directions[1].scored, 0);
  for (size_t m = 0; m < sym->directions[1].metrics.size(); ++m) {
    EXPECT_EQ(told->directions[1].metrics[m].value, sym->directions[1].metrics[m].value);
    EXPECT_EQ(apart->directions[1].metrics[m].value, sym->directions[1].metrics[m].value);
  }
  StatusOr<WorstResult> ahead = worst_case(spec, f.parts, opt, {}, {1, -1});
  ASSERT_FALSE(ahead.ok());
  EXPECT_NE(ahead.status().message().find("matched with a later one"), std::string::npos);
  // The copy is what the up direction computes on its own.
  spec.stimulus.directions = {link::Direction::kUp};
  StatusOr<WorstResult> up = worst_case(spec, f.parts, opt);
  ASSERT_TRUE(up.ok()) << up.status().message();
  ASSERT_EQ(up->directions[0].metrics.size(), sym->directions[1].metrics.size());
  for (size_t m = 0; m < up->directions[0].metrics.size(); ++m)
    EXPECT_EQ(up->directions[0].metrics[m].value, sym->directions[1].metrics[m].value);

  // A capacitor-isolated receiving end: not the same circuit up and down.
  StatusOr<link::LinkSpec> asym = link::read_link_spec_text(
      R"(name: worst-asym
tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
rx: {device: bq7961x, isolation: {type: cap}}
cable: {length: 2, material: pp, gauge: 24}
stimulus: {frames: ["single-read dev=1 reg=0x0215 n=1"], direction: both}
)",
      "asym.yaml");
  ASSERT_TRUE(asym.ok()) << asym.status().message();
  StatusOr<WorstResult> both = worst_case(*asym, f.parts, opt);
  ASSERT_TRUE(both.ok()) << both.status().message();
  ASSERT_EQ(both->directions.size(), 2u);
  EXPECT_EQ(both->directions[1].same_as, "");
  EXPECT_NE(both->directions[0].edge.e, both->directions[1].edge.e);
}

TEST(WorstCase, OptionsAreValidatedUpFront) {
  WorstOptions o;
  o.gap_step = 0;
  EXPECT_NE(o.validate().message().find("gap_step"), std::string::npos);
  o = {};
  o.gap_min = 3.8005e-6;
  EXPECT_NE(o.validate().message().find("whole number of dt"), std::string::npos);
  o = {};
  o.targets = {512};
  EXPECT_NE(o.validate().message().find("0-511"), std::string::npos);
}

}  // namespace
}  // namespace isolink::analysis
