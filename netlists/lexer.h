// SPICE lexing: physical lines -> logical lines (comments stripped, '+' continuations joined)
// -> tokens, and SPICE numbers with SI suffixes.
//
//   auto file = SourceFile::FromText("a.cir", text);
//   std::vector<LogicalLine> lines = join_lines(file, /*first_line=*/2);  // skip the title
//   StatusOr<std::vector<Token>> toks = tokenize(lines[0]);
//   SourceLoc where = lines[0].loc((*toks)[1].offset);
//   double v; bool ok = parse_number("2.2nF", v);  // v == 2.2e-9
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

// Scans a SPICE number at the start of s (no sign): digits, optional fraction and exponent, then
// an optional scale suffix (f p n u m k g t meg mil, any case) and ignored unit letters
// ("2.2nF", "1kohm", "10Meg"), or RKM notation where the letter is the decimal point ("4k7" =
// 4700, "2r2" = 2.2, "1u5" = 1.5e-6). Returns the value and the number of characters used, or
// nullopt when s does not start with a digit or '.' followed by a digit, or when an 'e' after the
// mantissa has no exponent digits ("1e" is refused, not read as 1 with a unit letter).
struct ScannedNumber {
  double value;
  std::size_t length;
};
std::optional<ScannedNumber> scan_number(std::string_view s);

// True when all of s (with an optional leading sign) is one SPICE number.
bool parse_number(std::string_view s, double& out);

// ASCII lower case.
std::string lower(std::string_view s);

}  // namespace isolink::spice
