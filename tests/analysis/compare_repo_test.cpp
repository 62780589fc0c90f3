// `isolink compare` through the binary on every capture and every link spec in the repository:
// - every example and bench link spec (netlists/examples, bench/links): a synthetic capture of
//   the link as designed is a "match" (exit 0), one of the link with its driver-side series
//   resistor five times its design value (a wrong part) a "mismatch" (exit 1), never exit 2 or a
//   crash. Two of them (bq79606a_xfmr_10m, capdualchoke_10m) swing beyond the scope model's
//   +/-5 V range: their captures clip, and match only because compare finds the rails;
// - every scope file kept as test data (tests/eye/data/real, tests/catalogue, the fuzz corpus),
//   none of them a daisy-chain record, paired with netlists/examples/cap_2m.yaml
//   (analysis/README.md, section Compare, says so): compare refuses exactly the files `isolink
//   check` refuses (exit 2 both, bad input), and on every other one answers 0 or 1 with a verdict
//   that is not "match", never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/compare.h"
#include "base/file_io.h"
#include "tests/analysis/synthetic_capture.h"
#include "tests/cli/run_isolink.h"

namespace isolink::analysis {
namespace {

namespace fs = std::filesystem;
const std::string kSource = ISOLINK_SOURCE_DIR;

// The link specs of the examples and the benches (sweep and pack files are not link specs).
std::vector<std::string> link_specs() {
  std::vector<std::string> out;
  for (const char* dir : {"netlists/examples", "bench/links"})
    for (const auto& e : fs::directory_iterator(kSource + "/" + dir)) {
      if (e.path().extension() != ".yaml") continue;
      StatusOr<std::string> text = read_input_file(e.path().string());
      StatusOr<link::LinkSpec> spec =
          text ? link::read_link_spec_text(*text, e.path().string()) : Status::Error("");
      // A nonlinear link (TVS parts, pin clamps) has no edge response: compare refuses it
      // (CompareOnTheRepo.NonlinearLinkIsRefusedWithTheReason).
      if (!spec || !link::nonlinear_parts(*spec).empty()) continue;
      out.push_back(fs::relative(e.path(), kSource).string());
    }
  std::sort(out.begin(), out.end());
  return out;
}

const std::vector<std::string> kLinkSpecs = {"bench/links/bridge_xfmr_12m_two_frames.yaml",
                                             "bench/links/xfmr_12m_two_frames.yaml",
                                             "bench/links/xfmr_20m.yaml",
                                             "bench/links/xfmr_40m.yaml",
                                             "netlists/examples/bq79606a_cap_2m.yaml",
                                             "netlists/examples/bq79606a_same_pcb.yaml",
                                             "netlists/examples/bq79606a_xfmr_10m.yaml",
                                             "netlists/examples/cap_2m.yaml",
                                             "netlists/examples/capchoke_5m.yaml",
                                             "netlists/examples/capdualchoke_10m.yaml",
                                             "netlists/examples/hybrid_xfmr_cap_12m.yaml",
                                             "netlists/examples/same_pcb.yaml",
                                             "netlists/examples/startup_16.yaml",
                                             "netlists/examples/transformer_15m.yaml"};
TEST(CompareOnTheRepo, TheListOfLinkSpecsIsComplete) {
  EXPECT_EQ(link_specs(), kLinkSpecs) << "a link spec was added or removed: update kLinkSpecs";
}

TEST(CompareOnTheRepo, NonlinearLinkIsRefusedWithTheReason) {
  const std::string spec = kSource + "/netlists/examples/bq79606a_tvs_2m.yaml";
  // Any capture will do: the spec is refused before the capture is compared with it.
  const std::string capture = testing::test_dir() + "/any.csv";
  std::ofstream(capture) << "time,v\n0,0\n1e-9,0\n2e-9,0\n";
  testing::CliResult r =
      testing::run_isolink(ISOLINK_BINARY, "compare " + capture + " " + spec, "nonlinear");
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("needs a linear link"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("TVS PESD2CAN"), std::string::npos) << r.err;
}

class CompareLinkSpecs : public ::testing::TestWithParam<std::string> {};

// The driver-side series resistor of the design: the spec's, else the board preset's.
double tx_series_r(const std::string& spec_path, const std::string& text) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(text, spec_path);
  static const link::PartLibrary parts = *link::PartLibrary::load({});
  StatusOr<DesignValue> d = design_value(*spec, parts, "tx.series_r");
  return d ? d->value : 0.0;
}

TEST_P(CompareLinkSpecs, NominalMatchesAndAWrongSeriesResistorDoesNot) {
  const std::string spec = kSource + "/" + GetParam();
  StatusOr<std::string> text = read_input_file(spec);
  ASSERT_TRUE(text.ok());
  const std::string dir = testing::test_dir();
  testing::ScopeModel scope;  // 2.5 GS/s, 300 MHz, 10 mV, 8 bits, trigger 3.3 us
  const std::string nominal = dir + "/nominal.csv", wrong = dir + "/wrong.csv";
  Status s = testing::write_synthetic_capture(*text, spec, {}, scope, nominal);
  ASSERT_TRUE(s.ok()) << s.message();
  const double r_series = tx_series_r(spec, *text);
  ASSERT_GT(r_series, 0);
  s = testing::write_synthetic_capture(
      *text, spec, {{"tx.series_r", std::to_string(5 * r_series), true}}, scope, wrong);
  ASSERT_TRUE(s.ok()) << s.message();
  testing::CliResult r =
      testing::run_isolink(ISOLINK_BINARY, "compare " + nominal + " " + spec + " --json", "nom");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["verdict"], "match");
  EXPECT_TRUE(j["findings"].empty());
  r = testing::run_isolink(ISOLINK_BINARY, "compare " + wrong + " " + spec + " --json", "wrong");
  ASSERT_EQ(r.code, 1) << r.out << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["verdict"], "mismatch");
  EXPECT_GT(j["residual"]["rms_v"].get<double>(), j["noise"]["threshold_rms_v"].get<double>());
}

