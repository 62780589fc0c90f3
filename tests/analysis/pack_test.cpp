// The pack: ring break cases for N = 2, 3, 16 (hand-listed), command timing against hand-worked
// figures for N = 1, 2, 8, identical hops simulated once (counted through the runner hooks, the
// worst case's too), a hop's worst case against worst_case() of its spec alone, a two-hop pack
// against two single-hop runs, and the 16-device example through the binary.
#include "analysis/pack.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "netlists/traffic/sequences.h"
#include "reports/pack_report.h"
#include "reports/run_report.h"
#include "reports/worst_report.h"

namespace isolink::analysis {
namespace {

namespace fs = std::filesystem;
using V = std::vector<int>;

std::string carried(const BreakCase& c) {
  std::string s;
  for (const BreakCase::Use& u : c.carried)
    s += fmt::format("{}{}{}", s.empty() ? "" : " ", u.hop, u.reversed ? "r" : "");
  return s;
}

TEST(RingBreaks, TwoDevices) {
  const std::vector<BreakCase> b = ring_breaks(2, true);
  ASSERT_EQ(b.size(), 4u);  // none, hop 1, hop 2, the return hop 3
  EXPECT_EQ(b[0].broken, 0);
  EXPECT_EQ(b[0].normal_side, (V{1, 2}));
  EXPECT_EQ(carried(b[0]), "1 2");
  EXPECT_EQ(b[1].normal_side, V{});
  EXPECT_EQ(b[1].reverse_side, (V{2, 1}));
  EXPECT_EQ(carried(b[1]), "3 2r");
  EXPECT_EQ(b[2].normal_side, V{1});
  EXPECT_EQ(b[2].reverse_side, V{2});
  EXPECT_EQ(carried(b[2]), "1 3");
  EXPECT_EQ(b[3].broken, 3);
  EXPECT_EQ(b[3].normal_side, (V{1, 2}));
  EXPECT_EQ(b[3].reverse_side, V{});
  EXPECT_EQ(carried(b[3]), "1 2");
  for (const BreakCase& c : b) EXPECT_TRUE(c.unreached.empty());
}

TEST(RingBreaks, ThreeDevices) {
  const std::vector<BreakCase> b = ring_breaks(3, true);
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(carried(b[1]), "4 3r 2r");
  EXPECT_EQ(b[1].reverse_side, (V{3, 2, 1}));
  EXPECT_EQ(carried(b[2]), "1 4 3r");
  EXPECT_EQ(b[2].normal_side, V{1});
  EXPECT_EQ(b[2].reverse_side, (V{3, 2}));
  EXPECT_EQ(carried(b[3]), "1 2 4");
  EXPECT_EQ(b[3].normal_side, (V{1, 2}));
  EXPECT_EQ(b[3].reverse_side, V{3});
  EXPECT_EQ(carried(b[4]), "1 2 3");
  // Without the ring a break cuts off the devices above it.
  const std::vector<BreakCase> open = ring_breaks(3, false);
  ASSERT_EQ(open.size(), 4u);
  EXPECT_EQ(open[2].normal_side, V{1});
  EXPECT_EQ(open[2].unreached, (V{2, 3}));
  EXPECT_EQ(carried(open[2]), "1");
  EXPECT_EQ(open[1].unreached, (V{1, 2, 3}));
  EXPECT_EQ(carried(open[1]), "");
}

TEST(RingBreaks, SixteenDevices) {
  const std::vector<BreakCase> b = ring_breaks(16, true);
  ASSERT_EQ(b.size(), 18u);
  EXPECT_EQ(carried(b[9]), "1 2 3 4 5 6 7 8 17 16r 15r 14r 13r 12r 11r 10r");
  EXPECT_EQ(b[9].reverse_side, (V{16, 15, 14, 13, 12, 11, 10, 9}));
  EXPECT_EQ(carried(b[16]), "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 17");
  EXPECT_EQ(b[16].reverse_side, V{16});
  for (size_t k = 0; k < b.size(); ++k) {
    const BreakCase& c = b[k];
    EXPECT_EQ(c.broken, static_cast<int>(k));
    // Every device is reached exactly once, and never through the broken hop.
    std::vector<int> seen(17, 0);
    for (int d : c.normal_side) ++seen[d];
    for (int d : c.reverse_side) ++seen[d];
    for (int d = 1; d <= 16; ++d) EXPECT_EQ(seen[d], 1) << "break " << k << " device " << d;
    for (const BreakCase::Use& u : c.carried) EXPECT_NE(u.hop, c.broken);
    // n hops carry traffic after any break (n + 1 hops minus the broken one, or n without one).
    EXPECT_EQ(c.carried.size(), 16u);
  }
}

// Inline specs with explicit per-metre l and c: velocity 1 / sqrt(500n * 50p) = 2e8 m/s, so a
// metre of cable delays 5 ns.
std::string hop_text(double length) {
  return fmt::format("  - spec: {{cable: {{length: {}, l: 500n, c: 50p}}}}\n", length);
}

StatusOr<PackSpec> timing_pack(const std::vector<double>& lengths, const std::string& frames,
                               double ring_length = 0, const std::string& timing = "") {
  std::string text = "stimulus: {frames: [" + frames + "]}\nhops:\n";
  for (double l : lengths) text += hop_text(l);
  if (ring_length > 0)
    text += fmt::format(
        "ring: true\nring_return: {{spec: {{cable: {{length: {}, l: 500n, c: "
        "50p}}}}}}\n",
        ring_length);
  text += timing;
  return read_pack_spec_text(text, ::testing::TempDir() + "/timing_pack.yaml");
}

TEST(PackTiming, OneDevice) {
  StatusOr<PackSpec> p = timing_pack({2.0}, "\"single-read dev=1 reg=0x0215 n=2\"");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok()) << t.status().message();
  ASSERT_EQ(t->cable_delay.size(), 1u);
  EXPECT_NEAR(t->cable_delay[0], 10e-9, 1e-15);
  ASSERT_EQ(t->commands.size(), 1u);
  const CommandTiming& c = t->commands[0];
  // 12 us bridge byte delay + 10 ns of cable.
  EXPECT_NEAR(c.arrival[0], 12.010e-6, 1e-12);
  // Response of 2 + 6 bytes: first byte at the bridge 12.010 + 6.5 (a chain byte) + 0.010 us,
  // then 8 UART bytes of 10.3 us: 18.52 + 82.4 = 100.92 us.
  EXPECT_TRUE(c.read);
  EXPECT_EQ(c.responders, V{1});
  EXPECT_NEAR(c.response_done, 100.92e-6, 1e-12);
  EXPECT_FALSE(c.late);  // no timeout set
}

TEST(PackTiming, TwoDevicesAndATimeout) {
  StatusOr<PackSpec> p =
      timing_pack({0.3, 2.0}, "\"single-read dev=2 reg=0x0215 n=2\", \"stack-read reg=0x0215 n=4\"",
                  0, "timing: {timeout: 200u}\n");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok()) << t.status().message();
  ASSERT_EQ(t->commands.size(), 2u);
  // Device 1: 12 us + 1.5 ns; device 2: 12 + 3 us + 11.5 ns.
  for (const CommandTiming& c : t->commands) {
    EXPECT_NEAR(c.arrival[0], 12.0015e-6, 1e-12);
    EXPECT_NEAR(c.arrival[1], 15.0115e-6, 1e-12);
  }
  // Device 2's response: 15.0115 + 6.5 + 3 + 0.0115 = 24.523 us at the bridge, + 8 x 10.3 us.
  EXPECT_NEAR(t->commands[0].response_done, 106.923e-6, 1e-12);
  EXPECT_FALSE(t->commands[0].late);
  // Stack read, 4 + 6 bytes each: device 1's first byte at 12.0015 + 6.5 + 0.0015 = 18.503 us,
  // its 103 us burst ends at 121.503 us; device 2's (at the bridge at 24.523 us) follows:
  // 224.503 us, past the 200 us timeout.
  EXPECT_EQ(t->commands[1].responders, (V{1, 2}));
  EXPECT_NEAR(t->commands[1].response_done, 224.503e-6, 1e-12);
  EXPECT_TRUE(t->commands[1].late);
}

