// `isolink sim` end to end: the CSV contract, exit codes, and nothing written on bad input.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "run_isolink.h"

namespace {

namespace fs = std::filesystem;
const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;
const std::string kData = ISOLINK_TEST_DATA_DIR;

using Result = isolink::testing::CliResult;
using isolink::testing::test_dir;

Result run(const std::string& args) {
  return isolink::testing::run_isolink(kBinary, args);
}

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = test_dir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(SimCommand, WritesHeaderAndStrictlyIncreasingTimes) {
  const std::string out = test_dir() + "/wave.csv";
  fs::remove(out);
  Result r =
      run("sim " + kData + "/floating_cable.cir --probe 'v(rxp,rxn)' --probe 'v(txp)' -o " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "time,\"v(rxp,rxn)\",v(txp)");  // RFC 4180: the comma is quoted
  double prev = -1;
  int rows = 0;
  while (std::getline(in, line)) {
    double t = std::stod(line.substr(0, line.find(',')));
    EXPECT_GT(t, prev);
    prev = t;
    ++rows;
  }
  EXPECT_GT(rows, 100);
  EXPECT_NEAR(prev, 3e-6, 1e-15);
  EXPECT_NE(r.err.find("tied to it with 1e-12 S"), std::string::npos) << r.err;  // floating cable
}

TEST(SimCommand, StepResamplesOnAUniformGrid) {
  const std::string out = test_dir() + "/wave_step.csv";
  Result r = run("sim " + kExamples + "/cap_link_2m.cir -p 'v(rxp,rxn)' --step 10n -q -o " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  int rows = 0;
  double t = 0;
  while (std::getline(in, line)) {
    t = std::stod(line.substr(0, line.find(',')));
    EXPECT_NEAR(t, rows * 10e-9, 1e-15);
    ++rows;
  }
  EXPECT_EQ(rows, 301);  // 0 .. 3 us
}

TEST(SimCommand, BadNetlistExitsTwoAndWritesNothing) {
  const std::string out = test_dir() + "/never.csv";
  fs::remove(out);
  std::string path =
      write_temp("bad_r.cir", "bad value\nV1 a 0 1\nR1 a 0 -5\n.tran 1n 10n\n.end\n");
  Result r = run("sim " + path + " -p 'v(a)' -o " + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad_r.cir:3:8: error: resistance of r1 must be positive, got -5"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(" R1 a 0 -5\n        ^"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(SimCommand, SingularCircuitNamesTheNodes) {
  std::string path =
      write_temp("loop.cir", "loop\nV1 a 0 1\nV2 a 0 2\nR1 a 0 1\n.tran 1n 10n\n.end\n");
  Result r = run("sim " + path + " -p 'v(a)'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("loop.cir:3:1: error: singular circuit: voltage sources / inductors form a "
                       "loop (v1, v2) through nodes a and 0"),
            std::string::npos)
      << r.err;
}

TEST(SimCommand, UnknownProbeAndMissingTranAreErrors) {
  std::string path =
      write_temp("rc.cir", "rc\nV1 a 0 PULSE(0 1 0 1n)\nR1 a b 1k\nC1 b 0 1n\n.end\n");
  Result r = run("sim " + path + " -p 'v(zz)' --tstop 1u");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no node named 'zz'"), std::string::npos) << r.err;
  r = run("sim " + path + " -p 'v(b)'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no .tran card"), std::string::npos) << r.err;
  EXPECT_EQ(run("sim " + path + " -p 'v(b)' --tstop 1u -o " + test_dir() + "/rc.csv").code, 0);
}

TEST(SimCommand, UnknownOptionIsWarnedAndIgnored) {
  std::string path = write_temp("opt.cir",
                                "opt\nV1 a 0 1\nR1 a 0 1k\n.options foo=3 reltol=1e-4\n"
                                ".tran 1n 10n\n.end\n");
  Result r = run("sim " + path + " -p 'v(a)' -o " + test_dir() + "/opt.csv");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("opt.cir:4:10: warning: option 'foo' is not used by isolink; ignored"),
            std::string::npos)
      << r.err;
}

