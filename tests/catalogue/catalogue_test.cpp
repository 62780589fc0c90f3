// The catalogue of bad and extreme inputs (issue 15): one folder per case under tests/catalogue/,
// each run through the real `isolink` binary and held to its expected exit code and message.
// The format is in tests/catalogue/README.md; adding a case is adding a folder.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
const std::string kCatalogue = ISOLINK_CATALOGUE_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> case_names() {
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(kCatalogue))
    if (e.is_directory() && fs::exists(e.path() / "cmd")) names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

struct Expect {
  int exit_code = -1;
  std::vector<std::string> stderr_has, stdout_has, stderr_lacks, files, no_files;
};

Expect read_expect(const fs::path& p) {
  Expect e;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t sp = line.find(' ');
    const std::string key = line.substr(0, sp);
    const std::string val = sp == std::string::npos ? "" : line.substr(sp + 1);
    if (key == "exit")
      e.exit_code = std::stoi(val);
    else if (key == "stderr")
      e.stderr_has.push_back(val);
    else if (key == "stdout")
      e.stdout_has.push_back(val);
    else if (key == "stderr-lacks")
      e.stderr_lacks.push_back(val);
    else if (key == "file")
      e.files.push_back(val);
    else if (key == "no-file")
      e.no_files.push_back(val);
    else
      ADD_FAILURE() << p << ": unknown expectation '" << key << "'";
  }
  return e;
}

class Catalogue : public ::testing::TestWithParam<std::string> {};

TEST_P(Catalogue, Case) {
  const fs::path dir = fs::path(kCatalogue) / GetParam();
  const Expect want = read_expect(dir / "expect");
  ASSERT_GE(want.exit_code, 0) << dir << "/expect has no 'exit N' line";
  // A scratch folder of its own (the command runs there; ctest -j2 runs cases at once).
  const fs::path scratch =
      fs::path(::testing::TempDir()) / ("catalogue_" + GetParam() + "_" + std::to_string(getpid()));
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  std::string cmd = slurp(dir / "cmd");
  while (!cmd.empty() && (cmd.back() == '\n' || cmd.back() == '\r')) cmd.pop_back();
  // 60 s is far above any case (each takes a few seconds at most): a timeout is a hang. The
  // sanitizer build (-O1, ASan + UBSan) runs Eigen's loops 15-20 times slower (the touchstone
  // case's fit: 2.4 s of CPU, 39 s there), so it allows 300 s.
  const std::string shell = "cd '" + scratch.string() + "' && ISOLINK='" ISOLINK_BINARY "' CASE='" +
                            dir.string() + "' EXAMPLES='" ISOLINK_EXAMPLES_DIR "' timeout " +
                            std::to_string(ISOLINK_CASE_TIMEOUT_S) + " sh -c '" +
                            [&] {
                              std::string q;
                              for (char c : cmd)
                                q += c == '\'' ? std::string("'\\''") : std::string(1, c);
                              return q;
                            }() +
                            "' >stdout.txt 2>stderr.txt";
  const int status = std::system(shell.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << "the shell died: " << status;
  const int code = WEXITSTATUS(status);
  const std::string out = slurp(scratch / "stdout.txt"), err = slurp(scratch / "stderr.txt");
  EXPECT_NE(code, 124) << "timed out (a hang): " << cmd;
  EXPECT_LT(code, 128) << "killed by a signal (a crash): " << cmd << "\n" << err;
  EXPECT_EQ(err.find("runtime error:"), std::string::npos) << "UBSan:\n" << err;
  EXPECT_EQ(err.find("AddressSanitizer"), std::string::npos) << err;
  EXPECT_EQ(code, want.exit_code) << cmd << "\nstderr:\n" << err;
  for (const std::string& s : want.stderr_has)
    EXPECT_NE(err.find(s), std::string::npos) << "stderr lacks '" << s << "':\n" << err;
  for (const std::string& s : want.stderr_lacks)
    EXPECT_EQ(err.find(s), std::string::npos) << "stderr has '" << s << "':\n" << err;
  for (const std::string& s : want.stdout_has)
    EXPECT_NE(out.find(s), std::string::npos) << "stdout lacks '" << s << "':\n" << out;
  for (const std::string& f : want.files) EXPECT_TRUE(fs::exists(scratch / f)) << f;
  for (const std::string& f : want.no_files) EXPECT_FALSE(fs::exists(scratch / f)) << f;
  if (!::testing::Test::HasFailure()) fs::remove_all(scratch);
}

INSTANTIATE_TEST_SUITE_P(Inputs, Catalogue, ::testing::ValuesIn(case_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string n = i.param;
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

}  // namespace