TEST(PackTiming, EightDevicesBothWaysRoundTheRing) {
  std::vector<double> lengths;
  for (int k = 1; k <= 8; ++k) lengths.push_back(0.5 * k);  // hop k: 2.5 ns x k
  StatusOr<PackSpec> p = timing_pack(
      lengths, "\"stack-write reg=0x0100 data=02\", \"single-read dev=3 reg=0x0215 n=1\"", 4.0);
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok()) << t.status().message();
  ASSERT_EQ(t->cable_delay.size(), 9u);
  EXPECT_NEAR(t->cable_delay[8], 20e-9, 1e-15);  // the 4 m return hop
  ASSERT_EQ(t->commands.size(), 4u);             // two commands, each way round
  const CommandTiming& w = t->commands[0];
  EXPECT_FALSE(w.reversed);
  EXPECT_FALSE(w.read);
  // Device 8: 12 + 7 x 3 us + 2.5 ns x (1 + ... + 8) = 33.09 us.
  EXPECT_NEAR(w.arrival[7], 33.09e-6, 1e-12);
  // Device 3: 12 + 6 us + 2.5 x 6 ns = 18.015 us.
  EXPECT_NEAR(w.arrival[2], 18.015e-6, 1e-12);
  // Single read of device 3, 1 + 6 bytes: 18.015 + 6.5 + 6 + 0.015 = 30.53 us at the bridge,
  // + 7 x 10.3 us = 102.63 us.
  EXPECT_NEAR(t->commands[1].response_done, 102.63e-6, 1e-12);
  // Reversed: through the return hop (20 ns) to device 8 first, then down.
  const CommandTiming& rw = t->commands[2];
  EXPECT_TRUE(rw.reversed);
  EXPECT_NEAR(rw.arrival[7], 12.020e-6, 1e-12);
  // Device 1: 12 + 7 x 3 us + 20 ns + 2.5 ns x (2 + ... + 8) = 33.1075 us.
  EXPECT_NEAR(rw.arrival[0], 33.1075e-6, 1e-12);
  // Device 3 reversed: 12 + 5 x 3 us + 20 + 2.5 x (4 + ... + 8) ns = 27.095 us; its response
  // goes back the same way: 27.095 + 6.5 + 15 + 0.095 = 48.69 us, + 72.1 us = 120.79 us.
  EXPECT_NEAR(rw.arrival[2], 27.095e-6, 1e-12);
  EXPECT_NEAR(t->commands[3].response_done, 120.79e-6, 1e-12);
}

