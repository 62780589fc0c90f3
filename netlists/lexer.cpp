#include "netlists/lexer.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

namespace isolink::spice {
namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}
bool is_alpha(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) != 0;
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

std::optional<ScannedNumber> scan_number(std::string_view s) {
  std::size_t i = 0;
  const std::size_t n = s.size();
  char buf[64];
  std::size_t b = 0;
  auto put = [&](char c) {
    if (b < sizeof(buf) - 12) buf[b++] = c;
  };
  bool digits = false;
  int dropped_int_digits = 0;  // integer digits beyond the buffer (absurdly long numbers)
  while (i < n && is_digit(s[i])) {
    if (b < sizeof(buf) - 12)
      buf[b++] = s[i];
    else
      ++dropped_int_digits;
    ++i, digits = true;
  }
  if (i < n && s[i] == '.') {
    if (i + 1 < n && is_digit(s[i + 1])) {
      put('.');
      ++i;
      while (i < n && is_digit(s[i])) put(s[i++]);
      digits = true;
    } else if (digits) {
      ++i;  // "5." is 5
    }
  }
  if (!digits) return std::nullopt;
  long exponent = dropped_int_digits;
  // RKM notation (IEC 60062): the scale letter stands for the decimal point, "4k7" = 4.7e3,
  // "2r2" = 2.2 ('r': no scale), "1u5" = 1.5e-6. Only after plain integer digits.
  char rkm = 0;
  if (i + 1 < n && i > 0 && is_digit(s[i - 1]) && is_digit(s[i + 1]) &&
      std::string_view("fpnumkgtrFPNUMKGTR").find(s[i]) != std::string_view::npos &&
      s.substr(0, i).find('.') == std::string_view::npos) {
    rkm = to_lower(s[i++]);
    put('.');
    while (i < n && is_digit(s[i])) put(s[i++]);
  }
  if (!rkm && i < n && (s[i] == 'e' || s[i] == 'E')) {
    std::size_t j = i + 1;
    bool neg = false;
    if (j < n && (s[j] == '+' || s[j] == '-')) neg = s[j++] == '-';
    if (j < n && is_digit(s[j])) {
      long e = 0;
      while (j < n && is_digit(s[j])) {
        if (e < 100000) e = e * 10 + (s[j] - '0');
        ++j;
      }
      exponent += neg ? -e : e;
      i = j;
    } else {
      return std::nullopt;  // "1e", "1e+": an exponent with no digits is not a unit letter
    }
  }
  double scale = 1.0;
  if (rkm) {
    static constexpr std::string_view kLetters = "fpnumkgt";
    static constexpr int kExponents[] = {-15, -12, -9, -6, -3, 3, 9, 12};
    const std::size_t k = kLetters.find(rkm);
    if (k != std::string_view::npos) exponent += kExponents[k];
    while (i < n && is_alpha(s[i])) ++i;  // unit letters
  } else if (i < n && is_alpha(s[i])) {
    auto starts = [&](const char* w) {
      for (std::size_t k = 0; w[k]; ++k)
        if (i + k >= n || to_lower(s[i + k]) != w[k]) return false;
      return true;
    };
    if (starts("meg")) {
      exponent += 6;
    } else if (starts("mil")) {
      scale = 25.4e-6;
    } else {
      switch (to_lower(s[i])) {
        case 'f':
          exponent -= 15;
          break;
        case 'p':
          exponent -= 12;
          break;
        case 'n':
          exponent -= 9;
          break;
        case 'u':
          exponent -= 6;
          break;
        case 'm':
          exponent -= 3;
          break;
        case 'k':
          exponent += 3;
          break;
        case 'g':
          exponent += 9;
          break;
        case 't':
          exponent += 12;
          break;
        default:
          break;
      }
    }
    while (i < n && is_alpha(s[i])) ++i;  // the scale letters and any unit
  }
  if (exponent != 0) {
    auto r = std::to_chars(buf + b + 1, buf + sizeof(buf), exponent);
    buf[b] = 'e';
    b = static_cast<std::size_t>(r.ptr - buf);
  }
  double value = 0.0;
  if (std::from_chars(buf, buf + b, value).ec == std::errc::result_out_of_range)
    value = exponent > 0 ? HUGE_VAL : 0.0;
  return ScannedNumber{value * scale, i};
}

bool parse_number(std::string_view s, double& out) {
  bool neg = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    neg = s[0] == '-';
    s.remove_prefix(1);
  }
  auto r = scan_number(s);
  if (!r || r->length != s.size()) return false;
  out = neg ? -r->value : r->value;
  return true;
}

}  // namespace isolink::spice
