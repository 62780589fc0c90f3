// Whole-file output that never leaves a half-written file under its final name.
//
//   Status s = write_file_atomic("out/report.md", text);   // out/report.md.tmp, then rename
#pragma once

#include <string>

#include "base/status.h"

namespace isolink {

// Writes text to path through path + ".tmp" and a rename.
Status write_file_atomic(const std::string& path, const std::string& text);

}  // namespace isolink
