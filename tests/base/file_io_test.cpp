// base/file_io.h: atomic output, devices and FIFOs written in place (never replaced), folders
// refused, disk-full errors reported with the old file intact, report bundles that appear whole,
// size-limited input. Device nodes (mknod) and a full disk (a 64 KiB tmpfs) need root: those
// tests skip with the reason otherwise.
#include "base/file_io.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace isolink {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test (ctest -j2 runs tests at once).
std::string test_dir() {
  const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir =
      ::testing::TempDir() + "/file_io_" + t->name() + "_" + std::to_string(::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void put(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::vector<std::string> names_in(const std::string& dir) {
  std::vector<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) n.push_back(e.path().filename().string());
  std::sort(n.begin(), n.end());
  return n;
}

using Names = std::vector<std::string>;

// Input that is not a regular file is read under a size and a time limit (issue 30: `isolink
// check /dev/zero` never ended): a device that never ends stops at the size, a FIFO whose writer
// never writes (or never opens it) stops at the deadline, and a FIFO that ends is read whole.
TEST(InputFile, DeviceWithoutEndStopsAtTheSizeLimit) {
  StatusOr<std::string> t = read_input_file("/dev/zero", 1024);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().message(),
            "/dev/zero: error: the file is larger than the 1024 byte limit for an input file (a "
            "character device, not a regular file: read for at most 10 s and 1024 byte; save its "
            "content to a file)");
}

TEST(InputFile, FifoWithoutEndStopsAtTheDeadline) {
  const std::string dir = test_dir(), path = dir + "/pipe";
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  // no writer at all: the open does not wait for one, the read stops at the deadline
  auto start = std::chrono::steady_clock::now();
  StatusOr<std::string> t = read_input_file(path, kMaxInputFileBytes, 0.3);
  double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().message(),
            path +
                ": error: no end of input after 0.3 s (a FIFO or pipe, not a regular file: "
                "read for at most 0.3 s and 64 MiB; save its content to a file)");
  EXPECT_GE(took, 0.29);  // the deadline, less poll()'s rounding to whole milliseconds
  EXPECT_LT(took, 5.0);
  // a writer that writes a line and holds the pipe open: the same
  const int w = ::open(path.c_str(), O_RDWR);  // RDWR: does not wait for a reader
  ASSERT_GE(w, 0);
  ASSERT_EQ(::write(w, "a,b\n", 4), 4);
  start = std::chrono::steady_clock::now();
  t = read_input_file(path, kMaxInputFileBytes, 0.3);
  took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ::close(w);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.status().message().find("no end of input after 0.3 s"), std::string::npos);
  EXPECT_LT(took, 5.0);
}

TEST(InputFile, FifoThatEndsIsReadWhole) {
  const std::string dir = test_dir(), path = dir + "/pipe";
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  std::thread writer([&] {
    std::ofstream(path, std::ios::binary) << "time,v\n0,1\n";  // opens once the reader has
  });
  StatusOr<std::string> t = read_input_file(path, kMaxInputFileBytes, 10);
  writer.join();
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(*t, "time,v\n0,1\n");
}

TEST(OutputFile, NewFileHasTheTextAndNothingElseIsLeft) {
  const std::string dir = test_dir();
  ASSERT_TRUE(write_file_atomic(dir + "/a.csv", "time,v\n0,1\n").ok());
  EXPECT_EQ(slurp(dir + "/a.csv"), "time,v\n0,1\n");
  EXPECT_EQ(names_in(dir), Names{"a.csv"});
}

TEST(OutputFile, RegularFileIsReplacedByRenameNotRewritten) {
  const std::string dir = test_dir(), path = dir + "/a.csv";
  put(path, "old\n");
  struct stat before {};
  ASSERT_EQ(::stat(path.c_str(), &before), 0);
  StatusOr<OutputFile> f = OutputFile::open(path);
  ASSERT_TRUE(f.ok()) << f.status().message();
  ASSERT_TRUE(f->write("new, not yet committed\n").ok());
  EXPECT_EQ(slurp(path), "old\n");  // a reader sees the old file until the rename
  ASSERT_TRUE(f->commit().ok());
  struct stat after {};
  ASSERT_EQ(::stat(path.c_str(), &after), 0);
  EXPECT_EQ(slurp(path), "new, not yet committed\n");
  EXPECT_NE(before.st_ino, after.st_ino);  // a new inode: renamed into place
  EXPECT_EQ(names_in(dir), Names{"a.csv"});
}

