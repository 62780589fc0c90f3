// isolink stress against ngspice on a seeded corpus of links (issue 42: "its peaks agree with
// ngspice on the exported netlists within 5 % or 0.2 V, on a seeded corpus of links"): eight link
// specs drawn from a fixed seed over cable length (0.5-15 m, log-uniform), insulation, isolation
// (cap 1-10 nF, cap + choke, transformer), the ESD part at each end (none, a capacitance 10-100 pF,
// or one of the library's three TVS parts) and the pins' clamps, each with one ESD scenario (end,
// line, polarity and level 2-8 kV drawn too), run by isolink and replayed in ngspice
// (stress_ngspice.h). Slow: about 10 s per link.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "stress_ngspice.h"

namespace isolink {
namespace {

struct CorpusLink {
  std::string spec;  // YAML
  std::string scenario;
};

std::string pick_one(std::mt19937& rng, std::initializer_list<const char*> xs) {
  return std::string(xs.begin()[std::uniform_int_distribution<size_t>(0, xs.size() - 1)(rng)]);
}

// symmetric: the same isolation at both ends (as a real link has; the traffic corpus), else
// each end's drawn on its own.
CorpusLink draw(std::mt19937& rng, int index, bool symmetric = false) {
  std::uniform_real_distribution<double> u(0, 1);
  auto pick = [&](std::initializer_list<const char*> xs) { return pick_one(rng, xs); };
  const double length = 0.5 * std::pow(30.0, u(rng));  // 0.5 .. 15 m
  const std::string material = pick({"pp", "pvc"});
  auto isolation = [&] {
    const std::string type = pick({"cap", "cap", "capchoke", "transformer"});
    std::string esd = pick({"none", "cap", "PESD2CAN", "ESD24VS2U", "ESDCAN24-2BLY"});
    if (esd == "cap") esd = fmt::format("{:.0f}p", 10 + 90 * u(rng));
    const std::string esd_key = esd == "none" ? "" : ", esd: " + esd;
    if (type == "transformer") return "{type: transformer, part: HMU1228NL" + esd_key + "}";
    const std::string cap = fmt::format("{:.2g}n", 1 + 9 * u(rng));
    if (type == "capchoke")
      return "{type: capchoke, cap: " + cap + ", chokes: [ACT45B-510-2P-TL003]" + esd_key + "}";
    return "{type: cap, cap: " + cap + esd_key + "}";
  };
  const std::string tx_iso = isolation(), rx_iso = symmetric ? tx_iso : isolation();
  const std::string end = pick({"tx", "rx"}), line = pick({"p", "n"}), sign = pick({"pos", "neg"});
  const double kv = 2 + 6 * u(rng);
  // The traffic corpus draws the ground step and the inverter's amplitude too (log-uniform
  // 3-60 V and 3-50 V): at the defaults every drawn link failed to communicate.
  const std::string levels =
      symmetric ? fmt::format(", ground_step: {:.3g}, wave_v: {:.3g}", 3 * std::pow(20.0, u(rng)),
                              3 * std::pow(50.0 / 3, u(rng)))
                : "";
  CorpusLink c;
  c.spec = fmt::format(
      "name: stress-corpus-{}\n"
      "tx: {{device: bq79600, isolation: {}}}\n"
      "rx: {{device: bq7961x, isolation: {}}}\n"
      "cable: {{length: {:.3g}, material: {}}}\n"
      "stress: {{esd: {:.2f}kV{}}}\n",
      index, tx_iso, rx_iso, length, material, kv, levels);
  c.scenario = "esd_" + end + "_" + line + "_" + sign;
  return c;
}

// The link's scenario replayed in ngspice (stress_ngspice.h), and the spec on one line for the
// log.
testing::StressAgreement replay(const CorpusLink& c, std::string* flat) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(c.spec, "corpus.yaml");
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  *flat = c.spec;
  std::replace(flat->begin(), flat->end(), '\n', ' ');
  return spec.ok() ? testing::stress_vs_ngspice(*spec, c.scenario) : testing::StressAgreement{};
}

TEST(StressCorpus, EsdPeaksAgreeWithNgspiceOnEightSeededLinks) {
  std::mt19937 rng(4242);
  double worst_v = 0, worst_share = 0;
  for (int i = 0; i < 8; ++i) {
    const CorpusLink c = draw(rng, i);
    SCOPED_TRACE(c.spec + c.scenario);
    std::string flat;
    const testing::StressAgreement a = replay(c, &flat);
    std::printf("link %d %s(%s): pins within %.3f V (%.0f %% of the allowance), diodes %.3g A\n", i,
                flat.c_str(), c.scenario.c_str(), a.worst_pin_v, 100 * a.worst_pin_share,
                a.worst_diode_a);
    worst_v = std::max(worst_v, a.worst_pin_v);
    worst_share = std::max(worst_share, a.worst_pin_share);
  }
  std::printf("corpus: pins within %.3f V of ngspice, %.0f %% of the allowance at worst\n", worst_v,
              100 * worst_share);
}

// The scenarios with traffic on four more seeded links (seed 4243), one short frame each way:
// two module-ground steps, an inverter square and a wire fault (the end, fault and direction
// drawn), isolink's peaks held to ngspice's and its `communicates` to the checker on ngspice's
// receiver waveform (stress_ngspice.h). The same isolation at both ends, as a real link has:
// with each end drawn alone, all four scenarios failed (one link, a 1.2 nF cap at one end and a
// transformer at the other, fails undisturbed), so `communicates` was checked on "false" alone.
// About 4 min (ngspice's transient of the traffic): labelled slow_corpus, run by hand
// (`ctest --test-dir build -L corpus`), not in CI's slow step.
TEST(StressCorpus, TrafficScenariosAgreeWithNgspiceAndTheChecker) {
  std::mt19937 rng(4243);
  double worst_v = 0;
  int communicates = 0;
  for (int i = 0; i < 4; ++i) {
    CorpusLink c = draw(rng, 10 + i, true);
    c.spec += "stimulus: {frames: [\"single-read dev=1 reg=0x0215 n=1\"]}\n";
    auto pick = [&](std::initializer_list<const char*> xs) { return pick_one(rng, xs); };
    const std::string kind = i == 1 ? "cm_wave" : i == 2 ? "wire" : "cm_step";
    if (kind == "wire")
      c.scenario = "wire_" + pick({"open_p", "short_pn", "n_to_ground", "p_to_chassis", "leak_n"}) +
                   "_" + pick({"down", "up"});
    else
      c.scenario = kind + "_" + pick({"tx", "rx"});
    SCOPED_TRACE(c.spec + c.scenario);
    std::string flat;
    const testing::StressAgreement a = replay(c, &flat);
    std::printf("link %d %s(%s): pins within %.3f V (%.0f %% of the allowance), communicates %d\n",
                i, flat.c_str(), c.scenario.c_str(), a.worst_pin_v, 100 * a.worst_pin_share,
                a.communicates);
    worst_v = std::max(worst_v, a.worst_pin_v);
    communicates += a.communicates ? 1 : 0;
  }
  std::printf("traffic corpus: pins within %.3f V of ngspice; %d of 4 communicate\n", worst_v,
              communicates);
}

}  // namespace
}  // namespace isolink
