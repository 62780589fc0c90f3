#include "eye/scope_formats.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "eye/csv_lines.h"

namespace isolink::eye {
namespace {

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

std::string upper_compact(std::string_view s) {
  std::string r;
  for (char c : s)
    if (c != ' ' && c != '_' && c != '-' && c != '.')
      r += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return r;
}

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string strip_zeros(std::string_view digits) {
  size_t i = 0;
  while (i + 1 < digits.size() && digits[i] == '0') ++i;
  return std::string(digits.substr(i));
}

// A name without its unit part, and that unit: "Time (s)" -> "Time", s; "C1 in V" -> "C1", V;
// "in s" -> "", s; "Time [s]" -> "Time", s.
std::pair<std::string, std::optional<Unit>> split_name_unit(std::string_view name) {
  name = trim_cell(name);
  if (!name.empty() && (name.back() == ')' || name.back() == ']')) {
    const char open = name.back() == ')' ? '(' : '[';
    const size_t k = name.rfind(open);
    if (k != std::string_view::npos)
      if (auto u = parse_unit(name.substr(k)))
        return {std::string(trim_cell(name.substr(0, k))), u};
  }
  const std::string lo = lower(name);
  size_t k = lo.rfind(" in ");
  size_t skip = 4;
  if (lo.rfind("in ", 0) == 0 && k == std::string::npos) {
    k = 0;
    skip = 3;
  }
  if (k != std::string::npos)
    if (auto u = parse_unit(name.substr(k + skip)))
      return {std::string(trim_cell(name.substr(0, k))), u};
  return {std::string(name), std::nullopt};
}

bool time_name(std::string_view bare) {
  static const char* kNames[] = {"time",   "temps", "zeit",    "tiempo", "tempo",
                                 "x-axis", "x",     "sec",     "second", "seconds",
                                 "t",      "xaxis", "time(s)", "time s"};
  const std::string lo = lower(trim_cell(bare));
  return std::any_of(std::begin(kNames), std::end(kNames), [&](const char* n) { return lo == n; });
}

// Preamble keys that may sit right above the data with as many fields as a data row.
bool preamble_key(std::string_view first) {
  static const char* kKeys[] = {"record length",
                                "sample interval",
                                "trigger point",
                                "trigger time",
                                "vertical units",
                                "vertical scale",
                                "vertical offset",
                                "horizontal units",
                                "horizontal scale",
                                "horizontal offset",
                                "pt fmt",
                                "yzero",
                                "probe atten",
                                "model number",
                                "firmware version",
                                "serial number",
                                "model",
                                "label"};
  const std::string lo = lower(unquote(first));
  return std::any_of(std::begin(kKeys), std::end(kKeys), [&](const char* n) { return lo == n; });
}

// A data row: every non-empty field a number, at least one.
bool numeric_row(const std::vector<std::string_view>& f, bool dc) {
  size_t n = 0;
  double x;
  for (auto s : f) {
    if (trim_cell(s).empty()) continue;
    if (!parse_cell(s, dc, &x)) return false;
    ++n;
  }
  return n > 0;
}

bool guess_decimal_comma(char delim, const std::vector<std::string_view>& f) {
  if (delim == ',') return false;
  bool comma = false;
  for (auto s : f) {
    s = unquote(s);
    if (s.find('.') != std::string_view::npos) return false;
    comma = comma || s.find(',') != std::string_view::npos;
  }
  return comma;
}

// A units row: every non-empty field a unit or a number (Rigol puts Start/Increment values in
// it), at least one unit.
bool units_row(const std::vector<std::string_view>& f, bool dc) {
  size_t units = 0;
  double x;
  for (auto s : f) {
    if (trim_cell(s).empty()) continue;
    if (parse_unit(unquote(s)))
      ++units;
    else if (!parse_cell(s, dc, &x))
      return false;
  }
  return units > 0;
}

std::optional<double> number_of(const std::string* s) {
  if (!s) return std::nullopt;
  std::string_view v = trim_cell(*s);
  // "2.000000e-08" or "1.00V" / "2.0E-10s": the leading number
  size_t e = 0;
  while (e < v.size() && (std::isdigit(static_cast<unsigned char>(v[e])) || v[e] == '.' ||
                          v[e] == '-' || v[e] == '+' || v[e] == 'e' || v[e] == 'E'))
    ++e;
  double x;
  if (e == 0) return std::nullopt;
  auto [ptr, ec] = std::from_chars(v.data(), v.data() + e, x);
  if (ec != std::errc() || !std::isfinite(x)) return std::nullopt;
  return x;
}

void key_values(const std::vector<std::string>& head, size_t end, bool dc,
                std::vector<std::pair<std::string, std::string>>* out) {
  std::vector<std::string_view> f;
  for (size_t i = 0; i < end && i < head.size(); ++i) {
    std::string_view line = trim_cell(head[i]);
    if (line.empty()) continue;
    const char delim = detect_delimiter(line);
    const size_t c = line.find(':');
    const size_t d = delim == ' ' ? std::string_view::npos : line.find(delim);
    if (c != std::string_view::npos && c > 0 && (d == std::string_view::npos || c < d)) {
      // "Key: value" (Infiniium) or "Key:value:" (R&S)
      std::string_view v = trim_cell(line.substr(c + 1));
      if (!v.empty() && v.back() == ':') v.remove_suffix(1);
      out->emplace_back(std::string(unquote(line.substr(0, c))), std::string(unquote(v)));
      continue;
    }
    split_fields(line, delim, &f);
    if (f.size() >= 2 && !numeric_row({f[0]}, dc))
      out->emplace_back(std::string(unquote(f[0])), std::string(unquote(f[1])));
  }
}

// The sample interval and first time a preamble gives, if any.
bool interval_from_preamble(const ScopeLayout& l, double* t0, double* dt, std::string* from) {
  for (const char* k : {"XInc", "XIncrement", "Sample Interval", "Increment", "Resolution",
                        "Sampling Interval", "dt"}) {
    const std::optional<double> d = number_of(l.find(k));
    if (!d || !(*d > 0)) continue;
    *dt = *d;
    *t0 = 0;
    std::string start = "0";
    for (const char* s : {"XOrg", "XOrigin", "XStart", "Start", "Horizontal Offset"})
      if (const std::optional<double> x = number_of(l.find(s))) {
        *t0 = *x;
        start = s;
        break;
      }
    if (start == "0")
      if (const std::optional<double> tp = number_of(l.find("Trigger Point"))) {
        *t0 = -*tp * *dt;
        start = "-Trigger Point * " + std::string(k);
      }
    *from = fmt::format("rebuilt: t = {} + row * {} ({:g} + row * {:g} s)", start, k, *t0, *dt);
    return true;
  }
  return false;
}

}  // namespace

std::optional<Unit> parse_unit(std::string_view token) {
  std::string_view s = trim_cell(token);
  if (s.size() >= 2 &&
      ((s.front() == '(' && s.back() == ')') || (s.front() == '[' && s.back() == ']')))
    s = trim_cell(s.substr(1, s.size() - 2));
  std::string lo = lower(s);
  if (lo.rfind("in ", 0) == 0) lo = std::string(trim_cell(std::string_view(lo).substr(3)));
  // micro as "u", U+00B5 or U+03BC
  for (const char* mu : {"\xC2\xB5", "\xCE\xBC"})
    if (lo.rfind(mu, 0) == 0) lo = "u" + lo.substr(2);
  struct Entry {
    const char* w;
    UnitKind k;
    double scale;
  };
  static const Entry kUnits[] = {{"s", UnitKind::kTime, 1},
                                 {"sec", UnitKind::kTime, 1},
                                 {"secs", UnitKind::kTime, 1},
                                 {"second", UnitKind::kTime, 1},
                                 {"seconds", UnitKind::kTime, 1},
                                 {"ms", UnitKind::kTime, 1e-3},
                                 {"msec", UnitKind::kTime, 1e-3},
                                 {"us", UnitKind::kTime, 1e-6},
                                 {"usec", UnitKind::kTime, 1e-6},
                                 {"ns", UnitKind::kTime, 1e-9},
                                 {"nsec", UnitKind::kTime, 1e-9},
                                 {"ps", UnitKind::kTime, 1e-12},
                                 {"v", UnitKind::kVolt, 1},
                                 {"volt", UnitKind::kVolt, 1},
                                 {"volts", UnitKind::kVolt, 1},
                                 {"mv", UnitKind::kVolt, 1e-3},
                                 {"millivolt", UnitKind::kVolt, 1e-3},
                                 {"millivolts", UnitKind::kVolt, 1e-3},
                                 {"uv", UnitKind::kVolt, 1e-6},
                                 {"kv", UnitKind::kVolt, 1e3},
                                 {"sequence", UnitKind::kIndex, 1},
                                 {"points", UnitKind::kIndex, 1},
                                 {"point", UnitKind::kIndex, 1},
                                 {"pts", UnitKind::kIndex, 1},
                                 {"samples", UnitKind::kIndex, 1},
                                 {"sample", UnitKind::kIndex, 1},
                                 {"index", UnitKind::kIndex, 1},
                                 {"a", UnitKind::kOther, 1},
                                 {"ma", UnitKind::kOther, 1e-3},
                                 {"ua", UnitKind::kOther, 1e-6},
                                 {"amp", UnitKind::kOther, 1},
                                 {"amps", UnitKind::kOther, 1},
                                 {"w", UnitKind::kOther, 1},
                                 {"db", UnitKind::kOther, 1},
                                 {"dbm", UnitKind::kOther, 1},
                                 {"hz", UnitKind::kOther, 1},
                                 {"div", UnitKind::kOther, 1},
                                 {"%", UnitKind::kOther, 1},
                                 {"u", UnitKind::kOther, 1}};
  for (const Entry& e : kUnits)
    if (lo == e.w) return Unit{e.k, e.scale, std::string(trim_cell(token))};
  return std::nullopt;
}

std::string canonical_channel(std::string_view name) {
  const std::string bare = split_name_unit(unquote(name)).first;
  const std::string u = upper_compact(bare);
  auto after = [&](std::initializer_list<const char*> prefixes, std::string* rest) {
    for (const char* p : prefixes) {
      const std::string_view pv(p);
      if (u.size() > pv.size() && u.compare(0, pv.size(), pv) == 0) {
        *rest = u.substr(pv.size());
        return true;
      }
    }
    return false;
  };
  std::string rest;
  if (all_digits(u)) return "CH" + strip_zeros(u);
  if (after({"CHANNEL", "CHAN", "CANAL", "KANAL", "CH", "C"}, &rest)) {
    if (all_digits(rest)) return "CH" + strip_zeros(rest);
    if (rest.size() == 1 && rest[0] >= 'A' && rest[0] <= 'H') return "CH" + rest;
  }
  if (u.size() == 1 && u[0] >= 'A' && u[0] <= 'H') return "CH" + u;
  if (u == "MATH" || u == "M" || u == "FUNC") return "MATH";
  if (after({"MATH", "FUNC", "M", "F"}, &rest) && all_digits(rest))
    return "MATH" + strip_zeros(rest);
  if (after({"REF", "R"}, &rest) && all_digits(rest)) return "REF" + strip_zeros(rest);
  if (after({"D"}, &rest) && all_digits(rest)) return "D" + strip_zeros(rest);
  return "";
}

namespace {

// The fields after the key of the first preamble row (lines [0, end)) whose first field is `key`
// (ignoring case and a trailing '=' with blanks, as in Rigol's "Attenuation = "), and its 0-based
// line; nullopt when there is none.
std::optional<std::pair<size_t, std::vector<std::string>>> preamble_row(
    const std::vector<std::string>& head, size_t end, std::string_view key) {
  std::vector<std::string_view> f;
  for (size_t i = 0; i < end && i < head.size(); ++i) {
    split_fields(head[i], ',', &f);
    if (f.size() < 2) continue;
    std::string_view k = unquote(f[0]);
    while (!k.empty() && (k.back() == '=' || k.back() == ' ')) k.remove_suffix(1);
    if (lower(k) != lower(key)) continue;
    std::vector<std::string> values;
    for (size_t j = 1; j < f.size(); ++j) values.emplace_back(unquote(f[j]));
    return std::pair{i, std::move(values)};
  }
  return std::nullopt;
}

// "10", "10X", "10x" -> 10.
std::optional<double> probe_factor(std::string v) {
  while (!v.empty() && (v.back() == 'X' || v.back() == 'x')) v.pop_back();
  return number_of(&v);
}

// Rigol DS1052E CSV: a `"Channel Data","CH 1","CH 2"` row names the value columns (whose header
// only says "Voltage (V)"), and `"Attenuation = ",10,1` gives each channel's probe factor with
// `"Scale (V/DIV) = ",0.1,2` its scale before the probe. The scope writes probe-tip volts (its
// 8-bit counts, 25 a division, times Scale x Attenuation / 25: the real export in
// tests/eye/data/real steps by 0.04 V on CH 1 at 0.1 V/div and 10X), so the values are read as
// they are; check_probe_step refuses a channel whose values step by the scale without the probe
// factor (the reader measures the step over the whole record).
Status rigol_channel_rows(const std::vector<std::string>& head, size_t pre_end, ScopeLayout* l,
                          const std::string& source) {
  const auto names = preamble_row(head, pre_end, "Channel Data");
  if (!names) return Status::Ok();
  std::vector<size_t> values;  // the value columns, in order
  for (size_t k = 0; k < l->columns.size(); ++k)
    if (!l->columns[k].time_like && !l->columns[k].meta) values.push_back(k);
  const int line = static_cast<int>(names->first) + 1;
  if (names->second.size() != values.size())
    return Status::Error(fmt::format(
        "{}:{}: error: the \"Channel Data\" row names {} channel{} but the data rows hold {} "
        "value column{}: the file contradicts itself",
        source, line, names->second.size(), names->second.size() == 1 ? "" : "s", values.size(),
        values.size() == 1 ? "" : "s"));
  for (size_t i = 0; i < values.size(); ++i) {
    ScopeColumn& c = l->columns[values[i]];
    c.name = names->second[i];
    c.channel = canonical_channel(c.name);
  }
  const auto att = preamble_row(head, pre_end, "Attenuation");
  if (!att) return Status::Ok();
  const auto scale = preamble_row(head, pre_end, "Scale (V/DIV)");
  l->probe_line = static_cast<int>(att->first) + 1;
  for (size_t i = 0; i < values.size(); ++i) {
    ScopeColumn& c = l->columns[values[i]];
    const std::optional<double> a =
        i < att->second.size() ? probe_factor(att->second[i]) : std::nullopt;
    if (!a || !(*a > 0))
      return Status::Error(
          fmt::format("{}:{}: error: no probe factor for {} in the "
                      "\"Attenuation\" row: expected a number such as 10 or 10X",
                      source, l->probe_line, c.name));
    c.probe_factor = *a;
    const std::optional<double> sc =
        scale && i < scale->second.size() ? number_of(&scale->second[i]) : std::nullopt;
    if (sc && *sc > 0) c.volts_per_div = *sc;
  }
  return Status::Ok();
}

}  // namespace

const std::string* ScopeLayout::find(std::string_view key) const {
  const std::string k = lower(key);
  for (const auto& [key_, value] : preamble)
    if (lower(key_) == k) return &value;
  return nullptr;
}

namespace {

// detect_layout's work: the three format detectors, tried in order until one names the layout,
// then the time column. One object per call; it reads `head` and fills `l_`.
class LayoutDetector {
 public:
  LayoutDetector(const std::vector<std::string>& head, const std::string& source, bool more_lines)
      : head_(head), source_(source), more_lines_(more_lines) {}