TEST(PackTiming, ReadOfAMissingDeviceIsFlagged) {
  StatusOr<PackSpec> p =
      timing_pack({1.0}, "\"single-read dev=5 reg=0x0215 n=1\"", 0, "timing: {timeout: 1m}\n");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok());
  EXPECT_TRUE(t->commands[0].late);
  EXPECT_TRUE(std::isnan(t->commands[0].response_done));
  EXPECT_NE(t->commands[0].note.find("device 5 is not in the stack"), std::string::npos);
}

// TI's start-up in a pack's stimulus (issue 45): `auto-address devices=2` is timed as the 21
// commands it stands for (8 + 1 + 2 + 1 + 1 + 8, netlists/traffic/sequences.h), the last eight
// stack reads answered by both devices; `responses` is what the devices send, not a command.
TEST(PackTiming, AutoAddressIsTimedAsItsCommands) {
  StatusOr<PackSpec> p =
      timing_pack({1.0, 1.0}, "\"auto-address devices=2\", \"responses reg=0x0343 n=1 devices=2\"");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok()) << t.status().message();
  StatusOr<std::vector<std::string>> cmds = traffic::auto_address_commands(2);
  ASSERT_TRUE(cmds.ok());
  ASSERT_EQ(cmds->size(), 21u);
  ASSERT_EQ(t->commands.size(), 21u);
  for (size_t k = 0; k < 21; ++k) EXPECT_EQ(t->commands[k].command, (*cmds)[k]);
  // Device 2 has each command after 12 us, one re-clock (3 us) and two 1 m hops (5 ns each).
  EXPECT_NEAR(t->commands[0].arrival[1], 15.010e-6, 1e-12);
  EXPECT_FALSE(t->commands[0].read);
  EXPECT_TRUE(t->commands[20].read);
  EXPECT_EQ(t->commands[20].responders, (V{1, 2}));
}

