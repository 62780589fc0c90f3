#include "base/file_io.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace isolink {
namespace fs = std::filesystem;

namespace {

std::atomic<unsigned> g_counter{0};

std::string errno_text(int err) {
  return std::error_code(err, std::generic_category()).message();
}

std::string parent_of(const std::string& path) {
  const fs::path p(path);
  return p.has_parent_path() ? p.parent_path().string() : std::string(".");
}

// ".NAME.PID-N.tmp" beside path: hidden, unique per process and call.
std::string temp_name_beside(const std::string& path) {
  const fs::path p(path);
  const std::string name = "." + p.filename().string() + "." + std::to_string(::getpid()) + "-" +
                           std::to_string(g_counter.fetch_add(1)) + ".tmp";
  return p.has_parent_path() ? (p.parent_path() / name).string() : name;
}

size_t human_mib(size_t bytes) {
  return bytes >> 20;
}

}  // namespace

// --- input -----------------------------------------------------------------------------------

namespace {

// What a path that is not a regular file is, in words.
const char* kind_of(const struct stat& st) {
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISFIFO(st.st_mode)) return "a FIFO or pipe";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "not a regular file";
}

// Waits until fd has input, an end, or the deadline passes (false: it passed).
bool wait_readable(int fd, std::chrono::steady_clock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    struct pollfd p {};
    p.fd = fd;
    p.events = POLLIN;
    const int n = ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1 << 30)));
    if (n > 0) return true;
    if (n < 0 && errno != EINTR) return true;  // let read() report it
  }
}

}  // namespace

StatusOr<std::string> read_input_file(const std::string& path, size_t max_bytes,
                                      double max_seconds) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return Status::Error(
        fmt::format("{}: error: cannot open the file: {}", path, errno_text(errno)));
  if (S_ISDIR(st.st_mode))
    return Status::Error(fmt::format("{}: error: this is a folder, not a file", path));
  const bool regular = S_ISREG(st.st_mode);
  // Not a regular file (a device, a FIFO, a pipe): opened without waiting for a writer, and read
  // under a deadline as well as the size limit, so that neither /dev/zero nor a pipe that never
  // ends holds isolink.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (regular ? 0 : O_NONBLOCK));
  if (fd < 0)
    return Status::Error(
        fmt::format("{}: error: cannot open the file: {}", path, errno_text(errno)));
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(std::clamp(max_seconds, 0.0, 1e6)));
  const std::string limits = max_bytes >= (size_t{1} << 20)
                                 ? fmt::format("{} MiB", human_mib(max_bytes))
                                 : fmt::format("{} byte", max_bytes);
  auto not_regular = [&] {
    return regular ? std::string()
                   : fmt::format(
                         " ({}, not a regular file: read for at most {:g} s and {}; save "
                         "its content to a file)",
                         kind_of(st), max_seconds, limits);
  };
  std::string text;
  if (regular && static_cast<unsigned long long>(st.st_size) <= max_bytes)
    text.reserve(static_cast<size_t>(st.st_size));
  char chunk[1 << 16];
  for (;;) {
    if (!regular && !wait_readable(fd, deadline)) {
      ::close(fd);
      return Status::Error(fmt::format("{}: error: no end of input after {:g} s{}", path,
                                       max_seconds, not_regular()));
    }
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      return Status::Error(
          fmt::format("{}: error: cannot read the file: {}", path, errno_text(err)));
    }
    if (n == 0) break;
    if (text.size() + static_cast<size_t>(n) > max_bytes) {
      ::close(fd);
      return Status::Error(
          fmt::format("{}: error: the file is larger than the {} limit for an "
                      "input file{}",
                      path, limits, not_regular()));
    }
    text.append(chunk, static_cast<size_t>(n));
  }
  ::close(fd);
  return text;
}

// --- one output file -------------------------------------------------------------------------

