// Running the isolink executable from a test: the one helper of tests/cli (exit status, stdout,
// stderr), with each test's own folder so that ctest -j2 never shares a file between processes.
//
//   isolink::testing::CliResult r = isolink::testing::run_isolink(ISOLINK_BINARY, "run x.yaml");
//   EXPECT_EQ(r.code, 0) << r.err;
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace isolink::testing {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The running test's own folder under TempDir (suite, name and process id), created.
inline std::string test_dir() {
  const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(t->test_suite_name()) + "_" + t->name();
  for (char& c : name)
    if (c == '/') c = '_';
  const std::string dir = ::testing::TempDir() + "/cli_" + name + "_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  return dir;
}

// `binary args` through the shell (args may hold quotes and redirections of their own);
// stdout and stderr are captured in files of the test's folder, named by `tag`.
inline CliResult run_isolink(const std::string& binary, const std::string& args,
                             const std::string& tag = "run") {
  const std::string base = test_dir() + "/" + tag;
  const std::string cmd =
      binary + " " + args + " >" + base + "_stdout.txt 2>" + base + "_stderr.txt";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(base + "_stdout.txt"),
          slurp(base + "_stderr.txt")};
}

}  // namespace isolink::testing