  StatusOr<ScopeLayout> run(const std::vector<std::pair<std::string, std::string>>& extra) {
    if (!head_.empty() && head_[0].size() >= 2 &&
        ((head_[0][0] == '\xFF' && head_[0][1] == '\xFE') ||
         (head_[0][0] == '\xFE' && head_[0][1] == '\xFF')))
      return err(1, "the file is UTF-16 text: save or convert it as UTF-8 (or ASCII) CSV");
    if (Status st = key_value_header(); !st.ok()) return st;
    if (l_.name.empty()) tektronix_classic();
    if (l_.name.empty())
      if (Status st = names_and_units(); !st.ok()) return st;
    l_.preamble.insert(l_.preamble.end(), extra.begin(), extra.end());
    if (Status st = time_column(); !st.ok()) return st;
    return std::move(l_);
  }

 private:
  Status err(int line, const std::string& msg) const {
    return Status::Error(line > 0 ? fmt::format("{}:{}: error: {}", source_, line, msg)
                                  : fmt::format("{}: error: {}", source_, msg));
  }
  static int line_no(size_t i) { return static_cast<int>(i) + 1; }
  size_t next_nonblank(size_t i) const {
    while (i < head_.size() && trim_cell(head_[i]).empty()) ++i;
    return i;
  }
  std::optional<size_t> prev_nonblank(size_t i) const {
    while (i > 0) {
      --i;
      if (!trim_cell(head_[i]).empty()) return i;
    }
    return std::nullopt;
  }

