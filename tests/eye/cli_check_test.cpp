// End to end: the built `isolink check` on CSV files written here; exit codes and JSON names.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "synth.h"

namespace {

namespace fs = std::filesystem;

class CliCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("isolink_eye_cli_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs isolink with args; returns the exit status, stdout in out_, stderr in err_.
  int run(const std::string& args) {
    const std::string o = (dir_ / "stdout.txt").string(), e = (dir_ / "stderr.txt").string();
    const std::string cmd =
        std::string("'") + ISOLINK_BIN + "' " + args + " >'" + o + "' 2>'" + e + "'";
    const int rc = std::system(cmd.c_str());
    out_ = slurp(o);
    err_ = slurp(e);
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  static std::string slurp(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  std::string write_frames(const std::string& name, const std::vector<uint8_t>& bytes,
                           double amp = 2.0) {
    isolink::Waveform w = synth::ideal_frames(bytes, isolink::FrameFormat{});
    for (double& x : w.columns[0]) x *= amp / 2.0;
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(isolink::write_waveform_csv(w, path).ok());
    return path;
  }
  std::string write_text(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }

  fs::path dir_;
  std::string out_, err_;
};

TEST_F(CliCheck, PassExitsZeroAndJsonHasTheFieldNames) {
  const std::string csv = write_frames("good.csv", {0x80, 0x00, 0x02});
  ASSERT_EQ(run("check '" + csv + "' --json --expect '80 00 02'"), 0) << err_;
  nlohmann::json j = nlohmann::json::parse(out_);
  EXPECT_EQ(j["verdict"], "pass");
  EXPECT_EQ(j["rules"], "bq7961x");
  for (const char* k : {"pulses", "failing", "vstart_min", "vend_min", "width_min_ns",
                        "width_max_ns", "edge_max_ns", "worst"})
    EXPECT_TRUE(j["summary"].contains(k)) << k;
  for (const char* k : {"index", "sign", "start_s", "end_s", "width_ns", "class", "edge_ns",
                        "vstart", "vend", "fails", "warnings"})
    EXPECT_TRUE(j["pulses"][0].contains(k)) << k;
  EXPECT_TRUE(j.contains("ringing"));
  EXPECT_TRUE(j.contains("idle"));
  EXPECT_EQ(j["decoded"]["bytes"], "80 00 02");
  ASSERT_EQ(j["decoded"]["frames"].size(), 3u);
  EXPECT_EQ(j["decoded"]["frames"][0]["byte"], "80");
  EXPECT_TRUE(j["decoded"]["frames"][0]["fault"].is_null());
  EXPECT_NEAR(j["summary"]["vstart_min"].get<double>(), 2.0, 1e-6);
}

// End to end: the cap-2m example link simulated by `isolink run` (TI's stack-write example sent
// down and up), its wave.csv checked by `isolink check`: the command is listed with a valid CRC,
// and run's report.json carries the same list.
TEST_F(CliCheck, CommandsOfASimulatedLink) {
  const std::string bundle = (dir_ / "bundle").string();
  ASSERT_EQ(run(std::string("run '") + ISOLINK_EXAMPLES_DIR + "/cap_2m.yaml' -o '" + bundle +
                "' -q --no-worst --no-images"),
            0)
      << err_;
  for (const char* column : {"down v(rxp,rxn)", "up v(rxp,rxn)"}) {
    ASSERT_EQ(run("check '" + bundle + "/wave.csv' --diff '" + column + "' --json"), 0) << err_;
    const nlohmann::json j = nlohmann::json::parse(out_);
    EXPECT_EQ(j["decoded"]["bytes"], "B3 01 00 02 B7 78 BC 0A 35");
    ASSERT_EQ(j["commands"].size(), 1u) << column;
    const nlohmann::json& c = j["commands"][0];
    EXPECT_EQ(c["kind"], "stack-write");
    EXPECT_EQ(c["register"], "0x0100");
    EXPECT_EQ(c["data"], "02 B7 78 BC");
    EXPECT_EQ(c["crc"], "0A35");
    EXPECT_EQ(c["crc_ok"], true);
    EXPECT_TRUE(c["flags"].empty());
    EXPECT_TRUE(j["commands_note"].is_null());
    // It spans the nine bytes: eight byte periods of 10.3 us plus the last byte's 6.5 us, within
    // the link's edges.
    EXPECT_NEAR(c["end_s"].get<double>() - c["start_s"].get<double>(), 8 * 10.3e-6 + 6.5e-6,
                100e-9);
  }
  ASSERT_EQ(run("check '" + bundle + "/wave.csv' --diff 'down v(rxp,rxn)'"), 0) << err_;
  EXPECT_NE(out_.find("stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok"), std::string::npos) << out_;
  const nlohmann::json report = nlohmann::json::parse(slurp(bundle + "/report.json"));
  EXPECT_EQ(report["directions"][0]["check"]["commands"][0]["text"],
            "stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok");
  EXPECT_EQ(run("check '" + bundle + "/wave.csv' --command-idle=-1u"), 2);
  EXPECT_NE(err_.find("--command-idle: error:"), std::string::npos) << err_;
}

TEST_F(CliCheck, TextSummaryAndPulsesCsv) {
  const std::string csv = write_frames("good.csv", {0x15});
  const std::string table = (dir_ / "pulses.csv").string();
  ASSERT_EQ(run("check '" + csv + "' --pulses-csv '" + table + "'"), 0) << err_;
  EXPECT_NE(out_.find("PASS (rules bq7961x)"), std::string::npos) << out_;
  EXPECT_NE(out_.find("decoded: 15"), std::string::npos) << out_;
  EXPECT_TRUE(fs::exists(table));
  EXPECT_EQ(slurp(table).rfind("index,sign,start_s", 0), 0u);
}

TEST_F(CliCheck, FailExitsOne) {
  // 1.65 V everywhere: fine for bq7961x (VEND 1.65 > 1.3 V needs 1.6 V), short of 1.8 V for the
  // bridge
  const std::string csv = write_frames("low.csv", {0x15}, 1.65);
  EXPECT_EQ(run("check '" + csv + "'"), 0) << out_ << err_;
  EXPECT_EQ(run("check '" + csv + "' --rules bq79600"), 1) << out_ << err_;
  EXPECT_NE(out_.find("FAIL (rules bq79600)"), std::string::npos) << out_;
  EXPECT_EQ(run("check '" + csv + "' --expect 16"), 1);
  EXPECT_EQ(run("check '" + csv + "' --msb-first --json"), 0);  // 0x15 reads as 0xA8
  EXPECT_EQ(nlohmann::json::parse(out_)["decoded"]["bytes"], "A8");
}

TEST_F(CliCheck, BadInputExitsTwoWithFileAndLine) {
  const std::string csv = write_text("bad.csv", "time,v\n0,0\n1e-9,x\n");
  EXPECT_EQ(run("check '" + csv + "'"), 2);
  EXPECT_EQ(err_,
            "isolink check: " + csv + ":3: error: column 2 ('v'): expected a number, found 'x'\n");
  const std::string rules = write_text("r.yaml", "base: bq7961x\nvth: 0\n");
  const std::string good = write_frames("good.csv", {0x15});
  EXPECT_EQ(run("check '" + good + "' --rules '" + rules + "'"), 2);
  EXPECT_EQ(err_, "isolink check: " + rules + ":2:1: error: vth = 0: must be > 0\n vth: 0\n ^\n");
  EXPECT_EQ(run("check '" + (dir_ / "missing.csv").string() + "'"), 2);
  EXPECT_EQ(run("check '" + good + "' --expect 'zz'"), 2);
  EXPECT_EQ(run("check '" + good + "' --diff nope"), 2);
  EXPECT_NE(err_.find("no such column"), std::string::npos) << err_;
}

TEST_F(CliCheck, TwoFilesPAndNWithWhatWasRead) {
  // R&S RTB style: one channel per file, units in the names; N in mV
  isolink::Waveform w = synth::ideal_frames({0x80, 0x15}, isolink::FrameFormat{});
  std::string p = "in s,C1 in V\n", n = "in s,C2 in mV\n";
  for (size_t i = 0; i < w.samples(); ++i) {
    const double v = w.columns[0][i];
    p += fmt::format("{:.9g},{:.9g}\n", w.time[i], 2.5 + v / 2);
    n += fmt::format("{:.9g},{:.9g}\n", w.time[i], (2.5 - v / 2) * 1e3);
  }
  const std::string a = write_text("C1.csv", p), b = write_text("C2.csv", n);
  ASSERT_EQ(run("check '" + a + "' '" + b + "' --json --expect '80 15'"), 0) << err_ << out_;
  nlohmann::json j = nlohmann::json::parse(out_);
  EXPECT_EQ(j["verdict"], "pass");
  EXPECT_EQ(j["decoded"]["bytes"], "80 15");
  const nlohmann::json& in = j["input"];
  EXPECT_EQ(in["files"].size(), 2u);
  EXPECT_EQ(in["samples"], w.samples());
  EXPECT_NEAR(in["interval_s"].get<double>(), 1e-9, 1e-18);
  EXPECT_NEAR(in["span_s"].get<double>(), w.time.back(), 1e-15);
  ASSERT_EQ(in["columns"].size(), 3u);
  EXPECT_EQ(in["columns"][1]["role"], "P");
  EXPECT_EQ(in["columns"][1]["channel"], "CH1");
  EXPECT_EQ(in["columns"][2]["role"], "N");
  EXPECT_EQ(in["columns"][2]["unit"], "mV");
  EXPECT_DOUBLE_EQ(in["columns"][2]["scale"].get<double>(), 1e-3);
  EXPECT_EQ(in["alignment"], "the two files share one time base");
  // the text summary says what was read
  ASSERT_EQ(run("check '" + a + "' '" + b + "'"), 0) << err_;
  EXPECT_NE(out_.find("  N     column 2 'C2 in mV' of " + b +
                      " (default (first channel), unit "
                      "mV, x0.001 to V)"),
            std::string::npos)
      << out_;
  EXPECT_NE(out_.find(fmt::format("  {} samples, 0 ..", w.samples())), std::string::npos) << out_;
  // --diff makes no sense with two files
  EXPECT_EQ(run("check '" + a + "' '" + b + "' --diff 2"), 2);
  EXPECT_NE(err_.find("with two files"), std::string::npos) << err_;
}

TEST_F(CliCheck, InconclusiveExitsOneWithReasonAndHint) {
  // a flat record: nothing to judge
  std::string text = "time,CH1\n";
  for (int i = 0; i < 100; ++i) text += fmt::format("{:g},0.001\n", i * 1e-9);
  const std::string csv = write_text("flat.csv", text);
  EXPECT_EQ(run("check '" + csv + "'"), 1);
  EXPECT_NE(out_.find("INCONCLUSIVE (rules bq7961x)"), std::string::npos) << out_;
  EXPECT_NE(out_.find("  hint: |v| stays under 0.001 V"), std::string::npos) << out_;
  EXPECT_EQ(run("check '" + csv + "' --json"), 1);
  nlohmann::json j = nlohmann::json::parse(out_);
  EXPECT_EQ(j["verdict"], "inconclusive");
  EXPECT_EQ(j["hints"].size(), 1u);
}

TEST_F(CliCheck, BinaryCapturesExitOneWhenReadAndTwoWhenRefused) {
  // real LeCroy captures (tests/eye/data/real/SOURCES.md): a single record is read and is no
  // daisy-chain record; a sequence of 20 segments is refused at its field's byte offset
  const std::string real = ISOLINK_EYE_DATA "/real/";
  EXPECT_EQ(run("check '" + real + "lecroy_4.trc' --json"), 1);
  nlohmann::json j = nlohmann::json::parse(out_);
  EXPECT_EQ(j["verdict"], "inconclusive");
  EXPECT_EQ(j["input"]["layouts"][0], "lecroy trc");
  EXPECT_EQ(j["input"]["samples"], 502);
  EXPECT_EQ(run("check '" + real + "lecroy_3.trc'"), 2);
  EXPECT_NE(err_.find("lecroy_3.trc:byte 155: error: SUBARRAY_COUNT 20: a sequence of 20 "
                      "segments; isolink reads one record: save a single segment"),
            std::string::npos)
      << err_;
  EXPECT_TRUE(out_.empty()) << out_;
}

}  // namespace
