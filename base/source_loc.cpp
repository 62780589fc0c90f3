#include "base/source_loc.h"

#include <sstream>

namespace isolink {

std::shared_ptr<const SourceFile> SourceFile::FromText(std::string path, const std::string& text,
                                                       std::shared_ptr<const SourceLoc> from) {
  auto file = std::make_shared<SourceFile>();
  file->path = std::move(path);
  file->included_from = std::move(from);
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    file->lines.push_back(line);
  }
  return file;
}

std::string SourceLoc::str() const {
  if (!file) return "<unknown>";
  std::string s = file->path;
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (col > 0) s += ":" + std::to_string(col);
  }
  return s;
}

std::string format_diagnostic(const SourceLoc& loc, const std::string& severity,
                              const std::string& message) {
  std::string out = loc.str();
  out.append(": ").append(severity).append(": ").append(message);
  if (loc.file && loc.line > 0 && loc.line <= static_cast<int>(loc.file->lines.size())) {
    const std::string& text = loc.file->lines[loc.line - 1];
    out.append("\n ").append(text).append("\n ");
    for (int i = 1; i < loc.col && i <= static_cast<int>(text.size()); ++i)
      out += text[i - 1] == '\t' ? '\t' : ' ';
    out += "^";
  }
  for (auto from = loc.file ? loc.file->included_from : nullptr; from;
       from = from->file ? from->file->included_from : nullptr) {
    out.append("\n (included from ").append(from->str()).append(")");
  }
  return out;
}

Status error_at(const SourceLoc& loc, const std::string& message) {
  // No place (a value built in code or given from Python): the message alone, which the caller's
  // context leads, rather than "<unknown>: error: ...".
  if (!loc.valid()) return Status::Error(message);
  return Status::Error(format_diagnostic(loc, "error", message));
}

}  // namespace isolink