StatusOr<OutputFile> OutputFile::open(const std::string& path) {
  OutputFile f;
  f.path_ = path;
  if (path.empty()) return Status::Error("error: an output path is empty");
  if (path == "-") {
    std::fflush(stdout);  // what printf buffered goes first
    f.fd_ = STDOUT_FILENO;
    return f;
  }
  std::string target = path;
  struct stat st {};
  bool exists = ::lstat(path.c_str(), &st) == 0;
  if (exists && S_ISLNK(st.st_mode)) {
    std::error_code ec;
    const fs::path resolved = fs::weakly_canonical(path, ec);
    if (ec)
      return Status::Error(
          fmt::format("{}: error: cannot follow the symbolic link: {}", path, ec.message()));
    target = resolved.string();
    exists = ::stat(target.c_str(), &st) == 0;
  }
  if (exists && S_ISDIR(st.st_mode))
    return Status::Error(
        fmt::format("{}: error: this is a folder; give the output a file name", path));
  if (exists && !S_ISREG(st.st_mode)) {
    // A device (/dev/null), a FIFO: written in place, never replaced.
    f.fd_ = ::open(target.c_str(), O_WRONLY | O_CLOEXEC);
    if (f.fd_ < 0)
      return Status::Error(
          fmt::format("{}: error: cannot open for writing: {}", path, errno_text(errno)));
    f.owns_fd_ = true;
    return f;
  }
  for (int attempt = 0; attempt < 100 && f.fd_ < 0; ++attempt) {
    f.tmp_ = temp_name_beside(target);
    f.fd_ = ::open(f.tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (f.fd_ < 0 && errno != EEXIST) {
      const int err = errno;
      return Status::Error(fmt::format("{}: error: cannot create a file in {}: {}", path,
                                       parent_of(target), errno_text(err)));
    }
  }
  if (f.fd_ < 0)
    return Status::Error(fmt::format("{}: error: cannot create a temporary file", path));
  f.owns_fd_ = true;
  f.target_ = target;
  return f;
}

OutputFile::OutputFile(OutputFile&& o) noexcept
    : path_(std::move(o.path_)),
      target_(std::move(o.target_)),
      tmp_(std::move(o.tmp_)),
      fd_(o.fd_),
      owns_fd_(o.owns_fd_),
      committed_(o.committed_),
      buf_(std::move(o.buf_)),
      error_(std::move(o.error_)) {
  o.fd_ = -1;
  o.owns_fd_ = false;
  o.tmp_.clear();
  o.committed_ = true;
}

OutputFile::~OutputFile() {
  if (!committed_) abandon();
}

void OutputFile::abandon() {
  if (owns_fd_ && fd_ >= 0) ::close(fd_);
  fd_ = -1;
  owns_fd_ = false;
  if (!tmp_.empty()) ::unlink(tmp_.c_str());
  tmp_.clear();
}

Status OutputFile::fail(const std::string& what, int err) {
  if (error_.ok())
    error_ = Status::Error(fmt::format("{}: error: {}: {}", path_, what, errno_text(err)));
  return error_;
}

Status OutputFile::flush() {
  if (!error_.ok()) return error_;
  if (fd_ < 0) return Status::Error(fmt::format("{}: error: the file is already closed", path_));
  size_t done = 0;
  while (done < buf_.size()) {
    const ssize_t n = ::write(fd_, buf_.data() + done, buf_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("cannot write", errno);
    if (n == 0) return fail("cannot write", EIO);
    done += static_cast<size_t>(n);
  }
  buf_.clear();
  return Status::Ok();
}

Status OutputFile::write(std::string_view data) {
  if (!error_.ok()) return error_;
  buf_.append(data);
  if (buf_.size() >= (size_t{1} << 16)) return flush();
  return Status::Ok();
}

Status OutputFile::commit() {
  if (committed_) return Status::Error(fmt::format("{}: error: written twice", path_));
  Status s = flush();
  if (s.ok() && owns_fd_) {
    const int fd = fd_;
    fd_ = -1;
    owns_fd_ = false;
    if (::close(fd) != 0) s = fail("cannot close", errno);  // NFS and some disks report here
  }
  if (s.ok() && !tmp_.empty()) {
    if (::rename(tmp_.c_str(), target_.c_str()) != 0)
      s = fail(fmt::format("cannot rename {} into place", tmp_), errno);
    else
      tmp_.clear();
  }
  if (!s.ok()) {
    abandon();
    committed_ = true;
    return s;
  }
  committed_ = true;
  return Status::Ok();
}

Status write_file_atomic(const std::string& path, std::string_view data) {
  StatusOr<OutputFile> f = OutputFile::open(path);
  if (!f) return f.status();
  if (Status s = f->write(data); !s.ok()) return s;
  return f->commit();
}

// --- a report folder -------------------------------------------------------------------------

namespace {

// Hidden temporary folders ".NAME.PID-N.tmp" beside dir whose process has gone (a kill -9).
void remove_stale_temps(const fs::path& dir) {
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  const std::string prefix = "." + dir.filename().string() + ".";
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(parent, ec)) {
    const std::string n = e.path().filename().string();
    if (n.size() <= prefix.size() + 4 || n.compare(0, prefix.size(), prefix) != 0 ||
        n.compare(n.size() - 4, 4, ".tmp") != 0)
      continue;
    const std::string mid = n.substr(prefix.size(), n.size() - prefix.size() - 4);  // PID-N
    const size_t dash = mid.find('-');
    if (dash == std::string::npos || dash == 0) continue;
    if (mid.find_first_not_of("0123456789-") != std::string::npos) continue;
    const long pid = std::strtol(mid.substr(0, dash).c_str(), nullptr, 10);
    if (pid <= 0 || pid == ::getpid()) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // still running
    std::error_code ec2;
    fs::remove_all(e.path(), ec2);
  }
}

}  // namespace

StatusOr<OutputBundle> OutputBundle::open(const std::string& dir,
                                          const std::vector<std::string>& names) {
  if (dir.empty()) return Status::Error("error: the output folder name is empty");
  fs::path p = fs::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "out/" -> "out"
  if (p.empty() || p == "." || p == ".." || p.filename() == "..")
    return Status::Error(fmt::format("{}: error: give the report a folder of its own", dir));
  struct stat st {};
  if (::lstat(p.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode))
      return Status::Error(fmt::format("{}: error: exists and is not a folder", dir));
    std::error_code ec;
    for (const fs::directory_entry& e : fs::directory_iterator(p, ec)) {
      const std::string n = e.path().filename().string();
      bool known = false;
      for (const std::string& k : names) known = known || k == n;
      if (!known)
        return Status::Error(fmt::format(
            "{}: error: the folder holds '{}', which is not part of a report; isolink replaces a "
            "report folder as a whole, so give -o a new folder, an empty one or an earlier "
            "report's",
            dir, n));
    }
    if (ec)
      return Status::Error(fmt::format("{}: error: cannot read the folder: {}", dir, ec.message()));
  }
  const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec)
    return Status::Error(fmt::format("{}: error: cannot create the folder {}: {}", dir,
                                     parent.string(), ec.message()));
  remove_stale_temps(p);
  OutputBundle b;
  b.dir_ = p.string();
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::string tmp = temp_name_beside(b.dir_);
    if (::mkdir(tmp.c_str(), 0777) == 0) {
      b.tmp_ = tmp;
      return b;
    }
    if (errno != EEXIST)
      return Status::Error(fmt::format("{}: error: cannot create a folder in {}: {}", dir,
                                       parent.string(), errno_text(errno)));
  }
  return Status::Error(fmt::format("{}: error: cannot create a temporary folder", dir));
}

