#include "eye/csv_lines.h"

#include <charconv>
#include <cmath>

namespace isolink::eye {

StatusOr<LineReader> LineReader::open(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return Status::Error(path + ": error: cannot open the file");
  LineReader r{std::string_view()};
  r.file_.reset(f);
  r.eof_ = false;
  if (std::fseek(f, 0, SEEK_END) == 0) {
    const long size = std::ftell(f);
    r.size_ = size > 0 ? static_cast<uint64_t>(size) : 0;
    std::rewind(f);
  }
  return r;
}

bool LineReader::refill() {
  if (eof_) return false;
  constexpr size_t kChunk = size_t{1} << 20;
  buf_.erase(0, pos_);
  pos_ = 0;
  const size_t old = buf_.size();
  buf_.resize(old + kChunk);
  const size_t got = std::fread(buf_.data() + old, 1, kChunk, file_.get());
  buf_.resize(old + got);
  if (got < kChunk) {
    eof_ = true;
    if (std::ferror(file_.get())) error_ = "cannot read the file";
  }
  view_ = buf_;
  return got > 0;
}

bool LineReader::next(std::string_view* line) {
  if (size_ == 0 && !file_) size_ = view_.size();
  for (;;) {
    if (skip_lf_) {
      if (pos_ >= view_.size() && !refill()) return false;
      if (pos_ < view_.size()) {
        if (view_[pos_] == '\n') ++pos_;
        skip_lf_ = false;
      }
      continue;
    }
    const size_t e = view_.find_first_of("\r\n", pos_);
    if (e == std::string_view::npos) {
      if (!eof_) {  // the line runs past the chunk: read on
        refill();
        continue;
      }
      if (pos_ >= view_.size()) return false;
      *line = view_.substr(pos_);
      pos_ = view_.size();
    } else {
      *line = view_.substr(pos_, e - pos_);
      skip_lf_ = view_[e] == '\r';
      pos_ = e + 1;
    }
    if (++number_ == 1 && line->substr(0, 3) == "\xEF\xBB\xBF") line->remove_prefix(3);
    return true;
  }
}

std::string_view trim_cell(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::string_view unquote(std::string_view s) {
  s = trim_cell(s);
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front())
    s = trim_cell(s.substr(1, s.size() - 2));
  return s;
}

char detect_delimiter(std::string_view line) {
  bool semi = false, tab = false, comma = false;
  int depth = 0;
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (!quoted && c == '(')
      ++depth;
    else if (!quoted && c == ')' && depth > 0)
      --depth;
    else if (!quoted && depth == 0) {
      semi = semi || c == ';';
      tab = tab || c == '\t';
      comma = comma || c == ',';
    }
  }
  return semi ? ';' : tab ? '\t' : comma ? ',' : ' ';
}

void split_fields(std::string_view line, char delim, std::vector<std::string_view>* out) {
  out->clear();
  if (delim == ' ') {
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      if (i >= line.size()) break;
      size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
      out->push_back(line.substr(i, j - i));
      i = j;
    }
    return;
  }
  if (line.find('"') == std::string_view::npos && line.find('(') == std::string_view::npos) {
    size_t start = 0;
    for (;;) {
      const size_t k = line.find(delim, start);
      if (k == std::string_view::npos) {
        out->push_back(line.substr(start));
        break;
      }
      out->push_back(line.substr(start, k - start));
      start = k + 1;
    }
  } else {  // names like v(rxp,rxn) or "a,b": no split inside parentheses or quotes
    size_t start = 0;
    int depth = 0;
    bool quoted = false;
    for (size_t k = 0; k < line.size(); ++k) {
      const char c = line[k];
      if (c == '"')
        quoted = !quoted;
      else if (!quoted && c == '(')
        ++depth;
      else if (!quoted && c == ')' && depth > 0)
        --depth;
      else if (!quoted && depth == 0 && c == delim) {
        out->push_back(line.substr(start, k - start));
        start = k + 1;
      }
    }
    out->push_back(line.substr(start));
  }
  while (!out->empty() && trim_cell(out->back()).empty()) out->pop_back();
}

bool parse_cell(std::string_view s, bool decimal_comma, double* out) {
  s = unquote(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  if (decimal_comma && s.find(',') != std::string_view::npos) {
    char tmp[64];
    if (s.size() >= sizeof tmp) return false;
    for (size_t i = 0; i < s.size(); ++i) tmp[i] = s[i] == ',' ? '.' : s[i];
    auto [ptr, ec] = std::from_chars(tmp, tmp + s.size(), *out);
    return ec == std::errc() && ptr == tmp + s.size() && std::isfinite(*out);
  }
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(*out);
}

}  // namespace isolink::eye