// Five hops: the bridge hop, then a module hop, the same module renamed, the same module with
// series_r written out at its preset value (49 ohm: the same circuit), and a longer cable.
TEST(PackDedupe, IdenticalCircuitsAreSimulatedOnce) {
  const std::string text =
      "hops:\n"
      "  - spec: {cable: {length: 0.5}}\n"
      "  - spec: {name: a, tx: {device: bq7961x}, cable: {length: 1}}\n"
      "  - spec: {name: b, cable: {length: 1}}\n"
      "  - spec: {name: c, tx: {series_r: 49}, rx: {series_r: 49}, cable: {length: 1}}\n"
      "  - spec: {name: d, cable: {length: 3}}\n";
  StatusOr<PackSpec> p = read_pack_spec_text(text, ::testing::TempDir() + "/dedupe.yaml");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  std::atomic<int> calls{0}, worst_calls{0};
  PackOptions opt;
  opt.runner = [&calls](link::ExpandedLink x, const RunOptions&) -> StatusOr<DirectionRun> {
    ++calls;
    DirectionRun d;
    d.link = std::move(x);
    d.pass = true;
    return d;
  };
  // The worst case is deduped as the runs are: one per distinct circuit.
  opt.worst = WorstOptions{};
  opt.worst_runner = [&worst_calls](const link::LinkSpec&, link::Direction d,
                                    const WorstOptions&) -> StatusOr<DirectionWorst> {
    ++worst_calls;
    DirectionWorst w;
    w.direction = d;
    w.metrics.push_back({.name = "vstart", .value = 2.5, .limit = 2.0, .margin = 0.5});
    return w;
  };
  // Progress: one call per finished job (4 simulations + 4 worst cases), counting up to 8.
  std::vector<std::pair<size_t, size_t>> progress;
  opt.on_job_done = [&progress](size_t done, size_t total) { progress.push_back({done, total}); };
  StatusOr<PackResult> r = run_pack(*p, *parts, opt);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(progress.size(), 8u);
  for (size_t k = 0; k < progress.size(); ++k)
    EXPECT_EQ(progress[k], (std::pair<size_t, size_t>{k + 1, 8}));
  // 5 hops x 2 directions expanded. The bridge hop's two directions differ (a bq79600 board at
  // one end); a module hop has the same devices and parts at both ends, so its up direction is
  // the same circuit as its down (node names follow the roles): 2 + 1 + 1 circuits.
  EXPECT_EQ(r->expansions, 10);
  EXPECT_EQ(r->simulations, 4);
  EXPECT_EQ(calls.load(), 4);
  // Shared results keep each hop's own direction.
  ASSERT_EQ(r->hops[2].run.directions.size(), 2u);
  EXPECT_EQ(r->hops[2].run.directions[0].link.direction, link::Direction::kDown);
  EXPECT_EQ(r->hops[2].run.directions[1].link.direction, link::Direction::kUp);
  EXPECT_EQ(r->hops[2].runs[0], r->hops[2].runs[1]);
  EXPECT_NE(r->hops[0].runs[0], r->hops[0].runs[1]);
  EXPECT_EQ(r->hops[0].same_as, 1);
  EXPECT_EQ(r->hops[1].same_as, 2);
  EXPECT_EQ(r->hops[2].same_as, 2);
  EXPECT_EQ(r->hops[3].same_as, 2);
  EXPECT_EQ(r->hops[4].same_as, 5);
  EXPECT_TRUE(r->pass);
  EXPECT_EQ(worst_calls.load(), 4);
  EXPECT_EQ(r->worst_cases, 4);
  EXPECT_TRUE(r->worst_done);
  EXPECT_TRUE(r->worst_pass);
  // Every hop direction has its worst case, in its own direction, margin 0.5 / 2.0.
  for (const HopResult& h : r->hops) {
    ASSERT_EQ(h.worst.size(), 2u);
    EXPECT_EQ(h.worst[0].direction, link::Direction::kDown);
    EXPECT_EQ(h.worst[1].direction, link::Direction::kUp);
    EXPECT_DOUBLE_EQ(h.worst_case_rel, 0.25);
    EXPECT_EQ(h.worst_case_metric, "vstart");
  }
}