// Issue 28: auto never trades accuracy silently. Each run states its engine, why auto took it,
// how long it took and the accuracy that engine promises, with the figures of its options.
TEST(SimCommand, StatesTheEngineWhyHowLongAndTheAccuracyItPromises) {
  const std::string sin = write_temp("sin_rc.cir",
                                     "sin\nV1 in 0 SIN(0 1 1meg)\nR1 in a 1k\nC1 a 0 1n\n"
                                     ".tran 10n 5u\n.end\n");
  Result r = run("sim " + sin + " -p 'v(a)' -o /dev/null");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("transient engine, not LTI: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("source 'v1' is not a continuous piecewise-linear"), std::string::npos);
  EXPECT_NE(r.err.find("(the LTI attempt took 0.0"), std::string::npos) << r.err;
  // auto's fallback checks itself (analysis/transient_check.h): reltol 1e-3 and TSTEP 10 ns, then
  // 1e-4 and 5 ns agree within 5 mV (the 1 V sine's 0.1 % is 1 mV, less than 5 mV).
  EXPECT_NE(r.err.find("accuracy: transient, checked by tightening: reltol "
                       "0.001 -> 0.0001 and largest step 1e-08 -> 5e-09 s in 2 runs"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("within its allowance of 5 m (5 mV"), std::string::npos) << r.err;
  // --engine transient at the defaults checks itself as auto's fallback does; with a reltol of
  // the user's (--reltol, or .options reltol in the netlist) it runs once, as asked.
  r = run("sim " + sin + " -p 'v(a)' -o /dev/null --engine transient");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("accuracy: transient, checked by tightening: reltol 0.001 -> 0.0001"),
            std::string::npos)
      << r.err;
  const std::string sin_tol = write_temp("sin_rc_tol.cir",
                                         "sin\nV1 in 0 SIN(0 1 1meg)\nR1 in a 1k\nC1 a 0 1n\n"
                                         ".options reltol=1e-3\n.tran 10n 5u\n.end\n");
  r = run("sim " + sin_tol + " -p 'v(a)' -o /dev/null --engine transient");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("accuracy: transient: local truncation error per step within trtol x "
                       "reltol = 0.0001 of each unknown's peak (reltol 0.001)"),
            std::string::npos)
      << r.err;
  r = run("sim " + sin + " -p 'v(a)' -o /dev/null --reltol 1e-5");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("= 1e-06 of each unknown's peak (reltol 1e-05)"), std::string::npos)
      << r.err;
  // The reduced model: its bound per volt of edge, 2e-5 ln(3 GHz / 1 kHz) / pi = 0.095 mV.
  const std::string rc =
      write_temp("pwl_rc.cir",
                 "rc\nV1 in 0 PWL(0 0 1u 0 1.01u 1)\nR1 in a 1k\nC1 a 0 1n\n.tran 10n 5u\n.end\n");
  r = run("sim " + rc + " -p 'v(a)' -o /dev/null");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("LTI engine, reduced model"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("accuracy: reduced model within"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("within 0.095 mV per volt of edge (0.47 mV for 5 V)"), std::string::npos)
      << r.err;
}

}  // namespace

// Issue 41: a circuit with a diode runs on the port model (solver/port_model.h), and the
// statistics say so; where it does not apply (.ic) auto runs the full transient and says why;
// --engine port on a circuit without a diode is an error before any run.
TEST(SimCommand, DiodeCircuitsRunOnThePortModelOrSayWhyNot) {
  const std::string clip = write_temp("clip.cir",
                                      "clip\nV1 in 0 SIN(0 5 1meg)\nR1 in out 1k\nC1 out 0 10p\n"
                                      "D1 out 0 dm\n.model dm D(is=1e-14 cjo=2p)\n"
                                      ".tran 10n 2u\n.end\n");
  Result r = run("sim " + clip + " -p 'v(out)' -o /dev/null");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("port model engine (the circuit has diodes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 ports"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("accuracy: port model: "), std::string::npos) << r.err;
  EXPECT_EQ(run("sim " + clip + " -p 'v(out)' --engine port -o /dev/null").code, 0);

  const std::string held = write_temp("clip_ic.cir",
                                      "clip\nV1 in 0 SIN(0 5 1meg)\nR1 in out 1k\nC1 out 0 10p\n"
                                      "D1 out 0 dm\n.model dm D(is=1e-14 cjo=2p)\n.ic v(out)=0.1\n"
                                      ".tran 10n 2u\n.end\n");
  r = run("sim " + held + " -p 'v(out)' -o /dev/null");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("transient engine, because the port model did not apply: .ic"),
            std::string::npos)
      << r.err;
  r = run("sim " + held + " -p 'v(out)' --engine port -o /dev/null");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find(".ic / .tran uic"), std::string::npos) << r.err;

  const std::string rc = write_temp("rc_port.cir",
                                    "rc\nV1 a 0 PULSE(0 1 0 1n)\nR1 a b 1k\n"
                                    "C1 b 0 1n\n.tran 1n 1u\n.end\n");
  r = run("sim " + rc + " -p 'v(b)' --engine port -o /dev/null");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("no nonlinear element"), std::string::npos) << r.err;
}