TEST(OutputFile, NotCommittedLeavesNothing) {
  const std::string dir = test_dir();
  {
    StatusOr<OutputFile> f = OutputFile::open(dir + "/a.csv");
    ASSERT_TRUE(f.ok());
    ASSERT_TRUE(f->write(std::string(200000, 'x')).ok());  // past the buffer: a real write
  }
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(OutputFile, FolderIsRefusedAndLeftAlone) {
  const std::string dir = test_dir();
  fs::create_directories(dir + "/out");
  put(dir + "/out/keep.txt", "mine");
  Status s = write_file_atomic(dir + "/out", "x");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/out: error: this is a folder"), std::string::npos) << s.message();
  EXPECT_EQ(slurp(dir + "/out/keep.txt"), "mine");
  EXPECT_EQ(names_in(dir), Names{"out"});
}

TEST(OutputFile, MissingFolderIsAnError) {
  const std::string dir = test_dir();
  Status s = write_file_atomic(dir + "/no/such/a.csv", "x");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("cannot create a file in"), std::string::npos) << s.message();
}

TEST(OutputFile, SymlinkIsFollowedAndKept) {
  const std::string dir = test_dir();
  put(dir + "/target.csv", "old");
  fs::create_symlink("target.csv", dir + "/link.csv");
  ASSERT_TRUE(write_file_atomic(dir + "/link.csv", "new").ok());
  EXPECT_TRUE(fs::is_symlink(dir + "/link.csv"));
  EXPECT_EQ(slurp(dir + "/target.csv"), "new");
  EXPECT_EQ(names_in(dir), (Names{"link.csv", "target.csv"}));
}

TEST(OutputFile, FifoIsWrittenInPlace) {
  const std::string dir = test_dir(), path = dir + "/pipe";
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = slurp(path); });  // open blocks until the writer opens
  Status s = write_file_atomic(path, "through the pipe\n");
  reader.join();
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(got, "through the pipe\n");
  struct stat st {};
  ASSERT_EQ(::lstat(path.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_EQ(names_in(dir), Names{"pipe"});
}

// The bug: run as root, `-o /dev/null` renamed a regular file over the device node.
TEST(OutputFile, CharacterDeviceSurvives) {
  const std::string dir = test_dir(), path = dir + "/null";
  if (::mknod(path.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0)
    GTEST_SKIP() << "mknod needs root (CAP_MKNOD): " << std::strerror(errno);
  ASSERT_TRUE(write_file_atomic(path, std::string(100000, 'x')).ok());
  struct stat st {};
  ASSERT_EQ(::lstat(path.c_str(), &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device node was replaced";
  EXPECT_EQ(major(st.st_rdev), 1u);
  EXPECT_EQ(minor(st.st_rdev), 3u);
  EXPECT_EQ(names_in(dir), Names{"null"});
}

// /dev/full: every write fails with ENOSPC, as a full disk does.
TEST(OutputFile, WriteErrorOnADeviceIsReported) {
  const std::string dir = test_dir(), path = dir + "/full";
  if (::mknod(path.c_str(), S_IFCHR | 0666, makedev(1, 7)) != 0)
    GTEST_SKIP() << "mknod needs root (CAP_MKNOD): " << std::strerror(errno);
  Status s = write_file_atomic(path, "x");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("No space left on device"), std::string::npos) << s.message();
}

// A real full disk: a 64 KiB tmpfs. The old file stays as it was and no temporary file is left.
class FullDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test_dir() + "/mnt";
    fs::create_directories(dir_);
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") != 0)
      GTEST_SKIP() << "mounting a small tmpfs needs root (CAP_SYS_ADMIN): " << std::strerror(errno);
    mounted_ = true;
  }
  void TearDown() override {
    if (mounted_) ::umount(dir_.c_str());
  }
  std::string dir_;
  bool mounted_ = false;
};

TEST_F(FullDisk, OldFileIsKeptAndTheErrorNamesThePath) {
  put(dir_ + "/wave.csv", "old\n");
  Status s = write_file_atomic(dir_ + "/wave.csv", std::string(1 << 20, 'x'));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("wave.csv: error: cannot write: No space left on device"),
            std::string::npos)
      << s.message();
  EXPECT_EQ(slurp(dir_ + "/wave.csv"), "old\n");
  EXPECT_EQ(names_in(dir_), Names{"wave.csv"});
}

TEST_F(FullDisk, BundleThatDoesNotFitLeavesTheOldReport) {
  const std::string out = dir_ + "/report";
  fs::create_directories(out);
  put(out + "/report.md", "old report\n");
  {
    StatusOr<OutputBundle> b = OutputBundle::open(out, {"report.md", "wave.csv"});
    ASSERT_TRUE(b.ok()) << b.status().message();
    ASSERT_TRUE(write_file_atomic(b->path("report.md"), "new report\n").ok());
    EXPECT_FALSE(write_file_atomic(b->path("wave.csv"), std::string(1 << 20, 'x')).ok());
  }  // destroyed without commit, as cmd_run does on an error
  EXPECT_EQ(slurp(out + "/report.md"), "old report\n");
  EXPECT_EQ(names_in(dir_), Names{"report"});
  EXPECT_EQ(names_in(out), Names{"report.md"});
}

