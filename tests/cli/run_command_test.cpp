// `isolink run` and `isolink export-spice` end to end: every example spec expands, simulates and
// is scored with the verdict expected for its design; the report bundle is complete; the
// exported netlist runs in ngspice and agrees with `isolink sim`; bad specs exit 2 and write
// nothing.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "base/waveform.h"
#include "ngspice_runner.h"
#include "run_isolink.h"

namespace {

namespace fs = std::filesystem;
const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;

using Result = isolink::testing::CliResult;
using isolink::testing::slurp;

Result run(const std::string& args, const std::string& tag) {
  return isolink::testing::run_isolink(kBinary, args, tag);
}

// Every example spec and the verdict its design gets (see the comment at the top of each file).
struct Example {
  const char* file;
  const char* verdict;    // report.json "verdict"
  const char *down, *up;  // per-direction verdicts
  // The worst case over all legal traffic (on by default, 60-80 % of a run's time) has its own
  // tests (tests/analysis/worst_test.cpp); two examples keep it here, the others run --no-worst.
  bool worst = false;
};

// The test names already say which example: print only the file in ctest's listing.
void PrintTo(const Example& e, std::ostream* os) {
  *os << e.file;
}

class RunExamples : public ::testing::TestWithParam<Example> {};

TEST_P(RunExamples, BundleAndVerdict) {
  const Example& ex = GetParam();
  const std::string stem = fs::path(ex.file).stem().string();
  const std::string dir = ::testing::TempDir() + "/run_" + stem;
  fs::remove_all(dir);
  Result r = run(
      "run " + kExamples + "/" + ex.file + " -o " + dir + " -q" + (ex.worst ? "" : " --no-worst"),
      stem);
  const bool pass = std::string(ex.verdict) == "pass";
  EXPECT_EQ(r.code, pass ? 0 : 1) << r.err;
  for (const char* f :
       {"eye.png", "wave.png", "report.json", "report.md", "wave.csv", "report.html"})
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
  for (const auto& e : fs::directory_iterator(dir))  // no temporary files left behind
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  nlohmann::json j = nlohmann::json::parse(slurp(dir + "/report.json"));
  EXPECT_EQ(j["verdict"], ex.verdict);
  EXPECT_EQ(j.contains("worst_case"), ex.worst);
  ASSERT_EQ(j["directions"].size(), 2u);
  EXPECT_EQ(j["directions"][0]["direction"], "down");
  EXPECT_EQ(j["directions"][0]["verdict"], ex.down);
  EXPECT_EQ(j["directions"][1]["direction"], "up");
  EXPECT_EQ(j["directions"][1]["verdict"], ex.up);
  for (const auto& d : j["directions"]) {
    // A passing direction decoded every byte that was sent; the check JSON is embedded whole.
    if (d["verdict"] == "pass") {
      EXPECT_EQ(d["check"]["verdict"], "pass");
    }
    // The reduced model (the default LTI method) has no march steps: its order and check say
    // what was computed; the march and the transient take many steps.
    if (d["solver"].value("lti_method", "") == "reduced model") {
      EXPECT_GT(d["solver"]["reduced_model"]["order"].get<int>(), 20);
      EXPECT_LE(d["solver"]["reduced_model"]["ac_error"].get<double>(), 2e-5);
    } else {
      EXPECT_GT(d["solver"]["steps"].get<long>(), 1000);
    }
    EXPECT_GE(d["solver"]["cable_segments"].get<int>(), 2);
  }
  const std::string md = slurp(dir + "/report.md");
  EXPECT_NE(md.find(pass ? "**Verdict: PASS**" : "**Verdict: FAIL**"), std::string::npos);
  EXPECT_NE(md.find("![eye.png](eye.png)"), std::string::npos);
  // wave.csv: time plus four probes per direction.
  std::istringstream csv(slurp(dir + "/wave.csv"));
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "time,\"down v(rxp,rxn)\",down v(rxp),down v(rxn),\"down v(txp,txn)\","
            "\"up v(rxp,rxn)\",up v(rxp),up v(rxn),\"up v(txp,txn)\"");
}

INSTANTIATE_TEST_SUITE_P(
    Examples, RunExamples,
    ::testing::Values(Example{"cap_2m.yaml", "pass", "pass", "pass", true},
                      Example{"same_pcb.yaml", "pass", "pass", "pass"},
                      Example{"capchoke_5m.yaml", "pass", "pass", "pass"},
                      Example{"capdualchoke_10m.yaml", "pass", "pass", "pass"},
                      Example{"transformer_15m.yaml", "pass", "pass", "pass"},
                      // The bq79600 bridge's receiver (VSTART 1.8 V, no dips) sees the 12 m
                      // cable's reflection as a dip inside double pulses.
                      Example{"hybrid_xfmr_cap_12m.yaml", "fail", "pass", "fail", true},
                      Example{"bq79606a_same_pcb.yaml", "pass", "pass", "pass"},
                      Example{"bq79606a_cap_2m.yaml", "pass", "pass", "pass"},
                      // 28.6 uH leakage at each end: 50 ns edges and 295 ns pulses.
                      Example{"bq79606a_xfmr_10m.yaml", "fail", "fail", "fail"}),
    [](const ::testing::TestParamInfo<Example>& i) {
      std::string s = fs::path(i.param.file).stem().string();
      for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return s;
    });