INSTANTIATE_TEST_SUITE_P(Repo, CompareLinkSpecs, ::testing::ValuesIn(kLinkSpecs),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string s = fs::path(i.param).stem().string();
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s;
                         });

// compare's commands are the check's: the same three fields as `isolink check --json` on the same
// capture, and TI's stack-write example (domain.md: stack write 0x0100 = 02 B7 78 BC, CRC 0A35)
// that the spec sends is among them.
TEST(CompareOnTheRepo, CommandsAreThoseOfCheck) {
  const std::string spec = kSource + "/netlists/examples/cap_2m.yaml";
  StatusOr<std::string> text = read_input_file(spec);
  ASSERT_TRUE(text.ok());
  const std::string cap = testing::test_dir() + "/nominal.csv";
  Status s = testing::write_synthetic_capture(*text, spec, {}, {}, cap);
  ASSERT_TRUE(s.ok()) << s.message();
  const testing::CliResult c = testing::run_isolink(ISOLINK_BINARY, "check " + cap + " --json");
  const testing::CliResult r =
      testing::run_isolink(ISOLINK_BINARY, "compare " + cap + " " + spec + " --json", "cmp");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json cj = nlohmann::json::parse(c.out), rj = nlohmann::json::parse(r.out);
  for (const char* k : {"commands", "commands_omitted", "commands_note"})
    EXPECT_EQ(rj[k], cj[k]) << k;
  ASSERT_EQ(rj["commands"].size(), 1u);
  EXPECT_EQ(rj["commands"][0]["text"], "stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok");
  EXPECT_EQ(rj["commands"][0]["crc_ok"], true);
  // The summary lists it too, as check's does.
  const testing::CliResult t =
      testing::run_isolink(ISOLINK_BINARY, "compare " + cap + " " + spec, "txt");
  EXPECT_NE(t.out.find("stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok"), std::string::npos);
}

// Every scope file kept as test data.
std::vector<std::string> scope_files() {
  std::vector<std::string> out;
  for (const char* dir : {"tests/eye/data/real", "tests/catalogue", "tests/fuzz/corpus"})
    for (const auto& e : fs::recursive_directory_iterator(kSource + "/" + dir)) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (e.is_regular_file() &&
          (ext == ".csv" || ext == ".bin" || ext == ".isf" || ext == ".wfm" || ext == ".trc"))
        out.push_back(e.path().string());
    }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CompareOnTheRepo, EveryScopeFileIsAnsweredAsCheckAnswersIt) {
  const std::vector<std::string> files = scope_files();
  ASSERT_GE(files.size(), 25u);
  const std::string spec = kSource + "/netlists/examples/cap_2m.yaml";
  int refused = 0;
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    const testing::CliResult c = testing::run_isolink(ISOLINK_BINARY, "check " + f, "check");
    const testing::CliResult r =
        testing::run_isolink(ISOLINK_BINARY, "compare " + f + " " + spec + " --json", "compare");
    ASSERT_NE(c.code, -1) << "check crashed";
    ASSERT_NE(r.code, -1) << "compare crashed";
    if (c.code == 2) {  // bad input for check is bad input for compare, with the file named
      ++refused;
      EXPECT_EQ(r.code, 2) << r.out;
      EXPECT_NE(r.err.find(fs::path(f).filename().string()), std::string::npos) << r.err;
      continue;
    }
    ASSERT_TRUE(r.code == 0 || r.code == 1) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_NE(j["verdict"], "match");  // no file here is a record of the cap_2m link
    EXPECT_EQ(r.code, 1);
  }
  EXPECT_GT(refused, 0);
  EXPECT_LT(refused, static_cast<int>(files.size()));
}

}  // namespace
}  // namespace isolink::analysis
