// Progress on stderr for long work (issue 15): drawn in place when stderr is a terminal, cleared
// when the work ends, absent on a pipe and with --quiet.
#include <gtest/gtest.h>

#include <string>

#include "run_isolink.h"

namespace isolink {
namespace {

using testing::run_isolink;
using testing::run_isolink_on_terminal;

const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;

// The 2 m capacitor link runs its transient over about 7,000 accepted steps, so the engine
// reports progress (every 1024 steps); the first report is drawn at once.
std::string sim_args() {
  return "sim " + kExamples + "/cap_link_2m.cir -p 'v(rxp,rxn)' --engine transient";
}

TEST(Progress, SimDrawsItsProgressOnATerminalAndClearsIt) {
  const testing::CliResult r = run_isolink_on_terminal(kBinary, sim_args());
  if (!r.no_terminal.empty()) GTEST_SKIP() << "no pseudo-terminal here (" << r.no_terminal << ")";
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string draw = "\r\033[Kisolink sim: transient ";
  const size_t first = r.err.find(draw);
  ASSERT_NE(first, std::string::npos) << r.err;
  // A percentage follows, and the line is erased before the statistics are printed.
  const size_t pct = r.err.find(" %", first);
  ASSERT_NE(pct, std::string::npos);
  const int value = std::stoi(r.err.substr(first + draw.size(), pct - first - draw.size()));
  EXPECT_GE(value, 0);
  EXPECT_LE(value, 100);
  const size_t last = r.err.rfind(draw);
  const size_t cleared = r.err.find("\r\033[K", last + 1);
  ASSERT_NE(cleared, std::string::npos) << "the progress line is left on the terminal";
  EXPECT_EQ(r.err.find("isolink sim: transient", cleared), std::string::npos);
  // The CSV went to stdout, whole: a header and rows.
  EXPECT_EQ(r.out.rfind("time,", 0), 0u) << r.out.substr(0, 80);
}

TEST(Progress, NoProgressOnAPipeOrWithQuiet) {
  const testing::CliResult piped = run_isolink(kBinary, sim_args());
  ASSERT_EQ(piped.code, 0) << piped.err;
  EXPECT_EQ(piped.err.find('\r'), std::string::npos) << piped.err;
  EXPECT_EQ(piped.err.find("isolink sim: transient"), std::string::npos) << piped.err;
  const testing::CliResult quiet = run_isolink_on_terminal(kBinary, sim_args() + " -q");
  if (!quiet.no_terminal.empty())
    GTEST_SKIP() << "the pipe case passed; no pseudo-terminal here for -q (" << quiet.no_terminal
                 << ")";
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("isolink sim: transient"), std::string::npos) << quiet.err;
}

}  // namespace
}  // namespace isolink