OutputBundle::OutputBundle(OutputBundle&& o) noexcept
    : dir_(std::move(o.dir_)), tmp_(std::move(o.tmp_)), committed_(o.committed_) {
  o.tmp_.clear();
  o.committed_ = true;
}

OutputBundle::~OutputBundle() {
  if (!committed_ && !tmp_.empty()) {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }
}

Status OutputBundle::commit() {
  if (committed_) return Status::Error(fmt::format("{}: error: written twice", dir_));
  struct stat st {};
  if (::lstat(dir_.c_str(), &st) != 0) {
    if (::rename(tmp_.c_str(), dir_.c_str()) != 0)
      return Status::Error(
          fmt::format("{}: error: cannot rename {} into place: {}", dir_, tmp_, errno_text(errno)));
    committed_ = true;
    return Status::Ok();
  }
  // Swap the new folder with the old in one step, then delete the old (now under the temp name).
  if (::renameat2(AT_FDCWD, tmp_.c_str(), AT_FDCWD, dir_.c_str(), RENAME_EXCHANGE) != 0) {
    const int err = errno;
    if (err != EINVAL && err != ENOSYS)
      return Status::Error(
          fmt::format("{}: error: cannot swap {} into place: {}", dir_, tmp_, errno_text(err)));
    // A file system without RENAME_EXCHANGE: move the old aside, the new in, the old away.
    const std::string old = temp_name_beside(dir_);
    if (::rename(dir_.c_str(), old.c_str()) != 0)
      return Status::Error(
          fmt::format("{}: error: cannot move the old report aside: {}", dir_, errno_text(errno)));
    if (::rename(tmp_.c_str(), dir_.c_str()) != 0) {
      const int err2 = errno;
      (void)::rename(old.c_str(), dir_.c_str());
      return Status::Error(
          fmt::format("{}: error: cannot rename {} into place: {}", dir_, tmp_, errno_text(err2)));
    }
    tmp_ = old;
  }
  committed_ = true;
  std::error_code ec;
  fs::remove_all(tmp_, ec);  // the old report
  return Status::Ok();
}

std::string safe_path_component(const std::string& s) {
  std::string out;
  for (unsigned char c : s) out += (c < 0x20 || c >= 0x7f || c == '/' || c == '\\') ? '_' : char(c);
  if (out.empty() || out == "." || out == "..") out = "_";
  if (out[0] == '.') out[0] = '_';  // no hidden report folders (and no clash with temp names)
  return out;
}

}  // namespace isolink