  // The columns from a names row and a units row (either may be absent) over nfields fields.
  void finish_columns(const std::vector<std::string_view>& names,
                      const std::vector<std::string_view>* units, size_t nfields) {
    const size_t n = std::max(names.size(), nfields);
    for (size_t k = 0; k < n; ++k) {
      ScopeColumn c;
      c.field = k;
      const std::string raw = k < names.size() ? std::string(unquote(names[k])) : std::string();
      auto [bare, unit] = split_name_unit(raw);
      c.name = raw.empty() ? fmt::format("column {}", k + 1) : raw;
      if (units && k < units->size())
        if (auto u = parse_unit(unquote((*units)[k]))) unit = u;
      if (unit) c.unit = *unit;
      c.channel = raw.empty() ? "" : canonical_channel(raw);
      c.time_like = c.unit.kind == UnitKind::kTime || c.unit.kind == UnitKind::kIndex ||
                    (!raw.empty() && time_name(bare.empty() ? raw : bare));
      const std::string lo = lower(bare);
      c.meta = lo == "start" || lo == "increment";
      if (!raw.empty() || k < nfields) l_.columns.push_back(std::move(c));
    }
  }

  // 1. "Key: value" header ending in "Data:" (Keysight Infiniium).
  Status key_value_header() {
    for (size_t i = 0; i < head_.size(); ++i) {
      if (lower(trim_cell(head_[i])) != "data:") continue;
      l_.name = "key: value header";
      key_values(head_, i, false, &l_.preamble);
      const size_t d = next_nonblank(i + 1);
      if (d >= head_.size()) return err(line_no(i), "no data after \"Data:\"");
      l_.data_line = line_no(d);
      l_.delim = detect_delimiter(head_[d]);
      split_fields(head_[d], l_.delim, &f_);
      l_.decimal_comma = guess_decimal_comma(l_.delim, f_);
      if (!numeric_row(f_, l_.decimal_comma))
        return err(l_.data_line,
                   fmt::format("expected a row of numbers after \"Data:\", found '{}'",
                               trim_cell(head_[d])));
      l_.data_fields = f_.size();
      key_value_columns();
      break;
    }
    return Status::Ok();
  }
  // The columns of a "Key: value" file: its YUnits, XUnits and Source lines name them.
  void key_value_columns() {
    const std::string* yu = l_.find("YUnits");
    const std::string* xu = l_.find("XUnits");
    const std::string* src = l_.find("Source");
    if (f_.size() == 1) {
      ScopeColumn c;
      c.name = src ? *src : "Y";
      c.channel = canonical_channel(c.name);
      if (yu)
        if (auto u = parse_unit(*yu)) c.unit = *u;
      l_.columns.push_back(c);
      return;
    }
    ScopeColumn t;
    t.name = "time";
    t.time_like = true;
    if (xu)
      if (auto u = parse_unit(*xu)) t.unit = *u;
    l_.columns.push_back(t);
    for (size_t k = 1; k < f_.size(); ++k) {
      ScopeColumn c;
      c.field = k;
      c.name = f_.size() == 2 && src ? *src : fmt::format("column {}", k + 1);
      c.channel = canonical_channel(c.name);
      if (yu)
        if (auto u = parse_unit(*yu)) c.unit = *u;
      l_.columns.push_back(c);
    }
    l_.time = 0;
  }

