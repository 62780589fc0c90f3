// Source locations and compiler-style diagnostics for every parsed object.
//
// Usage:
//   auto file = SourceFile::Load("link.cir", /*included_from=*/{});   // or SourceFile::FromText
//   SourceLoc loc{file, 12, 5};
//   std::string text = format_diagnostic(loc, "error", "resistance must be positive");
// gives
//   link.cir:12:5: error: resistance must be positive
//    R1 a b -4
//        ^
//   (included from top.cir:3:1)
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "base/status.h"

namespace isolink {

struct SourceLoc;

// One text file (or in-memory text) with its lines kept for diagnostics.
struct SourceFile {
  std::string path;                                // as the user named it (or "<string>")
  std::vector<std::string> lines;                  // without line terminators
  std::shared_ptr<const SourceLoc> included_from;  // the .include card that pulled it in, if any

  static std::shared_ptr<const SourceFile> FromText(std::string path, const std::string& text,
                                                    std::shared_ptr<const SourceLoc> from = {});
};

// A position in a source file: 1-based line and column; line 0 means "whole file".
struct SourceLoc {
  std::shared_ptr<const SourceFile> file;
  int line = 0;
  int col = 0;

  bool valid() const { return file != nullptr; }
  std::string str() const;  // "file:line:col" (or "<unknown>")
};

// "file:line:col: SEVERITY: message", the source line, a caret, and the include chain.
std::string format_diagnostic(const SourceLoc& loc, const std::string& severity,
                              const std::string& message);

// Status::Error carrying a formatted "error" diagnostic at loc; the message alone when loc is not
// valid (no file).
Status error_at(const SourceLoc& loc, const std::string& message);

}  // namespace isolink
