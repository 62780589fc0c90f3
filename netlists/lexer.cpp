#include "netlists/lexer.h"

#include <algorithm>
#include <cctype>

namespace isolink::spice {
namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
char to_lower(char c) {
  return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}

// Length of the line once an inline comment (';' anywhere, '$' first or after a blank) is cut.
std::size_t code_length(const std::string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == ';') return i;
    if (s[i] == '$' && (i == 0 || is_blank(s[i - 1]))) return i;
  }
  return s.size();
}

}  // namespace

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = to_lower(c);
  return out;
}

SourceLoc LogicalLine::loc(std::size_t offset) const {
  if (segments.empty()) return SourceLoc{file, 0, 0};
  auto it = std::upper_bound(segments.begin(), segments.end(), offset,
                             [](std::size_t o, const Segment& s) { return o < s.offset; });
  if (it != segments.begin()) --it;
  const std::size_t delta = offset >= it->offset ? offset - it->offset : 0;
  return SourceLoc{file, it->line, it->col + static_cast<int>(delta)};
}

StatusOr<std::vector<LogicalLine>> join_lines(const std::shared_ptr<const SourceFile>& file,
                                              int first_line) {
  std::vector<LogicalLine> out;
  const int n = static_cast<int>(file->lines.size());
  for (int ln = std::max(first_line, 1); ln <= n; ++ln) {
    const std::string& raw = file->lines[ln - 1];
    const std::size_t len = code_length(raw);
    std::size_t first = 0;
    while (first < len && is_blank(raw[first])) ++first;
    if (first == len) continue;       // blank (or only a comment)
    if (raw[first] == '*') continue;  // comment line
    if (raw[first] == '+') {
      if (out.empty())
        return error_at(SourceLoc{file, ln, static_cast<int>(first) + 1},
                        "continuation line '+' without a card before it");
      LogicalLine& cur = out.back();
      cur.text.push_back(' ');
      cur.segments.push_back({cur.text.size(), ln, static_cast<int>(first) + 2});
      cur.text.append(raw, first + 1, len - first - 1);
      continue;
    }
    LogicalLine line;
    line.file = file;
    line.segments.push_back({0, ln, 1});
    line.text.assign(raw, 0, len);
    out.push_back(std::move(line));
  }
  return out;
}

StatusOr<std::vector<Token>> tokenize(const LogicalLine& line) {
  std::vector<Token> toks;
  const std::string& s = line.text;
  const std::string_view sv(s);
  std::vector<std::size_t> open_parens;
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (is_blank(c)) {
      ++i;
      continue;
    }
    switch (c) {
      case '(':
        open_parens.push_back(i);
        toks.push_back({TokenKind::LParen, sv.substr(i, 1), i});
        ++i;
        continue;
      case ')':
        if (open_parens.empty()) return error_at(line.loc(i), "unbalanced ')': no '(' before it");
        open_parens.pop_back();
        toks.push_back({TokenKind::RParen, sv.substr(i, 1), i});
        ++i;
        continue;
      case ',':
        toks.push_back({TokenKind::Comma, sv.substr(i, 1), i});
        ++i;
        continue;
      case '=':
        toks.push_back({TokenKind::Equals, sv.substr(i, 1), i});
        ++i;
        continue;
      case '}':
        return error_at(line.loc(i), "unbalanced '}': no '{' before it");
      case '{': {
        int depth = 0;
        std::size_t j = i;
        for (; j < s.size(); ++j) {
          if (s[j] == '{') ++depth;
          if (s[j] == '}' && --depth == 0) break;
        }
        if (j >= s.size()) return error_at(line.loc(i), "unbalanced '{': missing '}'");
        toks.push_back({TokenKind::Expr, sv.substr(i + 1, j - i - 1), i});
        i = j + 1;
        continue;
      }
      case '\'': {
        const std::size_t j = s.find('\'', i + 1);
        if (j == std::string::npos)
          return error_at(line.loc(i), "unterminated quoted expression: missing closing '");
        toks.push_back({TokenKind::Expr, sv.substr(i + 1, j - i - 1), i});
        i = j + 1;
        continue;
      }
      default:
        break;
    }
    std::size_t j = i;
    while (j < s.size() && !is_blank(s[j]) && s[j] != '(' && s[j] != ')' && s[j] != ',' &&
           s[j] != '=' && s[j] != '{' && s[j] != '}' && s[j] != '\'')
      ++j;
    toks.push_back({TokenKind::Word, sv.substr(i, j - i), i});
    i = j;
  }
  if (!open_parens.empty())
    return error_at(line.loc(open_parens.back()), "unbalanced '(': missing ')'");
  return toks;
}

}  // namespace isolink::spice