  // 2. Tektronix TDS/TBS classic: "Record Length,2500,Points,-0.000025,0.04," from line 1.
  void tektronix_classic() {
    const size_t d = next_nonblank(0);
    if (d >= head_.size()) return;
    split_fields(head_[d], ',', &f_);
    double x;
    if (!(f_.size() >= 5 && parse_cell(f_[3], false, &x) && parse_cell(f_[4], false, &x) &&
          !trim_cell(f_[0]).empty() && !parse_cell(f_[0], false, &x)))
      return;
    l_.name = "tektronix classic";
    l_.delim = ',';
    l_.data_line = line_no(d);
    l_.data_fields = f_.size();
    for (size_t i = d; i < head_.size(); ++i) {
      split_fields(head_[i], ',', &g_);
      if (g_.size() >= 2 && !trim_cell(g_[0]).empty())
        l_.preamble.emplace_back(std::string(unquote(g_[0])), std::string(unquote(g_[1])));
    }
    ScopeColumn t;
    t.name = "time";
    t.field = 3;
    t.time_like = true;
    t.unit = Unit{UnitKind::kTime, 1, "s"};
    if (const std::string* hu = l_.find("Horizontal Units"))
      if (auto u = parse_unit(*hu)) t.unit = *u;
    ScopeColumn c;
    const std::string* src = l_.find("Source");
    c.name = src && !src->empty() ? *src : "value";
    c.channel = canonical_channel(c.name);
    c.field = 4;
    if (const std::string* vu = l_.find("Vertical Units"))
      if (auto u = parse_unit(*vu)) c.unit = *u;
    l_.columns = {t, c};
    l_.time = 0;
  }