// With the worst case, a break case also says which hops in use fail theirs: here hop 2 (the
// only 3 m cable) fails its worst case, so every case that uses it fails over all traffic, and
// only breaking hop 2 itself passes; the spec traffic passes everywhere.
TEST(PackWorst, BreakCasesJudgeTheHopsInUseOverAllTraffic) {
  const std::string text =
      "hops:\n"
      "  - spec: {cable: {length: 1}}\n"
      "  - spec: {cable: {length: 3}}\n"
      "  - spec: {cable: {length: 1}}\n"
      "ring: true\n"
      "ring_return: {spec: {cable: {length: 2}}}\n";
  StatusOr<PackSpec> p = read_pack_spec_text(text, ::testing::TempDir() + "/break_worst.yaml");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  PackOptions opt;
  opt.runner = [](link::ExpandedLink x, const RunOptions&) -> StatusOr<DirectionRun> {
    DirectionRun d;
    d.link = std::move(x);
    d.pass = true;
    return d;
  };
  opt.worst = WorstOptions{};
  opt.worst_runner = [](const link::LinkSpec& spec, link::Direction d,
                        const WorstOptions&) -> StatusOr<DirectionWorst> {
    DirectionWorst w;
    w.direction = d;
    w.pass = spec.cable.length != 3;
    w.metrics.push_back({.name = "vend", .value = 1.0, .limit = 1.2, .margin = -0.2});
    if (w.pass) w.metrics.back() = {.name = "vend", .value = 1.5, .limit = 1.2, .margin = 0.3};
    return w;
  };
  StatusOr<PackResult> r = run_pack(*p, *parts, opt);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->pass);
  EXPECT_FALSE(r->worst_pass);
  EXPECT_EQ(r->worst_weakest, 2);
  EXPECT_DOUBLE_EQ(r->hops[1].worst_case_rel, -0.2 / 1.2);
  EXPECT_DOUBLE_EQ(r->hops[0].worst_case_rel, 0.3 / 1.2);
  ASSERT_EQ(r->breaks.size(), 5u);  // none, hops 1-3, the return hop 4
  for (const BreakResult& b : r->breaks) {
    EXPECT_TRUE(b.pass) << b.c.broken;
    EXPECT_EQ(b.worst_pass, b.c.broken == 2) << b.c.broken;
  }
  // No break: hop 2 carries commands down (no reads: down only).
  EXPECT_EQ(r->breaks[0].worst_failing, std::vector<std::string>{"hop 2 normal (down)"});
  // Hop 1 broken: hops 4, 3r, 2r in use; hop 2 reversed carries commands up.
  EXPECT_EQ(r->breaks[1].worst_failing, std::vector<std::string>{"hop 2 reversed (up)"});
  const nlohmann::ordered_json j = reports::pack_report_json(*p, *r);
  EXPECT_EQ(j["worst_verdict"], "fail");
  EXPECT_EQ(j["verdict"], "pass");
  EXPECT_EQ(j["ring_breaks"][2]["worst_verdict"], "pass");
  EXPECT_EQ(j["ring_breaks"][3]["worst_verdict"], "fail");
}