// The nonlinear example (PESD2CAN TVS diodes and the pins' rail clamps on bq79606a_cap_2m's
// link) on the port model: about 3 s (the full Newton transient took a minute of CPU).
TEST(RunExamples, NonlinearTvsExamplePassesBothWays) {
  const std::string dir = ::testing::TempDir() + "/run_tvs_example";
  fs::remove_all(dir);
  Result r = run("run " + kExamples + "/bq79606a_tvs_2m.yaml -o " + dir + " -q", "tvs_example");
  EXPECT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(slurp(dir + "/report.json"));
  EXPECT_EQ(j["verdict"], "pass");
  ASSERT_EQ(j["directions"].size(), 2u);
  for (const auto& d : j["directions"]) {
    EXPECT_EQ(d["verdict"], "pass");
    EXPECT_EQ(d["solver"]["engine"], "port");
  }
  EXPECT_EQ(j["worst_case"]["computed"], false);
}

TEST(RunExamples, EveryExampleSpecIsListed) {
  int specs = 0;
  for (const auto& e : fs::directory_iterator(kExamples))
    if (e.path().extension() == ".yaml" && e.path().filename().string().rfind("sweep", 0) != 0)
      ++specs;
  EXPECT_EQ(specs, 11);
}

// The start-up of a 16-device stack down the first hop (TI's auto-addressing, then a stack read
// of the cell voltages): every byte decodes. 217 bytes by hand: 8 stack writes of 6 bytes
// (init, register x2, data, CRC x2), 18 broadcast writes of 6, one single write of 7 (the
// device address), 9 stack reads of 6 (init, register x2, count, CRC x2).
TEST(RunExamplesSlow, StartupOfSixteenDevicesDecodesEveryByte) {
  const std::string dir = ::testing::TempDir() + "/run_startup_16";
  fs::remove_all(dir);
  Result r = run("run " + kExamples + "/startup_16.yaml -o " + dir + " -q --no-worst", "startup");
  EXPECT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(slurp(dir + "/report.json"));
  ASSERT_EQ(j["directions"].size(), 1u);
  const auto& decoded = j["directions"][0]["check"]["decoded"];
  EXPECT_EQ(decoded["match"], true);
  const std::string bytes = decoded["bytes"];
  EXPECT_EQ((bytes.size() + 1) / 3, 8u * 6 + 18 * 6 + 7 + 9 * 6);
}

// A nonlinear link (TVS parts, pin clamps) runs on the nonlinear transient, and the worst case,
// which superposes edge responses, is reported as not computed with the reason; `isolink worst`
// refuses it (exit 2) with the same reason.
TEST(RunCommand, NonlinearLinkSaysWhyItHasNoWorstCase) {
  const std::string dir = ::testing::TempDir() + "/run_tvs_worst";
  fs::remove_all(dir);
  // One byte down a 1 m cap link with a PESD2CAN at the transmitter and rail clamps at the
  // receiver's pins: a few seconds on the nonlinear transient.
  const std::string spec = ::testing::TempDir() + "/tvs_one_byte.yaml";
  std::ofstream(spec) << "name: tvs-one-byte\n"
                         "tx: {isolation: {esd: PESD2CAN}}\n"
                         "rx: {pin_clamps: rails}\n"
                         "cable: {length: 1}\n"
                         "stimulus: {frames: [\"raw 5A nocrc\"], direction: down}\n";
  Result r = run("run " + spec + " -o " + dir + " -q", "tvs_worst");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("note: no worst case"), std::string::npos) << r.err;
  nlohmann::json j = nlohmann::json::parse(slurp(dir + "/report.json"));
  ASSERT_TRUE(j.contains("worst_case"));
  EXPECT_EQ(j["worst_case"]["computed"], false);
  const std::string why = j["worst_case"]["why"];
  EXPECT_NE(why.find("tx.isolation.esd: TVS PESD2CAN"), std::string::npos) << why;
  EXPECT_NE(why.find("rx.pin_clamps: rails"), std::string::npos) << why;
  for (const auto& d : j["directions"]) EXPECT_EQ(d["solver"]["engine"], "port");
  EXPECT_NE(slurp(dir + "/report.md").find("Not computed: the worst case"), std::string::npos);
  Result w = run("worst " + spec, "tvs_worst_cmd");
  EXPECT_EQ(w.code, 2);
  EXPECT_NE(w.err.find("needs a linear link"), std::string::npos) << w.err;
}