  // 3. Names / units rows above the first run of data rows.
  Status names_and_units() {
    size_t d = head_.size();
    if (Status st = find_data_row(&d); !st.ok()) return st;
    l_.data_line = line_no(d);
    split_fields(head_[d], l_.delim, &f_);
    l_.data_fields = f_.size();
    std::vector<std::string_view> units, names;
    std::optional<size_t> names_at;
    header_rows(d, &names, &units, &names_at);
    const size_t pre_end = names_at ? *names_at : (l_.units_line ? l_.units_line - 1 : d);
    key_values(head_, pre_end, l_.decimal_comma, &l_.preamble);
    finish_columns(names, units.empty() ? nullptr : &units, l_.data_fields);
    if (Status st = rigol_channel_rows(head_, pre_end, &l_, source_); !st.ok()) return st;
    l_.name = !names.empty() ? (units.empty() ? "header" : "header + units row")
                             : (!units.empty() ? "units row" : "no header");
    return rigol_start_increment(units);
  }

  // The first row of numbers that the next non-blank row continues (same field count or numbers
  // too): a numeric line inside a preamble is followed by text with another field count.
  Status find_data_row(size_t* d) {
    for (size_t i = 0; i < head_.size() && *d == head_.size(); ++i) {
      if (trim_cell(head_[i]).empty()) continue;
      const char delim = detect_delimiter(head_[i]);
      split_fields(head_[i], delim, &f_);
      const bool dc = guess_decimal_comma(delim, f_);
      if (!numeric_row(f_, dc)) continue;
      const size_t j = next_nonblank(i + 1);
      bool ok = true;
      if (j < head_.size()) {
        split_fields(head_[j], delim, &g_);
        ok = g_.size() == f_.size() || numeric_row(g_, dc);
      }
      if (ok) {
        *d = i;
        l_.delim = delim;
        l_.decimal_comma = dc;
      }
    }
    if (*d < head_.size()) return Status::Ok();
    std::string last;
    int last_no = 0;
    for (size_t i = 0; i < head_.size(); ++i)
      if (!trim_cell(head_[i]).empty()) {
        last = std::string(trim_cell(head_[i]).substr(0, 60));
        last_no = line_no(i);
      }
    if (last_no == 0) return err(0, "the file is empty");
    return err(
        last_no,
        fmt::format("no data found{}: expected rows of numbers (e.g. \"-1.0e-06,0.52\"), "
                    "optionally under a line of names (e.g. \"TIME,CH1,CH2\") and a "
                    "units row (e.g. \"s,V,V\"); the last line read was '{}'",
                    more_lines_ ? fmt::format(" in the first {} lines", head_.size()) : "", last));
  }

