#include "eye/waveform_csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

namespace isolink::eye {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::string_view unquote(std::string_view s) {
  s = trim(s);
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front())
    s = trim(s.substr(1, s.size() - 2));
  return s;
}

bool parse_number(std::string_view s, double* out) {
  s = unquote(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(*out);
}

// ' ' stands for "runs of blanks".
char detect_delimiter(std::string_view line) {
  std::string outside;
  int depth = 0;
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (!quoted && c == '(')
      ++depth;
    else if (!quoted && c == ')' && depth > 0)
      --depth;
    else if (!quoted && depth == 0)
      outside += c;
  }
  for (char d : {',', '\t', ';'})
    if (outside.find(d) != std::string::npos) return d;
  return ' ';
}

void split(std::string_view line, char delim, std::vector<std::string_view>* out) {
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
      size_t k = line.find(delim, start);
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
  while (!out->empty() && trim(out->back()).empty()) out->pop_back();  // trailing delimiters
}

bool all_numeric(const std::vector<std::string_view>& f) {
  double x;
  for (auto s : f)
    if (!parse_number(s, &x)) return false;
  return !f.empty();
}

// Line-by-line cursor over the text with 1-based line numbers.
struct Lines {
  std::string_view text;
  size_t pos = 0;
  int number = 0;
  bool next(std::string_view* line) {
    if (pos >= text.size()) return false;
    size_t e = text.find('\n', pos);
    if (e == std::string_view::npos) e = text.size();
    *line = text.substr(pos, e - pos);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    pos = e + 1;
    ++number;
    return true;
  }
};

std::string lower(std::string_view s) {
  std::string r(s);
  std::transform(r.begin(), r.end(), r.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  return r;
}

}  // namespace

StatusOr<Waveform> parse_differential_csv(std::string_view text, const std::string& source,
                                          const CsvColumns& cols) {
  auto err = [&](int line, const std::string& msg) {
    return Status::Error(line > 0 ? fmt::format("{}:{}: error: {}", source, line, msg)
                                  : fmt::format("{}: error: {}", source, msg));
  };
  if (!cols.diff.empty() && (!cols.p.empty() || !cols.n.empty()))
    return err(0, "give either a differential column or a P and an N column, not both");
  if (cols.p.empty() != cols.n.empty())
    return err(0, "a P column needs an N column (and the reverse): the differential is P - N");

  // 1. Find the header: a non-numeric line followed by a numeric row with as many fields.
  Lines lines{text};
  std::string_view line, prev;
  int prev_number = 0;
  char delim = ',';
  std::vector<std::string_view> header, fields;
  bool found = false;
  size_t data_pos = 0;
  int data_line = 0;
  for (;;) {
    const size_t start = lines.pos;
    if (!lines.next(&line)) break;
    if (trim(line).empty()) continue;
    if (prev_number > 0) {
      char d = detect_delimiter(prev);
      split(prev, d, &header);
      split(line, d, &fields);
      if (header.size() >= 2 && !all_numeric(header) && fields.size() == header.size() &&
          all_numeric(fields)) {
        delim = d;
        found = true;
        data_pos = start;  // re-read this row as data
        data_line = lines.number - 1;
        break;
      }
    }
    prev = line;
    prev_number = lines.number;
  }
  if (!found)
    return err(0,
               "no header found: expected a line of column names (e.g. \"time,v\") followed by "
               "rows of numbers with as many fields");
  const int header_line = prev_number;
  std::vector<std::string> names;
  for (auto h : header) names.emplace_back(unquote(h));

  auto resolve = [&](const std::string& ref, const char* flag, int fallback,
                     size_t* idx) -> Status {
    if (ref.empty()) {
      *idx = static_cast<size_t>(fallback);
      return Status::Ok();
    }
    for (size_t k = 0; k < names.size(); ++k)
      if (names[k] == ref) return (*idx = k, Status::Ok());
    for (size_t k = 0; k < names.size(); ++k)
      if (lower(names[k]) == lower(ref)) return (*idx = k, Status::Ok());
    int n = 0;
    auto [ptr, ec] = std::from_chars(ref.data(), ref.data() + ref.size(), n);
    if (ec == std::errc() && ptr == ref.data() + ref.size() && n >= 1 &&
        static_cast<size_t>(n) <= names.size())
      return (*idx = static_cast<size_t>(n - 1), Status::Ok());
    std::string list;
    for (const auto& nm : names) list += (list.empty() ? "" : ", ") + nm;
    return err(header_line, fmt::format("{} '{}': no such column (columns: {}; or a 1-based index "
                                        "up to {})",
                                        flag, ref, list, names.size()));
  };
  size_t it = 0, id = 1, ip = 0, in = 0;
  const bool pn = !cols.p.empty();
  if (Status s = resolve(cols.time, "time column", 0, &it); !s.ok()) return s;
  if (pn) {
    if (Status s = resolve(cols.p, "P column", 0, &ip); !s.ok()) return s;
    if (Status s = resolve(cols.n, "N column", 0, &in); !s.ok()) return s;
  } else if (Status s = resolve(cols.diff, "differential column", it == 1 ? 0 : 1, &id); !s.ok()) {
    return s;
  }

  // 2. Rows.
  Waveform w;
  std::vector<double> v;
  const size_t approx_rows =
      std::count(text.begin() + static_cast<std::ptrdiff_t>(data_pos), text.end(), '\n') + 1;
  w.time.reserve(approx_rows);
  v.reserve(approx_rows);
  Lines rows{text, data_pos, data_line};
  int prev_row_line = 0;
  while (rows.next(&line)) {
    if (trim(line).empty()) continue;
    split(line, delim, &fields);
    if (fields.size() != names.size())
      return err(rows.number, fmt::format("expected {} fields like the header (line {}), found {}",
                                          names.size(), header_line, fields.size()));
    auto get = [&](size_t k, double* x) -> Status {
      if (parse_number(fields[k], x)) return Status::Ok();
      return err(rows.number, fmt::format("column {} ('{}'): expected a number, found '{}'", k + 1,
                                          names[k], std::string(trim(fields[k]))));
    };
    double t = 0, x = 0, y = 0;
    if (Status s = get(it, &t); !s.ok()) return s;
    if (pn) {
      if (Status s = get(ip, &x); !s.ok()) return s;
      if (Status s = get(in, &y); !s.ok()) return s;
      x -= y;
    } else if (Status s = get(id, &x); !s.ok()) {
      return s;
    }
    if (!w.time.empty() && !(t > w.time.back()))
      return err(rows.number, fmt::format("time {:g} is not after {:g} on line {}: time must "
                                          "increase from row to row",
                                          t, w.time.back(), prev_row_line));
    w.time.push_back(t);
    v.push_back(x);
    prev_row_line = rows.number;
  }
  if (w.time.size() < 2) return err(0, "fewer than two samples after the header");
  w.add_column(pn ? names[ip] + "-" + names[in] : names[id], std::move(v));
  return w;
}

StatusOr<Waveform> read_differential_csv(const std::string& path, const CsvColumns& cols) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": error: cannot open the file");
  std::string text;
  in.seekg(0, std::ios::end);
  const auto size = in.tellg();
  if (size > 0) {
    text.resize(static_cast<size_t>(size));
    in.seekg(0);
    in.read(text.data(), size);
  }
  if (!in) return Status::Error(path + ": error: cannot read the file");
  return parse_differential_csv(text, path, cols);
}

}  // namespace isolink::eye