TEST(RunCommand, BadSpecExitsTwoAndWritesNothing) {
  const std::string spec = ::testing::TempDir() + "/bad_spec.yaml";
  std::ofstream(spec) << "name: bad\ncable: {length: 3, gauge: 40}\n";
  const std::string dir = ::testing::TempDir() + "/run_bad";
  fs::remove_all(dir);
  Result r = run("run " + spec + " -o " + dir, "bad");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad_spec.yaml:2:27: error: key 'cable.gauge' = 40: must be in 18..30"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir));
}

TEST(RunCommand, UnknownPartNamesTheKey) {
  const std::string spec = ::testing::TempDir() + "/bad_part.yaml";
  std::ofstream(spec) << "name: badpart\nrx:\n  isolation: {type: transformer, part: XYZ123}\n";
  Result r = run("run " + spec + " -o " + ::testing::TempDir() + "/run_badpart", "badpart");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad_part.yaml:3:14: error: rx.isolation.part: unknown part 'XYZ123'"),
            std::string::npos)
      << r.err;
}

// The exported netlist runs in ngspice and agrees with `isolink sim` of the same file within
// 10 mV (ngspice at tight tolerances). Both run the first 12 us only: the preamble and the first
// byte of the frame, every kind of edge the chokes and the cable shape; ngspice at reltol 1e-6 on
// the whole 95 us took 255 s of a 308 s suite (10 s of CPU for this window; its error is per
// edge, not accumulated, so the window loses nothing the comparison checks).
TEST(ExportSpice, RunsInNgspiceAndAgreesWithIsolink) {
  const std::string work = ::testing::TempDir() + "/export";
  fs::create_directories(work);
  const std::string cir = work + "/capchoke.cir";
  Result e = run("export-spice " + kExamples + "/capchoke_5m.yaml -o " + cir, "export");
  ASSERT_EQ(e.code, 0) << e.err;
  const std::string csv = work + "/iso.csv";
  Result s = run("sim " + cir + " --probe 'v(rxp,rxn)' --tstop 12e-6 -o " + csv, "export_sim");
  ASSERT_EQ(s.code, 0) << s.err;
  auto ng = isolink::testing::run_ngspice(cir, {"v(rxp,rxn)"}, work,
                                          isolink::testing::kNgspiceTight, ".tran 1e-9 12e-6");
  ASSERT_TRUE(ng.ok()) << ng.status().message();
  std::ifstream in(csv);
  isolink::Waveform iso;
  std::string line;
  std::getline(in, line);
  double t = 0, v = 0;
  char comma = 0;
  std::vector<double> vs;
  while (in >> t >> comma >> v) iso.time.push_back(t), vs.push_back(v);
  iso.add_column("v(rxp,rxn)", vs);
  ASSERT_GT(iso.samples(), 1000u);
  ASSERT_NEAR(iso.time.back(), 12e-6, 1e-12);
  ASSERT_NEAR(ng->time.back(), 12e-6, 1e-12);
  const double dev = isolink::testing::max_abs_difference(iso, 0, *ng, 0);
  std::printf("capchoke_5m exported: isolink sim vs ngspice (tight) max |dv| = %.2f mV\n",
              dev * 1e3);
  EXPECT_LT(dev, 10e-3);
}

TEST(ExportSpice, UpDirectionSwapsTheEnds) {
  Result down = run("export-spice " + kExamples + "/hybrid_xfmr_cap_12m.yaml", "export_down");
  Result up =
      run("export-spice " + kExamples + "/hybrid_xfmr_cap_12m.yaml --direction up", "export_up");
  ASSERT_EQ(down.code, 0) << down.err;
  ASSERT_EQ(up.code, 0) << up.err;
  // down: the bq79600 end (transformer) transmits; up: the bq7961x end (cap) transmits, so the
  // transformer sits on the receiving side. The title line says which.
  EXPECT_EQ(down.out.rfind("isolink link spec 'xfmr-12m', down: bq79600 -> bq7961x", 0), 0u);
  EXPECT_EQ(up.out.rfind("isolink link spec 'xfmr-12m', up: bq7961x -> bq79600", 0), 0u);
  EXPECT_NE(down.out.find("l.ttx.lpri tx_lp "), std::string::npos);
  EXPECT_EQ(down.out.find("trx."), std::string::npos);
  EXPECT_NE(up.out.find("l.trx.lpri rx_lp "), std::string::npos);
  EXPECT_EQ(up.out.find("ttx."), std::string::npos);
}

}  // namespace