  // Above the data row d: a units row ("s,V,V"), and above it (or above d) a names row.
  void header_rows(size_t d, std::vector<std::string_view>* names,
                   std::vector<std::string_view>* units, std::optional<size_t>* names_at) {
    std::optional<size_t> above = prev_nonblank(d);
    if (above) {
      split_fields(head_[*above], l_.delim, &g_);
      if (units_row(g_, l_.decimal_comma) && !numeric_row(g_, l_.decimal_comma)) {
        *units = g_;
        l_.units_line = line_no(*above);
        above = prev_nonblank(*above);
      }
    }
    if (!above) return;
    split_fields(head_[*above], l_.delim, &g_);
    double x;
    bool tail_numeric = g_.size() >= 2;
    for (size_t k = 1; k < g_.size(); ++k)
      tail_numeric = tail_numeric && parse_cell(g_[k], l_.decimal_comma, &x);
    const bool first_time = !g_.empty() && time_name(split_name_unit(unquote(g_[0])).first);
    const bool is_names = !numeric_row(g_, l_.decimal_comma) && g_.size() >= 2 &&
                          !(g_.size() >= 1 && preamble_key(g_[0])) &&
                          !(tail_numeric && !first_time && units->empty());
    if (is_names) {
      *names = g_;
      *names_at = *above;
      l_.header_line = line_no(*above);
    }
  }

