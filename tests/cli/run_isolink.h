// Running the isolink executable from a test: the one helper of tests/cli (exit status, stdout,
// stderr), with each test's own folder so that ctest -j2 never shares a file between processes.
//
//   isolink::testing::CliResult r = isolink::testing::run_isolink(ISOLINK_BINARY, "run x.yaml");
//   EXPECT_EQ(r.code, 0) << r.err;
#pragma once

#include <gtest/gtest.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace isolink::testing {

struct CliResult {
  int code = -1;
  std::string out, err;
  std::string no_terminal;  // run_isolink_on_terminal: why no pseudo-terminal could be opened
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

// The same with stderr on a pseudo-terminal (what a user at a terminal sees: progress lines);
// stdout goes to a file of the test's folder. err holds everything written to the terminal.
inline CliResult run_isolink_on_terminal(const std::string& binary, const std::string& args,
                                         const std::string& tag = "tty") {
  const std::string base = test_dir() + "/" + tag;
  const std::string cmd = binary + " " + args + " >" + base + "_stdout.txt";
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) {  // no /dev/ptmx or devpts (a bare chroot): the caller skips, saying why
    CliResult r;
    r.no_terminal = std::string("forkpty: ") + std::strerror(errno);
    return r;
  }
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  CliResult r;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(master, buf, sizeof buf);
    if (n > 0) {
      r.err.append(buf, static_cast<size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;  // EIO once the child side is closed
  }
  close(master);
  int status = 0;
  waitpid(pid, &status, 0);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(base + "_stdout.txt");
  return r;
}

}  // namespace isolink::testing
