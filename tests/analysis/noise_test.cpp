// Noise immunity (analysis/noise.h): conversion against a hand-worked RC case and ngspice, the
// balanced link, the receiver budget, TI's ranking of the isolation types on the BCI setup.
#include "analysis/noise.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "eye/rules.h"
#include "netlists/link/cards.h"
#include "ngspice_runner.h"

namespace isolink::analysis {
namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;

const link::PartLibrary& parts() {
  static const link::PartLibrary lib = *link::PartLibrary::load({});
  return lib;
}

link::LinkSpec spec_of(const std::string& yaml) {
  StatusOr<link::LinkSpec> s = link::read_link_spec_text(yaml, "test.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return s.ok() ? *s : link::LinkSpec{};
}

// A common-mode source driving two R-C lines to ground: p and n.
std::vector<Card> rc_cards(double r, double c) {
  using link::make_card;
  using link::number_arg;
  return {make_card('v', "vcm", {"s", "0"}, {number_arg(0)}),
          make_card('r', "rp", {"s", "p"}, {number_arg(r)}),
          make_card('r', "rn", {"s", "n"}, {number_arg(r)}),
          make_card('c', "cp", {"p", "0"}, {number_arg(c)}),
          make_card('c', "cn", {"n", "0"}, {number_arg(c)})};
}

// By hand: H(x) = 1 / (1 + j x), x = w R C. With C_p = C (1 + t) and C_n = C (1 - t) (the worst
// corner: the two lines move apart) the differential response is H(x (1 + t)) - H(x (1 - t)),
// to first order 2 t x / (1 + x^2): largest (t) at x = 1, falling as 2 t x at low and 2 t / x at
// high frequency, and growing in proportion to t.
TEST(NoiseConversion, RcImbalanceGrowsAsTheHandCalculationSays) {
  const double r = 1e3, c = 1e-9, f0 = 1 / (2 * kPi * r * c);
  for (double t : {0.01, 0.02, 0.05}) {
    ConversionRequest req;
    req.sources = {{"vcm", 1.0}};
    req.p = "p", req.n = "n";
    req.groups = {{"cp", "test", {3}, t}, {"cn", "test", {4}, t}};
    req.frequencies = {f0 / 10, f0, 10 * f0};
    StatusOr<std::vector<ConversionPoint>> pts = conversion_sweep(rc_cards(r, c), req);
    ASSERT_TRUE(pts.ok()) << pts.status().message();
    for (const ConversionPoint& p : *pts) {
      const double x = 2 * kPi * p.freq_hz * r * c;
      auto h = [](double y) { return 1.0 / Complex(1, y); };
      const double exact = std::abs(h(x * (1 + t)) - h(x * (1 - t)));
      const double first_order = 2 * t * x / (1 + x * x);
      EXPECT_NEAR(std::abs(p.vp - h(x)), 0, 1e-12);
      EXPECT_NEAR(std::abs(p.vp - p.vn), 0, 1e-12) << "balanced nominal";
      // The linearised worst case: first order exactly, the true corner within t^2.
      EXPECT_NEAR(p.dm_worst, first_order, 1e-9 * first_order) << "t " << t << " x " << x;
      EXPECT_NEAR(p.dm_worst, exact, 1.5 * t * t * exact) << "t " << t << " x " << x;
    }
  }
}

// Contributors on the RC pair with C_p +/- t1 and C_n +/- t2: the differential sensitivities are
// -H'(x) x t1 and +H'(x) x t2, of one phase, so the worst corner adds their magnitudes and the
// shares are t1 / (t1 + t2) and t2 / (t1 + t2) exactly: 0.25 and 0.75 for 1 % and 3 %.
TEST(NoiseContributors, TwoCapacitorsShareInProportionToTheirTolerances) {
  const double r = 1e3, c = 1e-9, f0 = 1 / (2 * kPi * r * c);
  ConversionRequest req;
  req.sources = {{"vcm", 1.0}};
  req.p = "p", req.n = "n";
  req.groups = {{"cp", "test", {3}, 0.01}, {"cn", "test", {4}, 0.03}};
  req.frequencies = {f0 / 7, f0, 3 * f0};
  StatusOr<std::vector<ConversionPoint>> pts = conversion_sweep(rc_cards(r, c), req);
  ASSERT_TRUE(pts.ok()) << pts.status().message();
  for (const ConversionPoint& p : *pts) {
    ASSERT_EQ(p.sp.size(), 2u);
    const std::vector<Complex> s_dm = {p.sp[0] - p.sn[0], p.sp[1] - p.sn[1]};
    const std::vector<Contributor> c2 = contributors_at(req.groups, s_dm, p.dm_theta);
    ASSERT_EQ(c2.size(), 2u);
    EXPECT_EQ(c2[0].element, "cn");
    EXPECT_NEAR(c2[0].share, 0.75, 1e-9);
    EXPECT_EQ(c2[1].element, "cp");
    EXPECT_NEAR(c2[1].share, 0.25, 1e-9);
    // The worst corner is the nominal (0 here) plus the two contributions at its angle.
    const Complex u = std::polar(1.0, -p.dm_theta);
    EXPECT_NEAR(p.dm_worst, std::abs((s_dm[0] * u).real()) + std::abs((s_dm[1] * u).real()),
                1e-12 * p.dm_worst);
    // Only one toleranced part: all of it.
    const std::vector<Contributor> c1 = contributors_at({req.groups[0]}, {s_dm[0]}, p.dm_theta);
    ASSERT_EQ(c1.size(), 1u);
    EXPECT_NEAR(c1[0].share, 1.0, 1e-12);
  }
}

// The Monte Carlo on the RC pair with one toleranced cap (the nominal balanced): a board's
// differential voltage is |s| |d|, d uniform in [-1, 1], so its immunity is the corner's / |d| and
// the figure 99 % of boards reach is the corner's / (the 99th percentile of |d|, 0.99). With 2000
// boards it is the 21st largest |d| of 2000: between 0.98 and 0.995 but for odds under 1e-3.
// 200 boards (the default) take the 3rd largest: above 0.95 but for odds of 3e-3.
TEST(NoiseStatistics, UniformSamplesGiveTheNinetyNinthPercentileOfTheHandModel) {
  const double r = 1e3, c = 1e-9, f0 = 1 / (2 * kPi * r * c);
  ConversionRequest req;
  req.sources = {{"vcm", 1.0}};
  req.p = "p", req.n = "n";
  req.groups = {{"cp", "test", {3}, 0.05}};
  req.frequencies = {f0};
  StatusOr<std::vector<ConversionPoint>> pts = conversion_sweep(rc_cards(r, c), req);
  ASSERT_TRUE(pts.ok()) << pts.status().message();
  const double budget = 0.3, peak = 1.4;
  const double corner = budget / ((*pts)[0].dm_worst * peak);
  link::NoiseSpec ns;
  ns.level = 0.1;
  for (int samples : {2000, 200}) {
    ns.samples = samples;
    for (uint64_t seed : {1u, 7u, 12345u}) {
      const StatisticalImmunity st = monte_carlo_immunity(*pts, 1, ns, seed, budget, 1e9, peak);
      EXPECT_EQ(st.samples, samples);
      const double ratio = st.immunity_min / corner;
      EXPECT_GE(ratio, 1.0 - 1e-9);
      if (samples == 2000) {
        EXPECT_GT(ratio, 1 / 0.995) << "seed " << seed;
        EXPECT_LT(ratio, 1 / 0.98) << "seed " << seed;
      } else {
        EXPECT_LT(ratio, 1 / 0.95) << "seed " << seed;
      }
      // The median board (|d| about 0.5) is twice the corner's.
      EXPECT_NEAR(st.median / corner, 2.0, samples == 2000 ? 0.15 : 0.4);
      EXPECT_DOUBLE_EQ(st.immunity_min_freq, f0);
    }
  }
}

TEST(NoiseConversion, BalancedRcConvertsNothing) {
  ConversionRequest req;
  req.sources = {{"vcm", 1.0}};
  req.p = "p", req.n = "n";
  req.frequencies = {1e4, 1e5, 1e6, 1e7, 1e8};
  StatusOr<std::vector<ConversionPoint>> pts = conversion_sweep(rc_cards(1e3, 1e-9), req);
  ASSERT_TRUE(pts.ok()) << pts.status().message();
  for (const ConversionPoint& p : *pts) {
    EXPECT_NEAR(p.dm_worst, std::abs(p.vp - p.vn), 1e-12 * std::abs(p.vp - p.vn));
    EXPECT_LT(std::abs(p.vp - p.vn), 1e-15);
  }
}

const char* kLink17 = R"(
name: bci-1p7m
tx: {device: bq7961x, isolation: {ISO}}
rx: {device: bq7961x, isolation: {ISO}}
cable: {length: 1.7}
noise: {injection: INJ, level: 100m, position: 0.5, time_domain: false}
)";

std::string link17(const std::string& iso, const std::string& injection = "bci") {
  std::string s = kLink17;
  for (int i = 0; i < 2; ++i) s.replace(s.find("ISO"), 3, iso);
  s.replace(s.find("INJ"), 3, injection);
  return s;
}

const char* kCap = "type: cap, cap: 2.2n";
const char* kCapChoke = "type: capchoke, cap: 2.2n, chokes: [ACT45B-510-2P-TL003]";
const char* kXfmr = "type: transformer, part: HMU1228NL";

// Every P and N part equal, the cable perfectly twisted: no common mode becomes differential,
// whatever the injection, down to the solver's rounding.
TEST(NoiseLink, PerfectlyBalancedLinkConvertsNothing) {
  for (const char* iso : {kCap, kCapChoke, kXfmr})
    for (const char* inj : {"bci", "ground_shift"}) {
      link::LinkSpec spec = spec_of(link17(iso, inj));
      StatusOr<NoiseCircuit> nc = build_noise_circuit(spec, parts(), link::Direction::kDown);
      ASSERT_TRUE(nc.ok()) << nc.status().message();
      ConversionRequest req;
      req.sources = nc->sources;
      req.ref = nc->rx_ground;
      req.frequencies = noise_frequencies(spec.noise);
      StatusOr<std::vector<ConversionPoint>> pts = conversion_sweep(nc->link.netlist.cards, req);
      ASSERT_TRUE(pts.ok()) << pts.status().message();
      // Relative to the largest pin voltage of the sweep (the solution's scale: where the pins'
      // common mode is itself tiny, rounding is relative to the larger voltages elsewhere).
      double scale = 0, worst = 0;
      for (const ConversionPoint& p : *pts)
        scale = std::max({scale, std::abs(p.vp), std::abs(p.vn)});
      ASSERT_GT(scale, 0);
      for (const ConversionPoint& p : *pts) worst = std::max(worst, std::abs(p.vp - p.vn) / scale);
      // -140 dB: the solver's floor on these circuits (measured 2e-8 at most, the transformer;
      // 1e-12 S floating ties against kilohm parts); 1 % of imbalance gives about -40 dB.
      EXPECT_LT(worst, 1e-7) << iso << ", " << inj;
    }
}

// The noise circuit exported for ngspice (noise_spice) with one isolation cap 10 % high, so the
// nominal link converts: ngspice's AC analysis gives the same differential and pin voltages
// within 1 dB at every frequency of its sweep.
TEST(NoiseLink, ConversionAgreesWithNgspiceAc) {
  const std::string dir = ::testing::TempDir() + "/noise_ngspice";
  std::filesystem::create_directories(dir);
  struct Case {
    const char* iso;
    const char* injection;
    const char* moved;  // the card made 10 % larger
  };
  // The installation keys too: boards bonded to the chassis (R + L), the transformer's
  // cable-side caps returning to the chassis, a lossless choke.
  for (const Case& k :
       {Case{kCap, "bci", "crxisop"}, Case{kCapChoke, "bci", "lrx1.lp"},
        Case{kXfmr, "ground_shift", "trx.cip"},
        Case{"type: transformer, part: HMU1228NL, cable_side_return: chassis", "bci", "crxcabp"},
        Case{"type: capchoke, chokes: [ACT45B-510-2P-TL003], choke_loss: none", "bci",
             "ltx1.lp"}}) {
    link::LinkSpec spec = spec_of(link17(k.iso, k.injection));
    if (std::string(k.moved) == "crxcabp") spec.tx.chassis_r = spec.rx.chassis_r = 10e-3;
    if (std::string(k.moved) == "crxcabp") spec.tx.chassis_l = spec.rx.chassis_l = 20e-9;
    StatusOr<NoiseCircuit> nc = build_noise_circuit(spec, parts(), link::Direction::kDown);
    ASSERT_TRUE(nc.ok()) << nc.status().message();
    bool moved = false;
    for (Card& c : nc->link.netlist.cards)
      if (c.name == k.moved) c.args[0].number *= 1.1, moved = true;
    ASSERT_TRUE(moved) << k.moved;
    const std::string deck = dir + "/" + std::string(k.moved) + ".cir";
    std::ofstream(deck) << noise_spice(*nc, spec.noise);
    StatusOr<Waveform> ng =
        testing::run_ngspice(deck, {"mag(v(rxp)-v(rxn))", "mag(v(rxp)-v(grx))"}, dir);
    ASSERT_TRUE(ng.ok()) << ng.status().message();
    ASSERT_GT(ng->samples(), 25u);  // 1-400 MHz (BCI) or 100 kHz-400 MHz, 10 per decade
    ConversionRequest req;
    req.sources = nc->sources;
    req.ref = nc->rx_ground;
    req.frequencies = ng->time;
    StatusOr<std::vector<ConversionPoint>> pts = conversion_sweep(nc->link.netlist.cards, req);
    ASSERT_TRUE(pts.ok()) << pts.status().message();
    double worst_dm = 0, worst_pin = 0;
    for (size_t i = 0; i < pts->size(); ++i) {
      const ConversionPoint& p = (*pts)[i];
      const double dm = std::abs(p.vp - p.vn), pin = std::abs(p.vp);
      worst_dm = std::max(worst_dm, std::abs(20 * std::log10(dm / ng->columns[0][i])));
      worst_pin = std::max(worst_pin, std::abs(20 * std::log10(pin / ng->columns[1][i])));
    }
    EXPECT_LT(worst_dm, 1.0) << k.iso;
    EXPECT_LT(worst_pin, 1.0) << k.iso;
    std::printf("%s (%s, %s +10 %%): |dB| worst DM %.4f, pin %.4f over %zu points\n", k.iso,
                k.injection, k.moved, worst_dm, worst_pin, pts->size());
  }
}

const Card* find_card(const NoiseCircuit& c, const std::string& name) {
  for (const Card& card : c.link.netlist.cards)
    if (card.name == name) return &card;
  return nullptr;
}

// The installation keys build what they say: the bond from the board's ground to the chassis,
// where the cable-side caps return, the choke's loss resistor.
TEST(NoiseInstallation, KeysBuildTheStatedCircuit) {
  auto circuit = [](const std::string& yaml) {
    StatusOr<NoiseCircuit> nc = build_noise_circuit(spec_of(yaml), parts(), link::Direction::kDown);
    EXPECT_TRUE(nc.ok()) << nc.status().message();
    return nc.ok() ? *nc : NoiseCircuit{};
  };
  // Defaults: the board floats on 1 nF, CBYPASS2 returns to the board's ground, no bond.
  NoiseCircuit c = circuit(link17(kXfmr));
  ASSERT_NE(find_card(c, "ctxcabp"), nullptr);
  EXPECT_EQ(find_card(c, "ctxcabp")->nodes[1], "gtx");
  EXPECT_EQ(find_card(c, "crxcabn")->nodes[1], "grx");
  EXPECT_DOUBLE_EQ(find_card(c, "ctxchassis")->args[0].number, 1e-9);
  EXPECT_EQ(find_card(c, "rtxbond"), nullptr);
  // To the chassis, and bonded boards.
  std::string yaml = link17("type: transformer, part: HMU1228NL, cable_side_return: chassis");
  yaml.replace(yaml.find("rx: {device: bq7961x,"), 21, "rx: {device: bq7961x, chassis_r: 2m,");
  yaml.replace(yaml.find("tx: {device: bq7961x,"), 21,
               "tx: {device: bq7961x, chassis_r: 5m, chassis_l: 20n,");
  c = circuit(yaml);
  ASSERT_NE(find_card(c, "ctxcabp"), nullptr);
  EXPECT_EQ(find_card(c, "ctxcabp")->nodes[1], "0");
  EXPECT_EQ(find_card(c, "crxcabn")->nodes[1], "0");
  ASSERT_NE(find_card(c, "rtxbond"), nullptr);
  EXPECT_EQ(find_card(c, "rtxbond")->nodes, (std::vector<std::string>{"gtx", "gtx_bond"}));
  EXPECT_DOUBLE_EQ(find_card(c, "rtxbond")->args[0].number, 5e-3);
  EXPECT_EQ(find_card(c, "ltxbond")->nodes, (std::vector<std::string>{"gtx_bond", "0"}));
  EXPECT_DOUBLE_EQ(find_card(c, "ltxbond")->args[0].number, 20e-9);
  EXPECT_EQ(find_card(c, "rrxbond")->nodes, (std::vector<std::string>{"grx", "0"}));
  EXPECT_EQ(find_card(c, "lrxbond"), nullptr);
  // The choke's loss: fitted (the part's), none, or given.
  const double fitted = parts().find("ACT45B-510-2P-TL003")->choke.loss_r;
  ASSERT_GT(fitted, 0);
  c = circuit(link17(kCapChoke));
  ASSERT_NE(find_card(c, "ltx1.rlp"), nullptr);
  EXPECT_DOUBLE_EQ(find_card(c, "ltx1.rlp")->args[0].number, fitted);
  c = circuit(link17(std::string(kCapChoke) + ", choke_loss: none"));
  EXPECT_EQ(find_card(c, "ltx1.rlp"), nullptr);
  EXPECT_NE(find_card(c, "ltx1.lp"), nullptr);
  c = circuit(link17(std::string(kCapChoke) + ", choke_loss: 300"));
  ASSERT_NE(find_card(c, "ltx1.rln"), nullptr);
  EXPECT_DOUBLE_EQ(find_card(c, "ltx1.rln")->args[0].number, 300);
}

// The band: ISO 11452-4's 1-400 MHz for BCI (and dm), 100 kHz-400 MHz for a ground shift,
// `noise.band` for another.
TEST(NoiseBand, DefaultsFollowTheInjectionAndBandSetsAnother) {
  link::LinkSpec bci = spec_of(link17(kCap));
  EXPECT_DOUBLE_EQ(bci.noise.f_start, 1e6);
  EXPECT_DOUBLE_EQ(bci.noise.f_stop, 400e6);
  const std::vector<double> f = noise_frequencies(bci.noise);
  ASSERT_EQ(f.size(), 28u);  // 2.6 decades, 10 per decade, both ends
  EXPECT_DOUBLE_EQ(f.front(), 1e6);
  EXPECT_DOUBLE_EQ(f.back(), 400e6);
  link::LinkSpec gs = spec_of(link17(kCap, "ground_shift"));
  EXPECT_DOUBLE_EQ(gs.noise.f_start, 100e3);
  EXPECT_DOUBLE_EQ(gs.noise.f_stop, 400e6);
  std::string yaml = link17(kCap);
  yaml.replace(yaml.find("time_domain"), 11, "band: [2meg, 50meg], time_domain");
  link::LinkSpec band = spec_of(yaml);
  EXPECT_DOUBLE_EQ(band.noise.f_start, 2e6);
  EXPECT_DOUBLE_EQ(band.noise.f_stop, 50e6);
  yaml = link17(kCap, "ground_shift");
  yaml.replace(yaml.find("time_domain"), 11, "band: [10k, 1meg], time_domain");
  band = spec_of(yaml);
  EXPECT_DOUBLE_EQ(band.noise.f_start, 10e3);
  EXPECT_DOUBLE_EQ(band.noise.f_stop, 1e6);
}

eye::PulseMetrics pulse(double vstart, double vend, double width_margin, double edge,
                        double edge_margin) {
  eye::PulseMetrics p;
  p.vstart.value = vstart;
  p.vend.value = vend;
  p.width.value = 250e-9, p.width.margin = width_margin;
  p.edge.value = edge, p.edge.margin = edge_margin;
  return p;
}

// Hand-checked budgets on the BQ7961x rules (VEND >= 1.2; VSTART >= 1.6, or 1.7 once VEND <= 1.3).
TEST(NoiseBudget, FollowsTheReceiverRules) {
  StatusOr<eye::Rules> rules = eye::load_rules("bq7961x");
  ASSERT_TRUE(rules.ok());
  eye::CheckResult r;
  r.pass = true;
  // VSTART 2.0 / VEND 1.8: 0.4 V takes VSTART to 1.6 while VEND (1.4) stays above the knee.
  // Edges 20 ns: slope 2.4 V / 20 ns; a 20 ns width margin takes 20 ns x slope / 2 = 1.2 V.
  r.pulses = {pulse(2.0, 1.8, 20e-9, 20e-9, 40e-9)};
  NoiseBudget b = noise_budget(r, *rules, 4.0);
  EXPECT_NEAR(b.amplitude, 0.4, 1e-9);
  EXPECT_NEAR(b.width, 1.2, 1e-9);
  EXPECT_NEAR(b.edge, 2.4, 1e-9);
  EXPECT_NEAR(b.dm_amplitude, 0.4, 1e-9);
  EXPECT_EQ(b.limited_by, "vstart/vend");
  // VSTART 2.5 / VEND 1.35: past 0.05 V VEND is under the knee and VSTART needs 1.7 (room to
  // 0.8 V), but VEND reaches 1.2 V at 0.15 V.
  r.pulses = {pulse(2.5, 1.35, 20e-9, 20e-9, 40e-9)};
  EXPECT_NEAR(noise_budget(r, *rules, 4.0).amplitude, 0.15, 1e-9);
  // VSTART 1.75 / VEND 1.32: under the knee after 0.02 V, where VSTART (1.73) is above 1.7 until
  // 0.05 V.
  r.pulses = {pulse(1.75, 1.32, 20e-9, 20e-9, 40e-9)};
  EXPECT_NEAR(noise_budget(r, *rules, 4.0).amplitude, 0.05, 1e-9);
  // A width margin of 2 ns with 20 ns edges: 2 ns x 0.12 V/ns / 2 = 0.12 V.
  r.pulses = {pulse(3, 3, 2e-9, 20e-9, 40e-9)};
  b = noise_budget(r, *rules, 4.0);
  EXPECT_NEAR(b.dm_amplitude, 0.12, 1e-9);
  EXPECT_EQ(b.limited_by, "width");
  // A failing link has no budget.
  r.pass = false;
  EXPECT_EQ(noise_budget(r, *rules, 4.0).dm_amplitude, 0);
}

StatusOr<NoiseResult> analyze(const link::LinkSpec& spec) {
  StatusOr<NoiseRun> r = run_noise(spec, parts());
  if (!r) return r.status();
  return r->noise;
}

// On TI's 1.7 m BCI link (cap-only, down): the 99 % figure of the Monte Carlo is never below the
// worst corner, the same seed gives the same figure and another seed another one, and
// `verdict_on` picks which of the two the verdict compares with the level. With only the
// isolation caps toleranced, they carry the whole imbalance (shares add up to 1).
TEST(NoiseStatistics, NeverBelowTheCornerSeededAndVerdictOnChoosesTheFigure) {
  link::LinkSpec spec = spec_of(link17(kCap));
  spec.stimulus.directions = {link::Direction::kDown};
  StatusOr<LinkRun> run = run_link(spec, parts());
  ASSERT_TRUE(run.ok()) << run.status().message();
  auto analyze_run = [&](const link::LinkSpec& s) {
    StatusOr<NoiseResult> n = analyze_noise_of_run(s, parts(), *run);
    EXPECT_TRUE(n.ok()) << n.status().message();
    return n.ok() ? n->directions.at(0) : NoiseDirection{};
  };
  const NoiseDirection a = analyze_run(spec);
  EXPECT_EQ(a.statistical.samples, 200);
  EXPECT_GE(a.statistical.immunity_min, a.immunity_min);
  EXPECT_GT(a.statistical.median, a.statistical.immunity_min);
  EXPECT_EQ(analyze_run(spec).statistical.immunity_min, a.statistical.immunity_min);
  link::LinkSpec other = spec;
  other.noise.seed = 2;
  const NoiseDirection b = analyze_run(other);
  EXPECT_NE(b.statistical.immunity_min, a.statistical.immunity_min);
  EXPECT_GE(b.statistical.immunity_min, b.immunity_min);
  EXPECT_EQ(b.immunity_min, a.immunity_min);  // the corner does not depend on the seed
  // A level between the two figures: the corner fails, 99 % of boards pass.
  ASSERT_GT(a.statistical.immunity_min, a.immunity_min * 1.001);
  link::LinkSpec between = spec;
  between.noise.level = std::sqrt(a.immunity_min * a.statistical.immunity_min);
  NoiseDirection d = analyze_run(between);
  EXPECT_FALSE(d.pass_corner);
  EXPECT_TRUE(d.statistical.pass);
  EXPECT_FALSE(d.pass);
  between.noise.verdict_on = "statistical";
  d = analyze_run(between);
  EXPECT_TRUE(d.pass);
  // Only the isolation caps toleranced: they are all of it.
  link::LinkSpec caps = spec;
  caps.noise.tolerance = link::NoiseTolerances{0, 0, 0, 0, 0, 0, 0, 0, 0};
  caps.noise.tolerance.isolation_cap = 0.1;
  d = analyze_run(caps);
  ASSERT_EQ(d.contributors.size(), 4u);
  double sum = 0;
  for (const Contributor& c : d.contributors) {
    EXPECT_EQ(c.kind, "isolation_cap");
    sum += c.share;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  // The default tolerances: sorted, adding up to 1.
  ASSERT_GT(a.contributors.size(), 4u);
  sum = 0;
  for (size_t i = 0; i < a.contributors.size(); ++i) {
    if (i > 0) {
      EXPECT_GE(a.contributors[i - 1].share, a.contributors[i].share);
    }
    sum += a.contributors[i].share;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  std::printf("cap 1.7 m: corner %.4g A at %.3g Hz, 99 %% %.4g A at %.3g Hz; top %s %.2f\n",
              a.immunity_min, a.immunity_min_freq, a.statistical.immunity_min,
              a.statistical.immunity_min_freq, a.contributors[0].element.c_str(),
              a.contributors[0].share);
}

// TI's BCI setup (docs/physics.md 6: ISO 11452-4, 1.7 m, 1 Mbps): the three isolation types with
// TI's parts. Capacitor-only has the lowest immunity over most of the band; capacitor + choke and
// transformer are far better.
// DISABLED: the model does not reproduce TI's ranking yet (issue 16 left open on this point).
// Since issue 30 (1-400 MHz, worst corner, down; analysis/README.md "Installation assumptions"):
// cap 21.3 mA at 9.2 MHz, cap + choke 14.2 mA at 1.0 MHz, transformer 39.7 mA at 14.3 MHz; the
// choke's place turns on its loss (choke_loss: 300 gives 58.4 mA), which no data sheet pins down.
// The history below is from the 100 kHz-400 MHz band:
// Measured (100 mA AM, worst corner, down, 38 points 100 kHz-400 MHz): cap-only is lowest at 17
// of 38 points; median gain over cap-only: cap + choke 0.5 dB, transformer 16.2 dB; immunity
// min: cap 21.2 mA at 8.9 MHz, cap + choke 17.3 mA at 0.94 MHz, transformer 38.5 mA at 14 MHz.
// The choke (51 uH per line pair) is 32 ohm at 100 kHz against a loop of kilohms of capacitance
// (isolation caps, board to chassis), so it changes nothing below 1 MHz, and it series-resonates
// with that capacitance near 0.9 MHz, where it is worst; from 3 to 40 MHz it is 18.5 dB better
// (median; cap-only lowest at 9 of 11 points). Restricted to ISO 11452-4's 1-400 MHz the result
// is the same in kind (cap-only lowest at 17 of 27, choke +5.2 dB, transformer +12.0 dB, the
// choke's minimum 18.0 mA below cap-only's). Checked and ruled out: the assumed 1 nF
// board-to-chassis C (100 pF: cap-only lowest at 13 of 38, choke -0.1 dB; 10 pF: 4 of 38,
// choke -1.9 dB: a smaller C makes it worse); the choke model meets every figure its data sheet
// lists (|Zcm| at 10 MHz exact, CM inductance at 100 kHz within 1 %); TDK's impedance curve is
// a graph only and Wurth's sheet was not available, so no further point to fit a second resonance
// or a frequency-dependent loss to. Open: where CBYPASS2 returns (no source), a ferrite loss that
// damps the 0.9 MHz loop resonance (needs the measured curve), cable radiation loss.
TEST(NoiseRanking, DISABLED_TiBciSetupCapacitorOnlyIsWeakest) {
  std::vector<NoiseResult> r;
  for (const char* iso : {kCap, kCapChoke, kXfmr}) {
    link::LinkSpec spec = spec_of(link17(iso));
    spec.stimulus.directions = {link::Direction::kDown};
    StatusOr<NoiseResult> n = analyze(spec);
    ASSERT_TRUE(n.ok()) << n.status().message();
    r.push_back(*n);
  }
  const auto& cap = r[0].directions[0].points;
  const auto& choke = r[1].directions[0].points;
  const auto& xfmr = r[2].directions[0].points;
  ASSERT_EQ(cap.size(), choke.size());
  size_t lowest = 0;
  std::vector<double> gain_choke, gain_xfmr;
  for (size_t i = 0; i < cap.size(); ++i) {
    if (cap[i].immunity < choke[i].immunity && cap[i].immunity < xfmr[i].immunity) ++lowest;
    gain_choke.push_back(20 * std::log10(choke[i].immunity / cap[i].immunity));
    gain_xfmr.push_back(20 * std::log10(xfmr[i].immunity / cap[i].immunity));
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf(
      "cap lowest at %zu of %zu points; median gain over cap: choke %.1f dB, "
      "transformer %.1f dB; immunity min: cap %.3g A, choke %.3g A, xfmr %.3g A\n",
      lowest, cap.size(), median(gain_choke), median(gain_xfmr), r[0].directions[0].immunity_min,
      r[1].directions[0].immunity_min, r[2].directions[0].immunity_min);
  EXPECT_GT(static_cast<double>(lowest), 0.6 * static_cast<double>(cap.size()));
  EXPECT_GT(median(gain_choke), 10.0);
  EXPECT_GT(median(gain_xfmr), 10.0);
  EXPECT_LT(r[0].directions[0].immunity_min, r[1].directions[0].immunity_min);
  EXPECT_LT(r[0].directions[0].immunity_min, r[2].directions[0].immunity_min);
}

}  // namespace
}  // namespace isolink::analysis