  // Rigol X,CH1,Start,Increment with the values under Start and Increment.
  Status rigol_start_increment(const std::vector<std::string_view>& units) {
    int ks = -1, ki = -1;
    for (size_t k = 0; k < l_.columns.size(); ++k) {
      const std::string lo = lower(split_name_unit(l_.columns[k].name).first);
      if (lo == "start") ks = static_cast<int>(k);
      if (lo == "increment") ki = static_cast<int>(k);
    }
    if (ks < 0 || ki < 0) return Status::Ok();
    double s = 0, inc = 0;
    const std::vector<std::string_view>& src = units.empty() ? f_ : units;
    const size_t fs = l_.columns[static_cast<size_t>(ks)].field;
    const size_t fi = l_.columns[static_cast<size_t>(ki)].field;
    if (!(fs < src.size() && fi < src.size() && parse_cell(src[fs], l_.decimal_comma, &s) &&
          parse_cell(src[fi], l_.decimal_comma, &inc) && inc > 0))
      return err(l_.units_line ? l_.units_line : l_.data_line,
                 "the header names Start and Increment columns but no numbers were found under "
                 "them: expected e.g. \"Sequence,Volt,-1e-05,1e-09\"");
    l_.name = "rigol start/increment";
    l_.t0 = s;
    l_.dt = inc;
    l_.time_is_index = true;
    l_.time = 0;
    l_.columns[0].time_like = true;
    l_.time_from = fmt::format("rebuilt: t = Start + X * Increment ({:g} + X * {:g} s)", s, inc);
    // the data rows hold fewer fields than the header when Start/Increment are empty
    std::erase_if(l_.columns,
                  [&](const ScopeColumn& c) { return c.meta && c.field >= l_.data_fields; });
    return Status::Ok();
  }

  // Which column is time, and how time is rebuilt when it counts samples or is absent.
  Status time_column() {
    if (l_.time < 0 && !l_.columns.empty()) {
      for (size_t k = 0; k < l_.columns.size(); ++k)
        if (l_.columns[k].time_like) {
          l_.time = static_cast<int>(k);
          break;
        }
      const bool signals_only = l_.columns.size() == 1;
      if (l_.time < 0 && !signals_only) l_.time = 0;  // default: the first column
    }
    if (l_.time < 0) {
      if (!interval_from_preamble(l_, &l_.t0, &l_.dt, &l_.time_from))
        return err(l_.data_line,
                   "one column of values and no time: expected a time column, or the sample "
                   "interval in the preamble ('Sample Interval', 'XInc'; for an R&S .Wfm.csv "
                   "keep its header file NAME.csv or NAME.bin beside it)");
      return Status::Ok();
    }
    ScopeColumn& tc = l_.columns[static_cast<size_t>(l_.time)];
    tc.time_like = true;
    if (tc.unit.kind == UnitKind::kIndex && !l_.time_is_index) {
      double t0 = 0, dt = 0;
      std::string from;
      if (!interval_from_preamble(l_, &t0, &dt, &from))
        return err(l_.units_line ? l_.units_line : l_.header_line,
                   fmt::format("column {} ('{}') counts samples ({}) and no sample interval was "
                               "found: expected Start and Increment columns, or a 'Sample "
                               "Interval' / 'XInc' line in the preamble",
                               tc.field + 1, tc.name, tc.unit.text));
      l_.time_is_index = true;
      l_.t0 = t0;
      l_.dt = dt;
      l_.time_from = fmt::format("rebuilt from sample numbers: t = {:g} + x * {:g} s", t0, dt);
    }
    if (l_.time_from.empty())
      l_.time_from = fmt::format("column {} ('{}'){}", tc.field + 1, tc.name,
                                 tc.unit.scale != 1 ? fmt::format(" in {}", tc.unit.text) : "");
    if (tc.unit.kind != UnitKind::kNone && tc.unit.kind != UnitKind::kTime &&
        tc.unit.kind != UnitKind::kIndex)
      return err(l_.units_line ? l_.units_line : l_.header_line,
                 fmt::format("the time column {} ('{}') is in {}, not seconds", tc.field + 1,
                             tc.name, tc.unit.text));
    return Status::Ok();
  }

