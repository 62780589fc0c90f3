// The one way isolink reads an input file and writes an output file or a report folder.
//
// Usage:
//   StatusOr<std::string> text = read_input_file("link.yaml");        // size-limited, no folders
//   Status s = write_file_atomic("report.json", json_text);           // temp name + rename
//   StatusOr<OutputFile> f = OutputFile::open("wave.csv");            // streaming, same rules
//   f->write("time,v\n"); ...; Status s = f->commit();                // nothing is left if never
//                                                                     // committed
//   StatusOr<OutputBundle> b = OutputBundle::open("reports/out/x", {"report.md", "eye.png"});
//   write_file_atomic(b->path("report.md"), md); ...; b->commit();    // the folder appears whole
//
// Output rules (issue 15):
// - "-" is standard output, written in place.
// - A regular file, or a path that does not exist yet, is written to a hidden temporary name in
//   the same folder (".NAME.PID-N.tmp") and renamed over the target only after every write and the
//   close succeeded, so a reader never sees a half-written file under the final name, and a disk
//   that fills up (ENOSPC) leaves the old file as it was.
// - Anything else that exists (a character or block device such as /dev/null, a FIFO) is opened
//   and written in place: it is never replaced, because isolink did not create it.
// - A folder is refused. A symbolic link is followed, and its target is what gets replaced.
// - Every write and the close are checked; errors name the path and the system's reason.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink {

// Input files larger than this are refused (a netlist, a link spec, a sweep, a part, a rule file;
// /dev/zero given as a netlist ends here rather than in std::bad_alloc).
inline constexpr size_t kMaxInputFileBytes = size_t{64} << 20;  // 64 MiB

// A path that is not a regular file (a character device such as /dev/zero, a FIFO, a pipe) is
// also read under this deadline: input with no end after it is refused.
inline constexpr double kMaxInputWaitSeconds = 10;

// The whole file, or "PATH: error: ..." when it cannot be opened, is a folder, or is larger than
// max_bytes (the message states the limit); a path that is not a regular file is opened without
// waiting for a writer and refused when its input has not ended after max_seconds (the message
// names what it is and both limits).
StatusOr<std::string> read_input_file(const std::string& path,
                                      size_t max_bytes = kMaxInputFileBytes,
                                      double max_seconds = kMaxInputWaitSeconds);

class OutputFile {
 public:
  static StatusOr<OutputFile> open(const std::string& path);
  OutputFile(OutputFile&& o) noexcept;
  OutputFile& operator=(OutputFile&&) = delete;
  OutputFile(const OutputFile&) = delete;
  ~OutputFile();  // not committed: the temporary file is removed

  // Buffered; a failed write (the disk is full) is reported here or by commit(), never lost.
  Status write(std::string_view data);
  // Flushes, closes and (for a temporary file) renames it over the target.
  Status commit();
  const std::string& path() const { return path_; }

 private:
  OutputFile() = default;
  Status flush();
  Status fail(const std::string& what, int err);
  void abandon();

  std::string path_;    // as the user named it
  std::string target_;  // what the rename replaces (the symlink's target when path_ is one)
  std::string tmp_;     // empty when writing in place
  int fd_ = -1;
  bool owns_fd_ = false;
  bool committed_ = false;
  std::string buf_;
  Status error_;
};

// data to path, by the rules above.
Status write_file_atomic(const std::string& path, std::string_view data);

// A report folder that appears whole or not at all. Files are written into a hidden temporary
// folder beside it; commit() renames that folder to the final name, or, when a report folder is
// already there, swaps the two atomically (renameat2 RENAME_EXCHANGE) and deletes the old one.
// An existing folder is replaced only when it is empty or holds nothing but names from `names`
// (what a report folder holds): any other content is a folder isolink did not write, and open()
// refuses it rather than delete it. Hidden temporary folders left by a killed run (their process
// is gone) are removed by the next open() of the same folder.
class OutputBundle {
 public:
  static StatusOr<OutputBundle> open(const std::string& dir, const std::vector<std::string>& names);
  OutputBundle(OutputBundle&& o) noexcept;
  OutputBundle& operator=(OutputBundle&&) = delete;
  OutputBundle(const OutputBundle&) = delete;
  ~OutputBundle();  // not committed: the temporary folder and all in it are removed

  // Where to write the file `name` of the bundle (inside the temporary folder).
  std::string path(const std::string& name) const { return tmp_ + "/" + name; }
  // The temporary folder itself (for code that takes a folder and writes names into it).
  const std::string& staging() const { return tmp_; }
  const std::string& dir() const { return dir_; }
  Status commit();

 private:
  OutputBundle() = default;
  std::string dir_;
  std::string tmp_;
  bool committed_ = false;
};

// s made safe as one path component: '/', '\\', control bytes and anything outside printable
// ASCII become '_', and "", "." or ".." become "_" (a spec's `name` used for reports/out/<name>).
std::string safe_path_component(const std::string& s);

}  // namespace isolink
