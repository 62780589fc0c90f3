// The low-level text tokenizer under the scope readers: lines (LF, CRLF or CR ends, a UTF-8 BOM
// dropped) streamed from a file in fixed chunks or taken from a string, fields split on one
// delimiter (quotes and parentheses protect it), numbers with a decimal point or comma.
// Layout knowledge (which line is a header, what a units row means) is in eye/scope_formats.h.
//
// Usage:
//   StatusOr<LineReader> in = LineReader::open("scope.csv");   // or LineReader(text)
//   std::string_view line;
//   std::vector<std::string_view> f;
//   while (in->next(&line)) { split_fields(line, ',', &f); double x; parse_cell(f[0], false, &x); }
//   in->number();   // 1-based number of the line just returned
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink::eye {

class LineReader {
 public:
  explicit LineReader(std::string_view text) : view_(text) {}
  // Streams the file in 1 MiB chunks: memory does not grow with the file.
  static StatusOr<LineReader> open(const std::string& path);

  // The next line without its end (valid until the next call); false at the end of the text.
  bool next(std::string_view* line);
  int number() const { return number_; }
  // The file's size in bytes (the text's for a string), for estimates.
  uint64_t size() const { return size_; }
  // Non-empty when reading stopped on an I/O error.
  const std::string& error() const { return error_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  bool refill();
  std::unique_ptr<std::FILE, Closer> file_;
  std::string buf_;        // file mode: the chunk being read
  std::string_view view_;  // the text (string mode) or buf_ (file mode)
  size_t pos_ = 0;
  bool eof_ = true;       // no more to read into buf_
  bool skip_lf_ = false;  // the last line ended in CR: a LF right after it belongs to it
  int number_ = 0;
  uint64_t size_ = 0;
  std::string error_;
};

std::string_view trim_cell(std::string_view s);  // blanks and CR off both ends
std::string_view unquote(std::string_view s);    // trimmed, one pair of quotes removed

// The delimiter of a row: ';' if one is outside quotes/parentheses, else tab, else ',', else ' '
// (runs of blanks). A ';' or tab row may then use a decimal comma.
char detect_delimiter(std::string_view line);
// Fields of a row; trailing empty fields are dropped. No split inside quotes or parentheses (so
// SPICE names such as v(rxp,rxn) stay whole).
void split_fields(std::string_view line, char delim, std::vector<std::string_view>* out);
// A finite number ("+1.5E-03", quoted or not); with decimal_comma "1,5" reads as 1.5.
bool parse_cell(std::string_view s, bool decimal_comma, double* out);

}  // namespace isolink::eye
