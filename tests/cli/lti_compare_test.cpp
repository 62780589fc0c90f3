// The LTI engine (`--engine lti`, and `auto` where it is the cheaper one) against ngspice at tight
// tolerances (reltol 1e-6) and against the transient engine, on the example netlists, the example
// link specs (exported as `isolink export-spice` does) and 20 m and 40 m transformer links.
// Windows are short (a few us) so that the tight ngspice runs stay a few seconds:
// the LTI engine's error does not accumulate over a run (each corner adds its own response).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "analysis/simulate.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/spice_writer.h"
#include "ngspice_runner.h"
#include "run_isolink.h"

namespace isolink {
namespace {

const std::string kExamples = ISOLINK_EXAMPLES_DIR;

// Runs `netlist` (written at `path`) through the LTI engine, the default transient and tight
// ngspice to `tstop` (0: the netlist's); returns the max deviations (V) of v(rxp,rxn).
struct Deviation {
  double lti = 0, transient = 0;
};
Deviation compare(const Netlist& netlist, const std::string& path, double tstop) {
  const std::vector<std::string> probes = {"v(rxp,rxn)"};
  analysis::SimulationRequest req{.probes = probes};
  std::string tran;
  if (tstop > 0) {
    req.tstop = tstop;
    char card[64];
    std::snprintf(card, sizeof card, ".tran %.9g %.9g", netlist.tran->tstep, tstop);
    tran = card;
  }
  req.engine = analysis::Engine::Lti;
  auto lti = analysis::simulate_netlist(netlist, req);
  EXPECT_TRUE(lti.ok()) << lti.status().message();
  req.engine = analysis::Engine::Transient;
  req.reltol = 1e-3;  // one run at the netlist's tolerance (at the defaults it would check itself)
  auto transient = analysis::simulate_netlist(netlist, req);
  req.reltol.reset();
  EXPECT_TRUE(transient.ok()) << transient.status().message();
  const std::string work = ::testing::TempDir() + "/lti_compare";
  // trtol 1: at reltol 1e-6 ngspice's default trtol 7 leaves 2.4 mV of its own error on the 15 m
  // transformer link (against reltol 1e-7, tmax 0.1 ns; README "LTI engine").
  auto ng = testing::run_ngspice(path, probes, work,
                                 std::string(testing::kNgspiceTight) + " trtol=1", tran);
  EXPECT_TRUE(ng.ok()) << ng.status().message();
  if (!lti.ok() || !transient.ok() || !ng.ok()) return {1, 1};
  EXPECT_GT(ng->samples(), 1000u);
  EXPECT_EQ(lti->engine, analysis::Engine::Lti);
  EXPECT_NEAR(lti->wave.time.back(), ng->time.back(), 1e-12);
  Deviation d{testing::max_abs_difference(lti->wave, 0, *ng, 0),
              testing::max_abs_difference(transient->wave, 0, *ng, 0)};
  std::printf(
      "%s: max |dev| from ngspice tight: LTI %.3f mV (%s: order %d, %ld march steps; %ld rows), "
      "transient %.3f mV\n",
      path.c_str(), d.lti * 1e3, lti->lti.method.c_str(), lti->lti.model.order, lti->lti.steps,
      lti->grid.rows, d.transient * 1e3);
  ::testing::Test::RecordProperty("lti_mV", std::to_string(d.lti * 1e3));
  return d;
}

void compare_example(const std::string& name, double tstop) {
  const std::string path = kExamples + "/" + name + ".cir";
  auto netlist = read_spice_file(path);
  ASSERT_TRUE(netlist.ok()) << netlist.status().message();
  Deviation d = compare(*netlist, path, tstop);
  EXPECT_LE(d.lti, 2e-3) << name;
  EXPECT_LE(d.transient, 10e-3) << name;  // the transient's documented accuracy
}

TEST(LtiVsNgspice, CapLink2m) {
  compare_example("cap_link_2m", 0);
}
TEST(LtiVsNgspice, CmcLink5m) {
  compare_example("cmc_link_5m", 5e-6);
}
TEST(LtiVsNgspice, HybridXfmrCap3m) {
  compare_example("hybrid_xfmr_cap_3m", 0);
}
TEST(LtiVsNgspice, XfmrLink15mFirst5us) {
  compare_example("xfmr_link_15m", 5e-6);
}

// A link spec expanded (down direction) and exported as export-spice does.
void compare_spec(const std::string& yaml_text, const std::string& name, double tstop) {
  auto spec = link::read_link_spec_text(yaml_text, name + ".yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  auto parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  auto ex = link::expand_link(*spec, *parts, link::Direction::kDown);
  ASSERT_TRUE(ex.ok()) << ex.status().message();
  const std::string dir = ::testing::TempDir() + "/lti_compare";
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + name + ".cir";
  std::ofstream(path) << write_spice(ex->netlist);
  Deviation d = compare(ex->netlist, path, tstop);
  EXPECT_LE(d.lti, 2e-3) << name;
}

using isolink::testing::slurp;

TEST(LtiVsNgspice, TransformerLink20m) {
  compare_spec(
      "name: xfmr-20m\n"
      "tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}\n"
      "rx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}\n"
      "cable: {length: 20, material: pp, gauge: 24}\n"
      "stimulus: {frames: [\"single-read dev=1 reg=0x0100 n=1\"]}\n",
      "xfmr_20m", 4e-6);
}
TEST(LtiVsNgspice, TransformerLink40m) {
  compare_spec(
      "name: xfmr-40m\n"
      "tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}\n"
      "rx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}\n"
      "cable: {length: 40, material: pp, gauge: 24}\n"
      "stimulus: {frames: [\"single-read dev=1 reg=0x0100 n=1\"]}\n",
      "xfmr_40m", 4e-6);
}
TEST(LtiVsNgspice, HybridLinkExampleSpec) {
  compare_spec(slurp(kExamples + "/hybrid_xfmr_cap_12m.yaml"), "hybrid_xfmr_cap_12m", 4e-6);
}
TEST(LtiVsNgspice, CapChokeExampleSpec) {
  compare_spec(slurp(kExamples + "/capchoke_5m.yaml"), "capchoke_5m", 4e-6);
}

// Auto picks LTI for every link; a SIN source sends auto to the transient and makes lti an error.
TEST(LtiEngineChoice, AutoFallsBackOnSinAndLtiRefusesNamingTheSource) {
  const std::string path = ::testing::TempDir() + "/sin_rc.cir";
  std::ofstream(path) << "sin rc\nVS in 0 SIN(0 1 1meg)\nR1 in out 1k\nC1 out 0 1n\n.tran 1n 2u\n"
                         ".end\n";
  auto netlist = read_spice_file(path);
  ASSERT_TRUE(netlist.ok()) << netlist.status().message();
  analysis::SimulationRequest req{.probes = {"v(out)"}};
  auto r = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->engine, analysis::Engine::Transient);
  EXPECT_NE(r->engine_note.find("'vs'"), std::string::npos) << r->engine_note;
  req.engine = analysis::Engine::Lti;
  auto forced = analysis::simulate_netlist(*netlist, req);
  ASSERT_FALSE(forced.ok());
  EXPECT_NE(forced.status().message().find("sin_rc.cir:2:1: error: source 'vs'"), std::string::npos)
      << forced.status().message();
}

// auto's transient fallback tightens itself (analysis/transient_check.h). A series RLC from rest
// (`uic`, which the LTI engine cannot take): 5 V through 1 ohm, 1 uH, 1 nF, Q = 31.6, ringing
// for 100 periods. Closed form v(c) = 5 (1 - e^(-a t) (cos(wd t) + a / wd sin(wd t))),
// a = R / 2L, wd = sqrt(1 / LC - a^2). At the default reltol 1e-3 the transient is more than
// 5 mV off it (its phase drifts over the periods; 9.7 mV); auto's run tightens reltol and the
// step until two runs agree within the allowance (0.1 % of the 9.8 V peak) and is then within it
// of the closed form at every row, and at most half the plain run's error.
TEST(LtiEngineChoice, AutoTransientFallbackTightensUntilTwoRunsAgree) {
  const std::string path = ::testing::TempDir() + "/rlc_uic.cir";
  std::ofstream(path) << "rlc\nV1 in 0 DC 5\nR1 in a 1\nL1 a c 1u\nC1 c 0 1n\n"
                         ".tran 1n 20u uic\n.end\n";
  auto netlist = read_spice_file(path);
  ASSERT_TRUE(netlist.ok()) << netlist.status().message();
  const double a = 1.0 / (2 * 1e-6), wd = std::sqrt(1.0 / (1e-6 * 1e-9) - a * a);
  auto worst = [&](const Waveform& w) {
    double e = 0;
    for (size_t i = 0; i < w.samples(); ++i) {
      const double t = w.time[i];
      const double v = 5 * (1 - std::exp(-a * t) * (std::cos(wd * t) + a / wd * std::sin(wd * t)));
      e = std::max(e, std::abs(w.columns[0][i] - v));
    }
    return e;
  };
  analysis::SimulationRequest req{
      .probes = {"v(c)"}, .reltol = 1e-3, .engine = analysis::Engine::Transient};
  auto plain = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_FALSE(plain->convergence);  // a tolerance asked for: no tightening
  EXPECT_GT(worst(plain->wave), 5e-3);
  // --engine transient at the defaults tightens itself too (issue 41).
  req.reltol.reset();
  auto forced = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(forced.ok()) << forced.status().message();
  ASSERT_TRUE(forced->convergence);
  EXPECT_TRUE(forced->convergence->agreed);
  EXPECT_LE(worst(forced->wave), forced->convergence->allowed.back());
  req.engine = analysis::Engine::Auto;
  auto r = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->engine, analysis::Engine::Transient);
  EXPECT_NE(r->engine_note.find("uic"), std::string::npos) << r->engine_note;
  ASSERT_TRUE(r->convergence);
  const analysis::TransientConvergence& c = *r->convergence;
  EXPECT_TRUE(c.agreed);
  ASSERT_GE(c.reltols.size(), 2u);
  EXPECT_DOUBLE_EQ(c.reltols.front(), 1e-3);
  EXPECT_NEAR(c.reltols.back(), r->reltol, 1e-18);
  double peak = 0;
  for (double v : r->wave.columns[0]) peak = std::max(peak, std::abs(v));
  EXPECT_NEAR(c.allowed.back(), 1e-3 * peak, 1e-9);  // 0.1 % of the 9.8 V peak, over 5 mV
  EXPECT_LE(c.deviations.back(), c.allowed.back());
  EXPECT_LE(worst(r->wave), c.allowed.back());  // the promise
  EXPECT_LT(worst(r->wave), 0.5 * worst(plain->wave));
  EXPECT_NE(analysis::engine_accuracy(*r).find("checked by tightening"), std::string::npos);
  // --reltol given: the user's tolerance, not tightened.
  req.reltol = 1e-3;
  auto given = analysis::simulate_netlist(*netlist, req);
  ASSERT_TRUE(given.ok());
  EXPECT_FALSE(given->convergence);
}

// max_deviation interpolates the coarse run linearly at the fine run's times: by hand, the ramp
// 0, 1, 2 at t = 0, 1, 2 against 0, 0.6, 1.5 at t = 0, 0.5, 1.5 is 0.1 off (at t = 0.5).
TEST(LtiEngineChoice, MaxDeviationInterpolatesTheCoarseRun) {
  Waveform coarse, fine;
  coarse.time = {0, 1, 2};
  coarse.add_column("v", {0, 1, 2});
  fine.time = {0, 0.5, 1.5};
  fine.add_column("v", {0, 0.6, 1.5});
  EXPECT_NEAR(analysis::max_deviation(coarse, fine), 0.1, 1e-12);
  EXPECT_EQ(analysis::max_deviation(Waveform{}, fine), 0.0);
}

// With the march (the reduced model's fallback), auto takes the LTI engine when the responses
// settle early in the run, and the transient when they do not settle within a quarter of it (the
// march would then cost more than the transient). The reduced model needs no settling: auto
// takes it for both.
// RC step responses, tau = 0.5 us (the march calls it settled at about 14 us of a 100 us run) and
// tau = 100 us (still moving at 25 us); each against v = 1 - exp(-t / tau).
TEST(LtiEngineChoice, AutoTakesTheLtiEngineOnlyWhenTheResponsesSettleEarly) {
  for (double tau : {0.5e-6, 100e-6}) {
    const std::string path = ::testing::TempDir() + "/rc_settle.cir";
    std::ofstream(path) << "rc\nV1 in 0 PWL(0 0 1n 1)\nR1 in out 1k\nC1 out 0 " << tau / 1e3
                        << "\n.tran 100n 100u\n.end\n";
    auto netlist = read_spice_file(path);
    ASSERT_TRUE(netlist.ok()) << netlist.status().message();
    analysis::SimulationRequest req{.probes = {"v(out)"}};
    auto reduced = analysis::simulate_netlist(*netlist, req);
    ASSERT_TRUE(reduced.ok()) << reduced.status().message();
    EXPECT_EQ(reduced->engine, analysis::Engine::Lti);
    EXPECT_EQ(reduced->lti.method, "reduced model");
    for (size_t i = 0; i < reduced->wave.samples(); ++i) {
      const double t = reduced->wave.time[i];
      if (t >= 1e-9) {
        ASSERT_NEAR(reduced->wave.columns[0][i], 1 - std::exp(-(t - 0.5e-9) / tau), 1e-3) << t;
      }
    }
    req.lti_method = LtiOptions::Method::March;
    auto r = analysis::simulate_netlist(*netlist, req);
    ASSERT_TRUE(r.ok()) << r.status().message();
    const bool settles = tau < 10e-6;
    EXPECT_EQ(r->engine, settles ? analysis::Engine::Lti : analysis::Engine::Transient) << tau;
    if (!settles) {
      EXPECT_NE(r->engine_note.find("not settled by 2.5e-05 s"), std::string::npos)
          << r->engine_note;
    }
    double worst = 0;
    for (size_t i = 0; i < r->wave.samples(); ++i) {
      const double t = r->wave.time[i];
      if (t < 1e-9) continue;
      // The 1 ns ramp shifts the response by half a nanosecond.
      worst =
          std::max(worst, std::fabs(r->wave.columns[0][i] - (1 - std::exp(-(t - 0.5e-9) / tau))));
    }
    EXPECT_LT(worst, settles ? 1.5e-3 : 10e-3) << tau;
  }
}

}  // namespace
}  // namespace isolink
