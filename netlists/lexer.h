// SPICE lexing: physical lines -> logical lines (comments stripped, '+' continuations joined)
// -> tokens. (SPICE numbers with SI suffixes: base/si_number.h.)
//
//   auto file = SourceFile::FromText("a.cir", text);
//   std::vector<LogicalLine> lines = join_lines(file, /*first_line=*/2);  // skip the title
//   StatusOr<std::vector<Token>> toks = tokenize(lines[0]);
//   SourceLoc where = lines[0].loc((*toks)[1].offset);
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"

namespace isolink::spice {

// One card: a physical line plus its '+' continuation lines, comments removed. The pieces are
// joined with one space; segments map offsets in `text` back to file positions.
struct LogicalLine {
  struct Segment {
    std::size_t offset;  // first offset in text that comes from this physical line
    int line;            // 1-based line number
    int col;             // 1-based column of text[offset]
  };
  std::shared_ptr<const SourceFile> file;
  std::string text;
  std::vector<Segment> segments;

  SourceLoc loc(std::size_t offset) const;
  int first_line() const { return segments.empty() ? 0 : segments.front().line; }
};

// Splits file lines [first_line, end] (1-based) into logical lines. Comment lines ('*' first),
// blank lines and inline comments (';' anywhere, '$' at line start or after blank) are dropped;
// a comment or blank line between a card and its '+' lines does not break the continuation.
// Error: a '+' line with no card before it.
StatusOr<std::vector<LogicalLine>> join_lines(const std::shared_ptr<const SourceFile>& file,
                                              int first_line);

enum class TokenKind {
  Word,    // a run of characters other than blanks and ( ) , = { } '
  Expr,    // {expr} or 'expr': text is the inside, offset points at the opening delimiter
  LParen,  // (
  RParen,  // )
  Comma,   // ,
  Equals,  // =
};

struct Token {
  TokenKind kind;
  std::string_view text;  // view into LogicalLine::text (keep the line alive and unmoved)
  std::size_t offset;     // offset of the token's first character in LogicalLine::text

  std::size_t end() const { return offset + text.size() + (kind == TokenKind::Expr ? 2 : 0); }
};

// Tokens of one logical line. Errors (with location): unbalanced ( ) { } or an unterminated '.
StatusOr<std::vector<Token>> tokenize(const LogicalLine& line);

// SPICE numbers with SI suffixes ("2.2nF", "4k7") are read by base/si_number.h.

// ASCII lower case.
std::string lower(std::string_view s);

}  // namespace isolink::spice
