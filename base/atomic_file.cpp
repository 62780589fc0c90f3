#include "base/atomic_file.h"

#include <fmt/format.h>

#include <cstdio>
#include <fstream>

namespace isolink {

Status write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      return Status::Error(fmt::format("{}: error: cannot write", path));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return Status::Error(fmt::format("{}: error: cannot rename {} into place", path, tmp));
  }
  return Status::Ok();
}

}  // namespace isolink