// A pack hop's worst case is worst_case() of that hop's link spec alone, bit for bit; hops 2 and
// 3 (the same module) share one. A reduced search (16 targets, 4 previous bytes) keeps it short:
// the pack and the direct call get the same options.
TEST(PackWorst, HopWorstEqualsWorstCaseOfItsSpecAlone) {
  const std::string text =
      "stimulus: {frames: [\"single-read dev=2 reg=0x0215 n=1\"]}\n"
      "hops:\n"
      "  - spec: {cable: {length: 1}}\n"
      "  - {spec: {name: m, cable: {length: 2}}, repeat: 2}\n";
  StatusOr<PackSpec> p = read_pack_spec_text(text, ::testing::TempDir() + "/worst_pack.yaml");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  WorstOptions wo;
  for (int b : {0x00, 0x01, 0x0F, 0x3C, 0x55, 0x7E, 0xAA, 0xFF})
    wo.targets.push_back(b), wo.targets.push_back(b | 0x100);
  wo.previous = {0x00, 0xFF, 0x155, 0xAA};
  PackOptions opt;
  opt.worst = wo;
  StatusOr<PackResult> r = run_pack(*p, *parts, opt);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r->hops.size(), 3u);
  // A read: both directions; hop 1 has the bridge at one end (2 circuits), hops 2 and 3 are one
  // symmetric circuit (up is down's).
  EXPECT_EQ(r->worst_cases, 3);
  bool all_pass = true;
  nlohmann::ordered_json first_alone;  // hop 1's, as `isolink worst --json` prints it
  for (size_t k = 0; k < r->hops.size(); ++k) {
    const HopResult& h = r->hops[k];
    StatusOr<WorstResult> alone = worst_case(p->hops[k].spec, *parts, wo);
    ASSERT_TRUE(alone.ok()) << alone.status().message();
    ASSERT_EQ(h.worst.size(), alone->directions.size());
    if (k == 0) first_alone = reports::worst_json(*alone);
    bool hop_pass = true;
    for (size_t d = 0; d < h.worst.size(); ++d) {
      const DirectionWorst& x = h.worst[d];
      const DirectionWorst& y = alone->directions[d];
      EXPECT_EQ(x.direction, y.direction);
      EXPECT_EQ(x.description, y.description);
      EXPECT_EQ(x.pass, y.pass);
      EXPECT_EQ(x.memory, y.memory);
      EXPECT_EQ(x.scored, y.scored);
      EXPECT_EQ(x.edge.e, y.edge.e);  // bit for bit
      ASSERT_EQ(x.metrics.size(), 5u);
      ASSERT_EQ(x.metrics.size(), y.metrics.size());
      for (size_t m = 0; m < x.metrics.size(); ++m) {
        EXPECT_EQ(x.metrics[m].name, y.metrics[m].name);
        EXPECT_EQ(x.metrics[m].value, y.metrics[m].value) << k << " " << x.metrics[m].name;
        EXPECT_EQ(x.metrics[m].margin, y.metrics[m].margin);
        EXPECT_EQ(x.metrics[m].bound, y.metrics[m].bound);
        EXPECT_EQ(x.metrics[m].traffic.gaps, y.metrics[m].traffic.gaps);
      }
      hop_pass = hop_pass && y.pass;
    }
    EXPECT_EQ(h.worst_pass, hop_pass);
    all_pass = all_pass && hop_pass;
    // The hop's worst-case margin is the smallest margin / |limit| of the direct call.
    double rel = 1e9;
    for (const DirectionWorst& y : alone->directions)
      for (const WorstMetric& m : y.metrics) rel = std::min(rel, m.margin / std::abs(m.limit));
    EXPECT_EQ(h.worst_case_rel, rel);
  }
  EXPECT_EQ(r->worst_pass, all_pass);
  // report.json: each hop direction's `worst` is `isolink worst --json`'s directions[].worst.
  const nlohmann::ordered_json pj = reports::pack_report_json(*p, *r);
  EXPECT_EQ(pj["worst_verdict"], all_pass ? "pass" : "fail");
  EXPECT_EQ(pj["verdict"], r->pass ? "pass" : "fail");
  for (size_t d = 0; d < 2; ++d)
    EXPECT_EQ(pj["hops"][0]["directions"][d]["worst"], first_alone["directions"][d]["worst"]);
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A two-hop pack gives each hop exactly what `isolink run` gives its spec alone.
TEST(PackSim, TwoHopPackEqualsTwoSingleHopRuns) {
  const std::string dir = ::testing::TempDir() + "/two_hop";
  fs::create_directories(dir);
  const std::string a =
      "name: a\ntx: {device: bq79600, isolation: {type: transformer, part: HMU1228NL}}\n"
      "cable: {length: 1}\nstimulus: {frames: [\"single-read dev=1 reg=0x0215 n=1\"]}\n";
  const std::string b =
      "name: b\ntx: {device: bq7961x}\ncable: {length: 3}\n"
      "stimulus: {frames: [\"single-read dev=1 reg=0x0215 n=1\"]}\n";
  std::ofstream(dir + "/a.yaml") << a;
  std::ofstream(dir + "/b.yaml") << b;
  std::ofstream(dir + "/pack.yaml") << "hops: [{spec: a.yaml}, {spec: b.yaml}]\n";
  StatusOr<PackSpec> p = read_pack_spec_file(dir + "/pack.yaml");
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<PackResult> r = run_pack(*p, *parts, {});
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r->hops.size(), 2u);
  EXPECT_EQ(r->simulations, 3);  // hop b is symmetric: its up is the same circuit as down
  const nlohmann::ordered_json pj = reports::pack_report_json(*p, *r);
  for (int k = 0; k < 2; ++k) {
    StatusOr<link::LinkSpec> spec = link::read_link_spec_file(dir + (k ? "/b.yaml" : "/a.yaml"));
    ASSERT_TRUE(spec.ok());
    StatusOr<LinkRun> single = run_link(*spec, *parts);
    ASSERT_TRUE(single.ok()) << single.status().message();
    const LinkRun& hop = r->hops[k].run;
    EXPECT_EQ(hop.pass, single->pass);
    ASSERT_EQ(hop.directions.size(), single->directions.size());
    const nlohmann::ordered_json sj = reports::run_report_json(*spec, *single);
    for (size_t d = 0; d < hop.directions.size(); ++d) {
      const DirectionRun& x = hop.directions[d];
      const DirectionRun& y = single->directions[d];
      EXPECT_EQ(x.link.direction, y.link.direction);
      EXPECT_EQ(x.sim.wave.time, y.sim.wave.time);
      EXPECT_EQ(x.sim.wave.columns[0], y.sim.wave.columns[0]);  // bit for bit
      // The report's directions[] carry the same check, verdict and rules as `isolink run`'s.
      const auto& hj = pj["hops"][k]["directions"][d];
      const auto& rj = sj["directions"][d];
      EXPECT_EQ(hj["check"], rj["check"]);
      EXPECT_EQ(hj["verdict"], rj["verdict"]);
      EXPECT_EQ(hj["rules"], rj["rules"]);
    }
  }
}

