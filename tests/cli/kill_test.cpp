// kill -9 at moments spread over a run (issue 15): `isolink run` leaves either the previous report
// or the new one, whole, never a mix and never a half-written file under a final name, and no
// temporary file that looks like a result; `isolink sweep --resume` after kills finishes with
// every point exactly once.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "run_isolink.h"

namespace {

namespace fs = std::filesystem;
const std::string kBinary = ISOLINK_BINARY;
const std::string kExamples = ISOLINK_EXAMPLES_DIR;

using isolink::testing::slurp;
using isolink::testing::test_dir;

pid_t spawn(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(kBinary.c_str()));
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1);
    ::dup2(devnull, 2);
    ::execv(kBinary.c_str(), argv.data());
    ::_exit(127);
  }
  return pid;
}

// Runs to the end; the exit status and the wall time.
std::pair<int, double> run_to_end(const std::vector<std::string>& args) {
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  ::waitpid(spawn(args), &status, 0);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
}

// Starts the command and kills it with SIGKILL after `seconds` (if it is still running).
void kill_after(const std::vector<std::string>& args, double seconds) {
  const pid_t pid = spawn(args);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  ::kill(pid, SIGKILL);
  ::waitpid(pid, nullptr, 0);
}

// Entries of dir that do not start with '.' (hidden temporaries of a killed run are allowed).
std::vector<std::string> visible(const std::string& dir) {
  std::vector<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name[0] != '.') n.push_back(name);
  }
  std::sort(n.begin(), n.end());
  return n;
}

const std::vector<std::string> kBundle = {"eye.png",   "report.html", "report.json",
                                          "report.md", "wave.csv",    "wave.png"};

TEST(KillDuringRun, ReportIsWholeOldOrWholeNew) {
  const std::string dir = test_dir(), out = dir + "/report";
  // --no-worst: the bundle of the spec's own traffic is what this test kills and checks.
  const std::vector<std::string> args = {"run",       kExamples + "/cap_2m.yaml", "-o", out, "-q",
                                         "--no-worst"};
  const auto [code, seconds] = run_to_end(args);
  ASSERT_EQ(code, 0);
  ASSERT_EQ(visible(out), kBundle);
  // Kill at 10 %, 30 %, ... 90 % of a full run, then once more at 99 % (the rename window).
  for (double f : {0.1, 0.3, 0.5, 0.7, 0.9, 0.99}) {
    kill_after(args, f * seconds);
    SCOPED_TRACE(::testing::Message() << "killed at " << f * seconds << " s");
    EXPECT_EQ(visible(dir), std::vector<std::string>{"report"});
    EXPECT_EQ(visible(out), kBundle);  // never a mix: the folder is swapped whole
    for (const std::string& f2 : visible(out)) EXPECT_EQ(f2.find(".tmp"), std::string::npos);
    const nlohmann::json j = nlohmann::json::parse(slurp(out + "/report.json"), nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << "report.json is not whole";
    const std::string csv = slurp(out + "/wave.csv");
    EXPECT_TRUE(!csv.empty() && csv.back() == '\n') << "wave.csv is cut short";
  }
  // A complete run afterwards removes what the killed runs left.
  ASSERT_EQ(run_to_end(args).first, 0);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename(), "report") << "left behind: " << e.path();
}

TEST(KillDuringSweep, ResumeRunsEveryPointExactlyOnce) {
  const std::string dir = test_dir(), out = dir + "/sweep";
  {
    std::ofstream(dir + "/sweep.yaml") << "base: " << kExamples << "/cap_2m.yaml\n"
                                       << "sweep:\n  cable.length: [1, 2, 3, 4]\n";
  }
  const std::vector<std::string> fresh = {"sweep", dir + "/sweep.yaml", "-o", out, "-j", "1", "-q"};
  std::vector<std::string> resume = fresh;
  resume.push_back("--resume");
  // The time of a whole sweep, measured on a copy.
  const auto [code, seconds] =
      run_to_end({"sweep", dir + "/sweep.yaml", "-o", dir + "/ref", "-j", "1", "-q"});
  ASSERT_EQ(code, 0);
  kill_after(fresh, 0.4 * seconds);
  kill_after(resume, 0.3 * seconds);
  ASSERT_EQ(run_to_end(resume).first, 0);
  std::istringstream rows(slurp(out + "/results.csv"));
  std::string line;
  std::getline(rows, line);
  EXPECT_EQ(line.rfind("point,", 0), 0u) << line;
  std::map<int, int> seen;
  while (std::getline(rows, line)) ++seen[std::stoi(line.substr(0, line.find(',')))];
  ASSERT_EQ(seen.size(), 4u);
  for (const auto& [point, n] : seen) EXPECT_EQ(n, 1) << "point " << point;
  // The same verdicts as the sweep that was never killed.
  const nlohmann::json got = nlohmann::json::parse(slurp(out + "/summary.json"));
  const nlohmann::json want = nlohmann::json::parse(slurp(dir + "/ref/summary.json"));
  for (const char* k : {"points", "done", "pass", "fail", "error"}) EXPECT_EQ(got[k], want[k]) << k;
  EXPECT_EQ(got["done"], 4);
}

}  // namespace