  const std::vector<std::string>& head_;
  const std::string& source_;
  const bool more_lines_;
  ScopeLayout l_;
  std::vector<std::string_view> f_, g_;  // the fields of the data row, of the row looked at
};

}  // namespace

StatusOr<ScopeLayout> detect_layout(
    const std::vector<std::string>& head, const std::string& source, bool more_lines,
    const std::vector<std::pair<std::string, std::string>>& extra_preamble) {
  return LayoutDetector(head, source, more_lines).run(extra_preamble);
}

StatusOr<std::string> check_probe_step(const ScopeLayout& l, const ScopeColumn& c, double step,
                                       const std::string& source) {
  if (c.probe_factor <= 0) return std::string();
  const double q = c.volts_per_div * c.probe_factor / 25;  // the 8-bit step at the probe tip
  auto multiple_of = [&](double unit) {
    return unit > 0 && step > 0 && std::abs(step / unit - std::round(step / unit)) < 0.01;
  };
  if (q > 0 && c.probe_factor != 1 && step < 0.5 * q && multiple_of(q / c.probe_factor))
    return Status::Error(fmt::format(
        "{}:{}: error: {}: Attenuation {:g}X, so its values should step by {:g} V ({:g} V/div x "
        "{:g} / 25), but they step by {:g} V, the scale without the probe: the file contradicts "
        "its data (volts at the scope's input, not at the probe tip?), so which volts it holds "
        "cannot be told; export it again from the scope",
        source, l.probe_line, c.name, c.probe_factor, q, c.volts_per_div, c.probe_factor, step));
  return fmt::format(
      "{}: probe attenuation {:g}X (line {}): the values are probe-tip volts as "
      "written{}",
      c.name, c.probe_factor, l.probe_line,
      q > 0 && multiple_of(q) ? fmt::format(" (the smallest step between values, {:g} V, is a "
                                            "multiple of {:g} V = {:g} V/div x {:g} / 25)",
                                            step, q, c.volts_per_div, c.probe_factor)
                              : "");
}

std::optional<size_t> first_channel(const ScopeLayout& l) {
  for (size_t k = 0; k < l.columns.size(); ++k)
    if (static_cast<int>(k) != l.time && !l.columns[k].time_like && !l.columns[k].meta) return k;
  return std::nullopt;
}

StatusOr<ColumnPick> pick_column(const ScopeLayout& l, const std::string& ref, const char* flag,
                                 const std::string& source) {
  auto list = [&] {
    std::string s;
    for (const ScopeColumn& c : l.columns)
      s += fmt::format(
          "{}{} '{}'{}", s.empty() ? "" : ", ", c.field + 1, c.name,
          c.channel.empty() || c.channel == upper_compact(c.name) ? "" : " (" + c.channel + ")");
    return s;
  };
  auto by_index = [&](std::string_view digits) -> std::optional<size_t> {
    if (!all_digits(digits)) return std::nullopt;
    size_t n = 0;
    std::from_chars(digits.data(), digits.data() + digits.size(), n);
    for (size_t k = 0; k < l.columns.size(); ++k)
      if (l.columns[k].field + 1 == n) return k;
    return std::nullopt;
  };
  ColumnPick p;
  if (!ref.empty() && ref[0] == '#') {
    if (auto k = by_index(std::string_view(ref).substr(1))) {
      p.column = *k;
      p.how = fmt::format("by index {}", l.columns[*k].field + 1);
      return p;
    }
  } else {
    std::optional<size_t> hit;
    for (size_t k = 0; k < l.columns.size() && !hit; ++k)
      if (l.columns[k].name == ref) {
        hit = k;
        p.how = "by name";
      }
    for (size_t k = 0; k < l.columns.size() && !hit; ++k)
      if (lower(l.columns[k].name) == lower(ref)) {
        hit = k;
        p.how = "by name";
      }
    const std::string ch = canonical_channel(ref);
    if (!ch.empty() && !hit) {
      std::vector<size_t> same;
      for (size_t k = 0; k < l.columns.size(); ++k)
        if (l.columns[k].channel == ch && !l.columns[k].time_like) same.push_back(k);
      if (same.size() > 1)
        return Status::Error(fmt::format(
            "{}: error: {} '{}': channel {} names {} columns; give the column by name or as #K "
            "(columns: {})",
            source, flag, ref, ch, same.size(), list()));
      if (same.size() == 1) {
        hit = same[0];
        p.how = "by channel " + ch;
      }
    }
    const std::optional<size_t> idx = by_index(ref);
    if (hit) {
      p.column = *hit;
      if (idx && *idx != *hit)
        p.note = fmt::format(
            "{} '{}' is both column {}'s name or channel and the index of column {} ('{}'): "
            "used column {} ('{}'); write #{} for the index",
            flag, ref, l.columns[*hit].field + 1, l.columns[*idx].field + 1, l.columns[*idx].name,
            l.columns[*hit].field + 1, l.columns[*hit].name, ref);
      return p;
    }
    if (idx) {
      p.column = *idx;
      p.how = fmt::format("by index {}", l.columns[*idx].field + 1);
      return p;
    }
  }
  return Status::Error(fmt::format(
      "{}:{}: error: {} '{}': no such column (columns: {}; or a 1-based index up to {})", source,
      l.header_line > 0 ? l.header_line : l.data_line, flag, ref, list(),
      l.columns.empty() ? 0 : l.columns.back().field + 1));
}

}  // namespace isolink::eye