// The example: 16 devices, a ring, through the binary; the bundle is complete, every hop and
// break case is listed, and the weakest hop is the one with the smallest margin.
TEST(PackSim, ExamplePackThroughTheBinary) {
  const std::string dir = ::testing::TempDir() + "/pack16";
  fs::remove_all(dir);
  const std::string cmd = std::string(ISOLINK_BINARY) + " pack " + ISOLINK_EXAMPLES_DIR +
                          "/pack/pack_16.yaml -q -o " + dir + " > " + dir + ".out 2>&1";
  const int status = std::system(cmd.c_str());
  const nlohmann::json j = nlohmann::json::parse(slurp(dir + "/report.json"));
  const int code = WEXITSTATUS(status);
  // Exit 1 when a hop fails the spec traffic or its worst case over all traffic.
  EXPECT_EQ(code, j["verdict"] == "pass" && j["worst_verdict"] == "pass" ? 0 : 1)
      << slurp(dir + ".out");
  EXPECT_EQ(j["worst_cases"], 7);  // one per distinct circuit, as the simulations
  ASSERT_EQ(j["hops"].size(), 17u);
  EXPECT_EQ(j["devices"], 16);
  // Distinct circuits: the bridge hop (0.5 m) and the 4 m return hop in each direction (a
  // bq79600 board at one end), on-board, the 0.3 m jumper and the 2.5 m harness once each
  // (symmetric: up is the same circuit as down): 2 + 2 + 3.
  EXPECT_EQ(j["simulations"], 7);
  EXPECT_EQ(j["expansions"], 34);
  EXPECT_EQ(j["ring_breaks"].size(), 18u);
  double worst = 1e9;
  int weakest = 0;
  for (const auto& h : j["hops"]) {
    EXPECT_EQ(h["directions"].size(), 2u);
    for (const auto& d : h["directions"])
      for (const char* m : {"vstart", "vend", "width_min", "width_max", "edge"})
        EXPECT_TRUE(d["worst"][m]["margin"].is_number()) << h["index"] << " " << m;
    const double m = h["worst_margin_rel"].get<double>() - (h["verdict"] == "pass" ? 0 : 1e9);
    if (m < worst) worst = m, weakest = h["index"];
    EXPECT_TRUE(fs::exists(fmt::format("{}/hop_{:02}/eye.png", dir, h["index"].get<int>())));
  }
  EXPECT_EQ(j["weakest_hop"], weakest);
  EXPECT_TRUE(fs::exists(dir + "/pack.png"));
  const std::string md = slurp(dir + "/report.md");
  EXPECT_NE(md.find(fmt::format("| **{} (weakest)** |", weakest)), std::string::npos);
}

}  // namespace
}  // namespace isolink::analysis
