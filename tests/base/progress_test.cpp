// The progress line for long work (base/progress.h): redrawn in place on a terminal at most every
// interval, silent on a pipe unless asked, notes never lost, nothing left once finished.
#include "base/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace isolink {
namespace {

// Everything written to a temporary FILE*.
std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  for (int c; (c = std::fgetc(f)) != EOF;) s.push_back(static_cast<char>(c));
  return s;
}

TEST(Progress, DurationText) {
  EXPECT_EQ(duration_text(12.34), "12.3 s");
  EXPECT_EQ(duration_text(245), "4 min 05 s");
  EXPECT_EQ(duration_text(3720), "1 h 02 min");
  EXPECT_EQ(duration_text(-1), "?");
  EXPECT_EQ(duration_text(1.0 / 0.0), "?");
}

TEST(Progress, TerminalRedrawsInPlaceAtMostEveryIntervalAndClearsAtTheEnd) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  double t = 100.0;
  {
    ProgressLine line({.label = "run", .out = f, .terminal = 1, .clock = [&] { return t; }});
    ASSERT_TRUE(line.active());
    line.show("a");  // first: drawn at once
    t += 0.2;
    line.show("b");  // 0.2 s later: kept for later
    t += 0.4;
    line.show("c");  // 0.6 s after the first draw: drawn
    line.note("warning: x");
    EXPECT_NEAR(line.elapsed(), 0.6, 1e-12);
    line.finish();
  }
  // The note clears the line, prints itself whole, and redraws the latest text.
  EXPECT_EQ(contents(f), "\r\033[Krun: a\r\033[Krun: c\r\033[Kwarning: x\n\r\033[Krun: c\r\033[K");
  std::fclose(f);
}

TEST(Progress, PipeIsSilentUnlessAnIntervalIsGivenAndQuietIsSilent) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  double t = 0.0;
  {
    ProgressLine silent({.label = "run", .out = f, .terminal = 0, .clock = [&] { return t; }});
    EXPECT_FALSE(silent.active());
    silent.show("a");
    silent.finish();
    ProgressLine quiet(
        {.label = "run", .enabled = false, .out = f, .terminal = 1, .clock = [&] { return t; }});
    EXPECT_FALSE(quiet.active());
    quiet.show("a");
  }
  EXPECT_EQ(contents(f), "");
  {
    ProgressLine logged(
        {.label = "sweep", .pipe_interval = 5.0, .out = f, .terminal = 0, .clock = [&] {
           return t;
         }});
    logged.show("1/3");
    t = 4.9;
    logged.show("2/3");  // within 5 s of the last line: not printed
    t = 5.0;
    logged.done("3/3, done");  // the last word is always printed
  }
  EXPECT_EQ(contents(f), "sweep: 1/3\nsweep: 3/3, done\n");
  std::fclose(f);
}

TEST(Progress, DoneKeepsTheLastLineOnATerminal) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressLine line({.label = "sweep", .out = f, .terminal = 1, .clock = [] { return 0.0; }});
    line.show("1/2");
    line.done("2/2, done");
  }  // the destructor's finish() has nothing left to clear
  EXPECT_EQ(contents(f), "\r\033[Ksweep: 1/2\r\033[Ksweep: 2/2, done\n");
  std::fclose(f);
}

}  // namespace
}  // namespace isolink
