// The options several commands share (cli/common_options.h): one declaration each, so every
// command's --help shows the same line, refuses the same bad values and passes the value on.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/simulate.h"
#include "run_isolink.h"

namespace {

const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;
const std::string kData = ISOLINK_TEST_DATA_DIR;

using isolink::testing::CliResult;
using isolink::testing::run_isolink;
using isolink::testing::test_dir;

// The entry of `isolink CMD --help` that declares option: its line, and the description CLI11
// puts on the next line when the option's name column overflows; empty when there is none.
std::string help_line(const std::string& cmd, const std::string& option) {
  CliResult r = run_isolink(kBinary, cmd + " --help", "help_" + cmd);
  EXPECT_EQ(r.code, 0) << cmd << ": " << r.err;
  std::istringstream in(r.out);
  std::string entry;
  for (std::string line; std::getline(in, line);) {
    const size_t text = line.find_first_not_of(' ');
    if (!entry.empty()) {
      if (text == std::string::npos || text < 6 || line[text] == '-') break;
      entry += "\n" + line;
    } else if (line.rfind("  " + option + " ", 0) == 0) {
      entry = line;
    }
  }
  return entry;
}

// The commands that take each option, with arguments that would make them run.
const std::vector<std::string> kEngineCommands = {
    "run " + kExamples + "/cap_2m.yaml", "sweep " + kExamples + "/sweep_cap_length.yaml",
    "sim " + kData + "/floating_cable.cir -p 'v(rxp,rxn)'"};
const std::vector<std::string> kPartsCommands = {"run",   "worst",        "sweep", "pack",
                                                 "noise", "export-spice", "parts", "compare"};

std::string first_word(const std::string& s) {
  return s.substr(0, s.find(' '));
}

TEST(EngineOption, EveryCommandShowsTheSameHelpWithTheEnginesOwnChoices) {
  std::string choices;  // CLI11's IsMember writes the set as {a,b,c}
  for (isolink::analysis::Engine e : isolink::analysis::kEngines)
    choices += (choices.empty() ? "{" : ",") + std::string(isolink::analysis::engine_name(e));
  choices += "}";
  const std::string first = help_line(first_word(kEngineCommands.front()), "--engine");
  ASSERT_NE(first, "");
  EXPECT_NE(first.find(choices), std::string::npos) << first;
  for (isolink::analysis::Engine e : isolink::analysis::kEngines)
    EXPECT_NE(first.find(isolink::analysis::engine_summary(e)), std::string::npos) << first;
  for (const std::string& cmd : kEngineCommands)
    EXPECT_EQ(help_line(first_word(cmd), "--engine"), first) << cmd;
}

TEST(EngineOption, EveryCommandRefusesAnUnknownEngineBeforeRunning) {
  for (const std::string& cmd : kEngineCommands) {
    const std::string out = test_dir() + "/out_" + first_word(cmd);
    CliResult r = run_isolink(kBinary, cmd + " --engine bogus -o " + out, "bogus");
    EXPECT_EQ(r.code, 2) << cmd;
    EXPECT_NE(r.err.find("--engine: bogus not in {auto,lti,port,transient}"), std::string::npos)
        << cmd << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << cmd << " wrote " << out;
  }
}

TEST(EngineOption, TheChosenEngineRuns) {
  // floating_cable.cir is LTI (linear, PULSE sources): both engines can run it, and isolink sim
  // names the one that did on stderr.
  const std::string sim = "sim " + kData + "/floating_cable.cir -p 'v(rxp,rxn)' -o /dev/null";
  CliResult lti = run_isolink(kBinary, sim + " --engine lti", "lti");
  ASSERT_EQ(lti.code, 0) << lti.err;
  EXPECT_NE(lti.err.find("isolink sim: LTI engine"), std::string::npos) << lti.err;
  CliResult tr = run_isolink(kBinary, sim + " --engine transient", "transient");
  ASSERT_EQ(tr.code, 0) << tr.err;
  EXPECT_EQ(tr.err.find("LTI engine"), std::string::npos) << tr.err;
  EXPECT_NE(tr.err.find("steps accepted"), std::string::npos) << tr.err;
}

TEST(PartsOption, EveryCommandShowsTheSameHelp) {
  const std::string first = help_line(kPartsCommands.front(), "--parts");
  ASSERT_NE(first, "");
  for (const std::string& cmd : kPartsCommands) EXPECT_EQ(help_line(cmd, "--parts"), first) << cmd;
}

TEST(PartsOption, TakesOnePathSoTheSpecAfterItIsStillTheSpec) {
  // `--parts DIR SPEC`: were --parts to take every following word, SPEC would be read as a
  // second part folder and the command would miss its spec.
  const std::string dir = test_dir() + "/my_parts";
  std::filesystem::create_directories(dir);
  const std::string out = test_dir() + "/cap_2m.cir";
  CliResult r = run_isolink(
      kBinary, "export-spice --parts " + dir + " " + kExamples + "/cap_2m.yaml -o " + out,
      "export");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out));
}

TEST(DirectionOption, RunAndWorstShowTheSameHelpAndRefuseOtherValues) {
  const std::string first = help_line("run", "--direction");
  ASSERT_NE(first, "");
  EXPECT_NE(first.find("{down,up,both}"), std::string::npos) << first;
  EXPECT_EQ(help_line("worst", "--direction"), first);
  for (const std::string cmd : {"run", "worst"}) {
    CliResult r = run_isolink(
        kBinary,
        cmd + " " + kExamples + "/cap_2m.yaml --direction sideways -o " + test_dir() + "/x",
        "sideways");
    EXPECT_EQ(r.code, 2) << cmd;
    EXPECT_NE(r.err.find("--direction: sideways not in {down,up,both}"), std::string::npos)
        << cmd << ": " << r.err;
  }
}

TEST(DirectionOption, ReplacesTheSpecsDirections) {
  // cap_2m.yaml's stimulus runs both directions; --direction up leaves only the up one.
  const std::string out = test_dir() + "/up";
  CliResult r = run_isolink(kBinary,
                            "run " + kExamples +
                                "/cap_2m.yaml --direction up --no-worst "
                                "--no-images -q -o " +
                                out,
                            "up");
  ASSERT_LE(r.code, 1) << r.err;
  const std::string json = isolink::testing::slurp(out + "/report.json");
  EXPECT_NE(json.find("\"direction\": \"up\""), std::string::npos) << json.substr(0, 400);
  EXPECT_EQ(json.find("\"direction\": \"down\""), std::string::npos);
}

}  // namespace