const std::vector<std::string> kReport = {"report.md", "report.json", "eye.png"};

TEST(OutputBundle, NewFolderAppearsOnlyAtCommit) {
  const std::string dir = test_dir(), out = dir + "/xfmr";
  StatusOr<OutputBundle> b = OutputBundle::open(out, kReport);
  ASSERT_TRUE(b.ok()) << b.status().message();
  ASSERT_TRUE(write_file_atomic(b->path("report.md"), "md").ok());
  ASSERT_TRUE(write_file_atomic(b->path("report.json"), "{}").ok());
  EXPECT_FALSE(fs::exists(out));
  ASSERT_TRUE(b->commit().ok());
  EXPECT_EQ(names_in(out), (Names{"report.json", "report.md"}));
  EXPECT_EQ(names_in(dir), Names{"xfmr"});  // no temporary folder left beside it
}

TEST(OutputBundle, ExistingReportIsSwappedWhole) {
  const std::string dir = test_dir(), out = dir + "/xfmr";
  fs::create_directories(out);
  put(out + "/report.md", "old md");
  put(out + "/eye.png", "old eye");  // the new run draws no images: the old eye must go too
  StatusOr<OutputBundle> b = OutputBundle::open(out, kReport);
  ASSERT_TRUE(b.ok()) << b.status().message();
  ASSERT_TRUE(write_file_atomic(b->path("report.md"), "new md").ok());
  EXPECT_EQ(slurp(out + "/report.md"), "old md");
  ASSERT_TRUE(b->commit().ok());
  EXPECT_EQ(names_in(out), Names{"report.md"});
  EXPECT_EQ(slurp(out + "/report.md"), "new md");
  EXPECT_EQ(names_in(dir), Names{"xfmr"});
}

TEST(OutputBundle, FolderWithOtherFilesIsRefusedAndKept) {
  const std::string dir = test_dir();
  put(dir + "/thesis.tex", "years of work");
  StatusOr<OutputBundle> b = OutputBundle::open(dir, kReport);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("holds 'thesis.tex', which is not part of a report"),
            std::string::npos)
      << b.status().message();
  EXPECT_EQ(slurp(dir + "/thesis.tex"), "years of work");
}

TEST(OutputBundle, NotCommittedLeavesNothing) {
  const std::string dir = test_dir();
  {
    StatusOr<OutputBundle> b = OutputBundle::open(dir + "/x", kReport);
    ASSERT_TRUE(b.ok());
    ASSERT_TRUE(write_file_atomic(b->path("report.md"), "md").ok());
  }
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(OutputBundle, TemporaryFolderOfAKilledRunIsRemovedNextTime) {
  const std::string dir = test_dir();
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // a process id that is certainly gone
  const std::string stale = dir + "/.x." + std::to_string(child) + "-0.tmp";
  const std::string alive = dir + "/.x." + std::to_string(::getppid()) + "-0.tmp";
  fs::create_directories(stale);
  fs::create_directories(alive);  // a running process's: left alone
  StatusOr<OutputBundle> b = OutputBundle::open(dir + "/x", kReport);
  ASSERT_TRUE(b.ok());
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(alive));
}

TEST(ReadInputFile, StatesTheLimit) {
  const std::string dir = test_dir();
  put(dir + "/a.cir", std::string(11, 'x'));
  StatusOr<std::string> r = read_input_file(dir + "/a.cir", 10);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("a.cir: error: the file is larger than the 10 byte limit"),
            std::string::npos)
      << r.status().message();
  StatusOr<std::string> ok = read_input_file(dir + "/a.cir", 11);
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(*ok, std::string(11, 'x'));
}

TEST(ReadInputFile, EndlessDeviceStopsAtTheLimit) {
  StatusOr<std::string> r = read_input_file("/dev/zero", size_t{1} << 20);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("/dev/zero: error: the file is larger than the 1 MiB limit"),
            std::string::npos)
      << r.status().message();
}

TEST(ReadInputFile, FolderIsNotAnEmptyFile) {
  const std::string dir = test_dir();
  StatusOr<std::string> r = read_input_file(dir);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("error: this is a folder, not a file"), std::string::npos);
}

TEST(SafePathComponent, NoEscapeFromTheReportFolder) {
  EXPECT_EQ(safe_path_component(".."), "_");
  EXPECT_EQ(safe_path_component("."), "_");
  EXPECT_EQ(safe_path_component(""), "_");
  EXPECT_EQ(safe_path_component("../../etc"), "_._.._etc");
  EXPECT_EQ(safe_path_component("a/b\\c"), "a_b_c");
  EXPECT_EQ(safe_path_component("x\ty\n"), "x_y_");
  EXPECT_EQ(safe_path_component(".hidden"), "_hidden");
  EXPECT_EQ(safe_path_component("xfmr-12m"), "xfmr-12m");
}

}  // namespace
}  // namespace isolink
