#include "eye/waveform_csv.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "base/file_io.h"
#include "eye/csv_lines.h"
#include "eye/scope_binary.h"
#include "eye/scope_formats.h"

namespace isolink::eye {
namespace {

constexpr size_t kHeadLines = 256;   // lines looked at to find the layout
constexpr double kOverrange = 1e30;  // Tektronix writes 9.9E37 for a clipped sample

// A column read with a sign: the value is the sum of sign * scale * field.
struct Term {
  std::string role;
  std::string ref;
};

struct OneFile {
  std::vector<double> t, v;
  std::string name;  // the value column's name ("CH1-CH2")
};

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

// R&S RTx exports NAME.Wfm.csv (data) beside NAME.csv ("Key:value:" lines).
// The header file beside an R&S .Wfm.csv: NAME.csv of "Key:value:" lines (RTB, RTM, RTO), or
// NAME.bin, an XML database of <Prop Name="XStart" Value="-0.0025" .../> entries (RTP, newer
// RTO firmware). Its pairs join the preamble (XStart, Resolution give the time base).
std::vector<std::pair<std::string, std::string>> rs_sibling_header(const std::string& path) {
  std::vector<std::pair<std::string, std::string>> out;
  const std::string lo = lower(path);
  const std::string tail = ".wfm.csv";
  if (lo.size() <= tail.size() || lo.compare(lo.size() - tail.size(), tail.size(), tail) != 0)
    return out;
  const std::string stem = path.substr(0, path.size() - tail.size());
  std::string_view line;
  if (StatusOr<LineReader> in = LineReader::open(stem + ".csv"); in) {
    for (int i = 0; i < 500 && in->next(&line); ++i) {
      const size_t c = line.find(':');
      if (c == std::string_view::npos || c == 0) continue;
      std::string_view v = line.substr(c + 1);
      const size_t c2 = v.find(':');
      if (c2 != std::string_view::npos) v = v.substr(0, c2);
      out.emplace_back(std::string(trim_cell(line.substr(0, c))), std::string(trim_cell(v)));
    }
    return out;
  }
  StatusOr<LineReader> xml = LineReader::open(stem + ".bin");
  if (!xml) return out;
  auto attr = [](std::string_view tag, std::string_view name) -> std::optional<std::string_view> {
    const std::string key = " " + std::string(name) + "=\"";
    const size_t a = tag.find(key);
    if (a == std::string_view::npos) return std::nullopt;
    const size_t b = tag.find('"', a + key.size());
    if (b == std::string_view::npos) return std::nullopt;
    return tag.substr(a + key.size(), b - a - key.size());
  };
  for (int i = 0; i < 2000 && xml->next(&line); ++i) {
    if (i == 0 && line.find("<?xml") == std::string_view::npos) return out;
    if (line.find("<Prop") == std::string_view::npos) continue;
    std::optional<std::string_view> name = attr(line, "Name"), value = attr(line, "Value");
    if (name && value) out.emplace_back(std::string(*name), std::string(*value));
  }
  return out;
}

Status error_at(const std::string& source, int line, const std::string& msg) {
  return Status::Error(line > 0 ? fmt::format("{}:{}: error: {}", source, line, msg)
                                : fmt::format("{}: error: {}", source, msg));
}

std::string describe_column(const ScopeLayout& l, size_t k) {
  return fmt::format("column {} ('{}')", l.columns[k].field + 1, l.columns[k].name);
}

// Resolves the P/N/diff references against the layout; refuses time columns, Start/Increment,
// non-volt units and P = N.
Status pick_terms(const ScopeLayout& l, const std::vector<Term>& terms, const std::string& source,
                  std::vector<size_t>* picked_out, std::vector<double>* sign_out,
                  std::vector<std::string>* how_out, std::vector<std::string>* notes) {
  auto err = [&](int line, const std::string& msg) { return error_at(source, line, msg); };
  auto describe = [&](size_t k) { return describe_column(l, k); };
  std::vector<size_t>& picked = *picked_out;
  std::vector<double>& sign = *sign_out;
  std::vector<std::string>& how = *how_out;
  for (size_t i = 0; i < terms.size(); ++i) {
    const Term& tm = terms[i];
    const std::string flag = tm.role == "diff" ? "differential column" : tm.role + " column";
    size_t k = 0;
    if (tm.ref.empty()) {
      std::optional<size_t> c = first_channel(l);
      if (!c)
        return err(l.header_line ? l.header_line : l.data_line,
                   fmt::format("no signal column besides time: the {} needs one", flag));
      k = *c;
      how.push_back("default (first channel)");
    } else {
      StatusOr<ColumnPick> p = pick_column(l, tm.ref, flag.c_str(), source);
      if (!p) return p.status();
      if (!p->note.empty()) notes->push_back(p->note);
      k = p->column;
      how.push_back(p->how);
    }
    const ScopeColumn& c = l.columns[k];
    const int at = l.header_line ? l.header_line : l.data_line;
    if (static_cast<int>(k) == l.time || c.time_like)
      return err(at, fmt::format("{} '{}' is {}, a time column: choose a signal column", flag,
                                 tm.ref.empty() ? "(default)" : tm.ref, describe(k)));
    if (c.meta)
      return err(at, fmt::format("{} '{}' is {}, which holds Rigol's Start/Increment, not a "
                                 "signal",
                                 flag, tm.ref, describe(k)));
    if (c.unit.kind == UnitKind::kOther)
      return err(at, fmt::format("{} '{}' is {}, in {}, not volts", flag, tm.ref, describe(k),
                                 c.unit.text));
    for (size_t j = 0; j < picked.size(); ++j)
      if (picked[j] == k)
        return err(at, fmt::format("P and N are both {}: P - N would be zero; choose two "
                                   "different columns",
                                   describe(k)));
    picked.push_back(k);
    sign.push_back(i == 0 ? 1.0 : -1.0);
  }

  return Status::Ok();
}

// Resolves --time against the layout (none given: the layout's own time column stays).
Status pick_time_column(const std::string& time_ref, const std::string& source, ScopeLayout* l,
                        std::vector<std::string>* notes) {
  if (time_ref.empty()) return Status::Ok();
  StatusOr<ColumnPick> p = pick_column(*l, time_ref, "time column", source);
  if (!p) return p.status();
  if (!p->note.empty()) notes->push_back(p->note);
  l->time = static_cast<int>(p->column);
  l->time_is_index = l->columns[p->column].unit.kind == UnitKind::kIndex && l->dt > 0;
  l->columns[p->column].time_like = true;
  l->time_from = "--time " + describe_column(*l, p->column);
  return Status::Ok();
}

// The data rows of one file, one line at a time: time (read, or from t0 and dt) and the signed,
// scaled sum of the picked columns; footers end the data, and the first bad row stops it with
// an error at its line.
class RowReader {
 public:
  RowReader(const ScopeLayout& l, const std::vector<size_t>& picked,
            const std::vector<double>& sign, const std::string& source)
      : l_(l), source_(source), steps_(picked.size()) {
    tcol_ = l.time;
    tfield_ = tcol_ >= 0 ? l.columns[static_cast<size_t>(tcol_)].field : 0;
    tscale_ = tcol_ >= 0 && !l.time_is_index ? l.columns[static_cast<size_t>(tcol_)].unit.scale : 1;
    for (size_t i = 0; i < picked.size(); ++i) {
      vfield_.push_back(l.columns[picked[i]].field);
      vscale_.push_back(sign[i] * l.columns[picked[i]].unit.scale);
    }
    need_ = tcol_ >= 0 ? tfield_ + 1 : 0;
    for (size_t f : vfield_) need_ = std::max(need_, f + 1);
    probed_ = std::any_of(picked.begin(), picked.end(),
                          [&](size_t k) { return l.columns[k].probe_factor > 0; });
  }

  // Reserves from the file's size and the first data rows' length: no doubling past the file.
  void reserve(const std::vector<std::string>& head, uint64_t file_size) {
    size_t bytes = 0, rows = 0;
    for (size_t i = static_cast<size_t>(l_.data_line - 1); i < head.size() && rows < 64; ++i)
      if (!trim_cell(head[i]).empty()) {
        bytes += head[i].size() + 1;
        ++rows;
      }
    if (rows > 0 && file_size > 0) {
      const size_t est = static_cast<size_t>(static_cast<double>(file_size) /
                                             (static_cast<double>(bytes) / rows) * 1.02) +
                         16;
      out_.t.reserve(est);
      out_.v.reserve(est);
    }
  }

  // Takes line `number`; false (and error() says why) at a bad row.
  bool take(std::string_view text, int number) {
    if (trim_cell(text).empty()) return true;
    split_fields(text, l_.delim, &f_);
    double x = 0;
    bool any = false;
    for (auto s : f_)
      if (parse_cell(s, l_.decimal_comma, &x)) {
        any = true;
        break;
      }
    if (!any) {  // a footer (",,", "End of data"): the data end here
      if (!footer_line_) {
        footer_line_ = number;
        footer_text_ = std::string(trim_cell(text).substr(0, 40));
      }
      return true;
    }
    if (footer_line_)
      return fail(number, fmt::format("data after line {} ('{}'), which is no data row: expected "
                                      "the data to end there (a footer) or to go on as numbers",
                                      footer_line_, footer_text_));
    if (f_.size() != l_.data_fields || f_.size() < need_) {
      const bool like_header = l_.header_line > 0 && l_.columns.size() == l_.data_fields;
      return fail(number,
                  fmt::format("expected {} fields like {} (line {}), found {}", l_.data_fields,
                              like_header ? "the header" : "the first data row",
                              like_header ? l_.header_line : l_.data_line, f_.size()));
    }
    double t = 0;
    if (tcol_ >= 0) {
      if (!get(tfield_, number, &t)) return false;
      t = l_.time_is_index ? l_.t0 + t * l_.dt : t * tscale_;
    } else {
      t = l_.t0 + static_cast<double>(row_) * l_.dt;
    }
    double v = 0;
    for (size_t i = 0; i < vfield_.size(); ++i) {
      if (!get(vfield_[i], number, &x)) return false;
      v += vscale_[i] * x;
      if (probed_) {  // the smallest step between values, for check_probe_step
        ValueStep& s = steps_[i];
        const double d = std::abs(x - s.prev);
        if (row_ > 0 && d > 0 && (s.min == 0 || d < s.min)) s.min = d;
        s.prev = x;
      }
    }
    if (!out_.t.empty() && !(t > out_.t.back()))
      return fail(number, fmt::format("time {:g} is not after {:g} on line {}: time must increase "
                                      "from row to row",
                                      t, out_.t.back(), prev_row_line_));
    out_.t.push_back(t);
    out_.v.push_back(v);
    prev_row_line_ = number;
    ++row_;
    return true;
  }

  const Status& error() const { return bad_; }
  bool probed() const { return probed_; }
  double tscale() const { return tscale_; }
  // The smallest step between two values of picked column i (probed() only; 0: none seen).
  double min_step(size_t i) const { return steps_[i].min; }
  OneFile& out() { return out_; }

 private:
  struct ValueStep {
    double prev = 0, min = 0;
  };

  bool fail(int number, const std::string& msg) {
    bad_ = error_at(source_, number, msg);
    return false;
  }
  // Field `field` of the row as a number; an overrange marker or a word is an error.
  bool get(size_t field, int number, double* y) {
    if (parse_cell(f_[field], l_.decimal_comma, y)) {
      if (std::abs(*y) < kOverrange) return true;
      return fail(number, fmt::format("field {}: {} is the scope's overrange marker: the "
                                      "channel clipped; capture again with more volts/div",
                                      field + 1, std::string(trim_cell(f_[field]))));
    }
    std::string name = fmt::format("column {}", field + 1);
    for (const ScopeColumn& c : l_.columns)
      if (c.field == field) name = c.name;
    return fail(number, fmt::format("column {} ('{}'): expected a number, found '{}'", field + 1,
                                    name, std::string(trim_cell(f_[field]))));
  }

  const ScopeLayout& l_;
  const std::string& source_;
  int tcol_ = -1;
  size_t tfield_ = 0, need_ = 0;
  double tscale_ = 1;
  std::vector<size_t> vfield_;
  std::vector<double> vscale_;
  bool probed_ = false;
  std::vector<ValueStep> steps_;
  std::vector<std::string_view> f_;
  int prev_row_line_ = 0, footer_line_ = 0;
  std::string footer_text_;
  size_t row_ = 0;
  Status bad_ = Status::Ok();
  OneFile out_;
};

// What was read: the file, its layout, and each column taken, with its unit and how it was
// chosen; notes for columns without a unit.
void record_capture(const ScopeLayout& l, const std::string& source, const std::string& time_ref,
                    const std::vector<Term>& terms, const std::vector<size_t>& picked,
                    const std::vector<std::string>& how, double tscale,
                    const std::vector<std::string>& notes, CaptureInfo* info) {
  info->files.push_back(source);
  info->layouts.push_back(l.name);
  if (info->time_from.empty()) info->time_from = l.time_from;
  if (l.time >= 0 && info->columns.empty()) {
    const ScopeColumn& c = l.columns[static_cast<size_t>(l.time)];
    const bool assumed = c.unit.kind == UnitKind::kNone;
    info->columns.push_back({"time", source, c.name, c.channel, c.field + 1,
                             time_ref.empty() ? "default" : "by --time", assumed ? "" : c.unit.text,
                             l.time_is_index ? l.dt : tscale});
    if (assumed && !l.time_is_index)
      info->notes.push_back(
          fmt::format("{}: no unit for the time column: read as seconds", source));
  }
  for (size_t i = 0; i < picked.size(); ++i) {
    const ScopeColumn& c = l.columns[picked[i]];
    info->columns.push_back(
        {terms[i].role, source, c.name, c.channel, c.field + 1, how[i], c.unit.text, c.unit.scale});
    if (c.unit.kind == UnitKind::kNone)
      info->notes.push_back(
          fmt::format("{}: no unit for {} ('{}'): read as volts", source, terms[i].role, c.name));
  }
  info->notes.insert(info->notes.end(), notes.begin(), notes.end());
}

StatusOr<OneFile> read_one(LineReader& in, const std::string& source, const std::string& time_ref,
                           const std::vector<Term>& terms,
                           const std::vector<std::pair<std::string, std::string>>& extra,
                           CaptureInfo* info) {
  std::vector<std::string> head;
  std::string_view line;
  bool more = false;
  while (in.next(&line)) {
    head.emplace_back(line);
    if (head.size() >= kHeadLines) {
      more = true;
      break;
    }
  }
  if (!in.error().empty()) return error_at(source, 0, in.error());
  StatusOr<ScopeLayout> lay = detect_layout(head, source, more, extra);
  if (!lay) return lay.status();
  ScopeLayout& l = *lay;
  std::vector<std::string> notes;
  if (Status st = pick_time_column(time_ref, source, &l, &notes); !st.ok()) return st;
  std::vector<size_t> picked;
  std::vector<double> sign;
  std::vector<std::string> how;
  if (Status st = pick_terms(l, terms, source, &picked, &sign, &how, &notes); !st.ok()) return st;

  RowReader rows(l, picked, sign, source);
  rows.reserve(head, in.size());
  for (size_t i = static_cast<size_t>(l.data_line - 1); i < head.size(); ++i)
    if (!rows.take(head[i], static_cast<int>(i) + 1)) return rows.error();
  if (more)
    while (in.next(&line))
      if (!rows.take(line, in.number())) return rows.error();
  if (!in.error().empty()) return error_at(source, 0, in.error());
  OneFile& out = rows.out();
  if (out.t.size() < 2)
    return error_at(source, l.data_line,
                    fmt::format("fewer than two samples in the data from line {}", l.data_line));
  for (size_t i = 0; i < picked.size() && rows.probed(); ++i) {
    StatusOr<std::string> note =
        check_probe_step(l, l.columns[picked[i]], rows.min_step(i), source);
    if (!note) return note.status();
    if (!note->empty()) notes.push_back(*note);
  }
  if (info) record_capture(l, source, time_ref, terms, picked, how, rows.tscale(), notes, info);
  out.name = l.columns[picked[0]].name;
  if (picked.size() == 2) out.name += "-" + l.columns[picked[1]].name;
  return std::move(out);
}

void finish_info(const Waveform& w, CaptureInfo* info) {
  if (!info) return;
  info->samples = w.time.size();
  info->t_begin = w.time.front();
  info->t_end = w.time.back();
  // median interval from a bounded sample of steps
  std::vector<double> steps;
  const size_t n = w.time.size() - 1;
  const size_t stride = std::max<size_t>(1, n / 4096);
  for (size_t i = 0; i < n; i += stride) steps.push_back(w.time[i + 1] - w.time[i]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                   steps.end());
  info->interval = steps[steps.size() / 2];
  info->uniform = true;
  for (size_t i = 0; i < n && info->uniform; ++i)
    info->uniform = std::abs(w.time[i + 1] - w.time[i] - info->interval) <= 0.01 * info->interval;
}

StatusOr<std::vector<Term>> terms_for(const CsvColumns& cols, const std::string& source) {
  auto err = [&](const std::string& msg) {
    return Status::Error(fmt::format("{}: error: {}", source, msg));
  };
  if (!cols.diff.empty() && (!cols.p.empty() || !cols.n.empty()))
    return err("give either a differential column or a P and an N column, not both");
  if (cols.p.empty() != cols.n.empty())
    return err("a P column needs an N column (and the reverse): the differential is P - N");
  if (!cols.p.empty()) return std::vector<Term>{{"P", cols.p}, {"N", cols.n}};
  return std::vector<Term>{{"diff", cols.diff}};
}

// A binary capture: its traces stand for columns, so the same choices and refusals apply.
StatusOr<OneFile> read_binary_one(const std::string& path, const std::string& kind,
                                  const std::vector<Term>& terms, CaptureInfo* info) {
  StatusOr<std::vector<BinaryTrace>> traces = read_binary(path);
  if (!traces) return traces.status();
  ScopeLayout l;
  l.name = kind;
  for (size_t k = 0; k < traces->size(); ++k) {
    ScopeColumn c;
    c.name = (*traces)[k].name;
    c.channel = canonical_channel(c.name);
    c.field = k;
    if (auto u = parse_unit((*traces)[k].y_unit)) c.unit = *u;
    l.columns.push_back(c);
  }
  std::vector<size_t> picked;
  std::vector<double> sign;
  std::vector<std::string> how, notes;
  if (Status st = pick_terms(l, terms, path, &picked, &sign, &how, &notes); !st.ok()) return st;
  BinaryTrace& first = (*traces)[picked[0]];
  for (size_t i = 1; i < picked.size(); ++i)
    if ((*traces)[picked[i]].t != first.t)
      return Status::Error(
          fmt::format("{}: error: waveforms '{}' and '{}' have different time "
                      "bases: P and N must come from one acquisition",
                      path, first.name, (*traces)[picked[i]].name));
  // The first trace's samples are moved, not copied: memory stays the samples read.
  OneFile out;
  const std::string time_from = first.time_from;
  out.t = std::move(first.t);
  out.v = std::move(first.v);
  if (sign[0] != 1.0)
    for (double& x : out.v) x *= sign[0];
  for (size_t i = 1; i < picked.size(); ++i) {
    const BinaryTrace& tr = (*traces)[picked[i]];
    for (size_t j = 0; j < tr.v.size(); ++j) out.v[j] += sign[i] * tr.v[j];
  }
  for (size_t j = 1; j < out.t.size(); ++j)
    if (!(out.t[j] > out.t[j - 1]))
      return Status::Error(fmt::format("{}: error: time does not increase at point {}", path, j));
  if (info) {
    info->files.push_back(path);
    info->layouts.push_back(kind);
    if (info->time_from.empty()) info->time_from = time_from;
    for (size_t i = 0; i < picked.size(); ++i) {
      const ScopeColumn& c = l.columns[picked[i]];
      info->columns.push_back(
          {terms[i].role, path, c.name, c.channel, c.field + 1, how[i], c.unit.text, c.unit.scale});
    }
    info->notes.insert(info->notes.end(), notes.begin(), notes.end());
  }
  out.name = l.columns[picked[0]].name;
  if (picked.size() == 2) out.name += "-" + l.columns[picked[1]].name;
  return out;
}

StatusOr<OneFile> read_path(const std::string& path, const std::string& time_ref,
                            const std::vector<Term>& terms, CaptureInfo* info) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) &&
      !std::filesystem::is_directory(st)) {
    // A device, a FIFO or a pipe: read whole under read_input_file's size and time limits
    // (/dev/zero, a pipe that never ends), then parsed as text.
    StatusOr<std::string> text = read_input_file(path);
    if (!text) return text.status();
    if (std::optional<std::string> kind = binary_kind_of(path, *text))
      return Status::Error(fmt::format(
          "{}: error: a {} capture from a device or pipe: binary captures are read from a regular "
          "file (their headers are checked against its length); save it to a file first",
          path, *kind));
    LineReader in(*text);
    return read_one(in, path, time_ref, terms, {}, info);
  }
  if (std::optional<std::string> kind = binary_kind(path)) {
    if (!time_ref.empty())
      return Status::Error(
          fmt::format("{}: error: --time '{}': a {} capture carries its own "
                      "time base",
                      path, time_ref, *kind));
    return read_binary_one(path, *kind, terms, info);
  }
  StatusOr<LineReader> in = LineReader::open(path);
  if (!in) return in.status();
  return read_one(*in, path, time_ref, terms, rs_sibling_header(path), info);
}

Waveform to_waveform(OneFile&& one, CaptureInfo* info) {
  Waveform w;
  w.time = std::move(one.t);
  w.add_column(one.name, std::move(one.v));
  finish_info(w, info);
  return w;
}

}  // namespace

StatusOr<Waveform> parse_differential_csv(std::string_view text, const std::string& source,
                                          const CsvColumns& cols, CaptureInfo* info) {
  StatusOr<std::vector<Term>> terms = terms_for(cols, source);
  if (!terms) return terms.status();
  LineReader in(text);
  StatusOr<OneFile> one = read_one(in, source, cols.time, *terms, {}, info);
  if (!one) return one.status();
  return to_waveform(std::move(*one), info);
}

StatusOr<Waveform> read_differential_csv(const std::string& path, const CsvColumns& cols,
                                         CaptureInfo* info) {
  StatusOr<std::vector<Term>> terms = terms_for(cols, path);
  if (!terms) return terms.status();
  StatusOr<OneFile> one = read_path(path, cols.time, *terms, info);
  if (!one) return one.status();
  return to_waveform(std::move(*one), info);
}

StatusOr<Waveform> read_capture(const std::vector<std::string>& paths, const CsvColumns& cols,
                                CaptureInfo* info) {
  if (paths.size() == 1) return read_differential_csv(paths[0], cols, info);
  if (paths.size() != 2)
    return Status::Error(
        fmt::format("give one capture file or two (P and N), not {}", paths.size()));
  if (!cols.diff.empty())
    return Status::Error(fmt::format(
        "{}: error: --diff '{}' with two files: the first file gives P (--p) and the second N "
        "(--n)",
        paths[1], cols.diff));
  OneFile leg[2];
  for (int i = 0; i < 2; ++i) {
    StatusOr<OneFile> one =
        read_path(paths[i], cols.time, {{i == 0 ? "P" : "N", i == 0 ? cols.p : cols.n}}, info);
    if (!one) return one.status();
    leg[i] = std::move(*one);
  }
  std::error_code ec;
  if (std::filesystem::equivalent(paths[0], paths[1], ec) && cols.p == cols.n)
    return Status::Error(
        fmt::format("{}: error: P and N are the same column of the same file: P "
                    "- N would be zero",
                    paths[1]));
  // Align: the same time base, or N interpolated onto P's samples inside the common span.
  const std::vector<double>& tp = leg[0].t;
  const std::vector<double>& tn = leg[1].t;
  const double dt = (tp.back() - tp.front()) / static_cast<double>(tp.size() - 1);
  bool same = tp.size() == tn.size();
  for (size_t i = 0; same && i < tp.size(); ++i) same = std::abs(tp[i] - tn[i]) <= 1e-3 * dt;
  Waveform w;
  std::vector<double> v;
  std::string alignment;
  if (same) {
    w.time = std::move(leg[0].t);
    v = std::move(leg[0].v);
    for (size_t i = 0; i < v.size(); ++i) v[i] -= leg[1].v[i];
    alignment = "the two files share one time base";
  } else {
    const double a = std::max(tp.front(), tn.front()), b = std::min(tp.back(), tn.back());
    if (!(b > a))
      return Status::Error(fmt::format(
          "{}: error: its time span {:g} .. {:g} s does not overlap {}'s {:g} .. {:g} s: the "
          "captures must come from one acquisition",
          paths[1], tn.front(), tn.back(), paths[0], tp.front(), tp.back()));
    size_t j = 0;
    for (size_t i = 0; i < tp.size(); ++i) {
      if (tp[i] < a || tp[i] > b) continue;
      while (j + 1 < tn.size() && tn[j + 1] < tp[i]) ++j;
      double nv = leg[1].v[j];
      if (j + 1 < tn.size() && tn[j] <= tp[i]) {
        const double u = (tp[i] - tn[j]) / (tn[j + 1] - tn[j]);
        nv = leg[1].v[j] + std::clamp(u, 0.0, 1.0) * (leg[1].v[j + 1] - leg[1].v[j]);
      }
      w.time.push_back(tp[i]);
      v.push_back(leg[0].v[i] - nv);
    }
    if (w.time.size() < 2)
      return Status::Error(
          fmt::format("{}: error: fewer than two samples of {} fall inside {}'s "
                      "time span",
                      paths[1], paths[0], paths[1]));
    alignment = fmt::format(
        "time bases differ: N interpolated onto P's samples over the common "
        "span {:g} .. {:g} s ({} of {} P samples kept)",
        a, b, w.time.size(), tp.size());
  }
  w.add_column(leg[0].name + "-" + leg[1].name, std::move(v));
  if (info) info->alignment = alignment;
  finish_info(w, info);
  return w;
}

nlohmann::ordered_json capture_json(const CaptureInfo& info) {
  nlohmann::ordered_json j;
  j["files"] = info.files;
  j["layouts"] = info.layouts;
  nlohmann::ordered_json cols = nlohmann::ordered_json::array();
  for (const CaptureColumn& c : info.columns)
    cols.push_back({{"role", c.role},
                    {"file", c.file},
                    {"index", c.index},
                    {"name", c.name},
                    {"channel", c.channel.empty() ? nlohmann::ordered_json(nullptr)
                                                  : nlohmann::ordered_json(c.channel)},
                    {"selected", c.how},
                    {"unit", c.unit.empty() ? nlohmann::ordered_json(nullptr)
                                            : nlohmann::ordered_json(c.unit)},
                    {"scale", c.scale}});
  j["columns"] = std::move(cols);
  j["time_from"] = info.time_from;
  j["samples"] = info.samples;
  j["t_begin_s"] = info.t_begin;
  j["t_end_s"] = info.t_end;
  j["span_s"] = info.t_end - info.t_begin;
  j["interval_s"] = info.interval;
  j["uniform"] = info.uniform;
  j["alignment"] = info.alignment.empty() ? nlohmann::ordered_json(nullptr)
                                          : nlohmann::ordered_json(info.alignment);
  j["notes"] = info.notes;
  return j;
}

std::string capture_text(const CaptureInfo& info) {
  std::string out = "read:";
  for (size_t i = 0; i < info.files.size(); ++i)
    out += fmt::format(" {} ({})", info.files[i], info.layouts[i]);
  out += "\n";
  for (const CaptureColumn& c : info.columns) {
    std::string scale;
    if (c.role == "time" && c.scale != 1)
      scale = fmt::format(", x{:g} to s", c.scale);
    else if (c.role != "time" && c.scale != 1)
      scale = fmt::format(", x{:g} to V", c.scale);
    out += fmt::format("  {:<5} column {} '{}'{} ({}{}{})\n", c.role, c.index, c.name,
                       info.files.size() > 1 ? " of " + c.file : "", c.how,
                       c.unit.empty() ? "" : ", unit " + c.unit, scale);
  }
  out += fmt::format("  {} samples, {:g} .. {:g} s (span {:g} s), interval {:g} s{}\n",
                     info.samples, info.t_begin, info.t_end, info.t_end - info.t_begin,
                     info.interval, info.uniform ? "" : " (median; not uniform)");
  out += "  time: " + info.time_from + "\n";
  if (!info.alignment.empty()) out += "  alignment: " + info.alignment + "\n";
  for (const std::string& n : info.notes) out += "  note: " + n + "\n";
  return out;
}

}  // namespace isolink::eye
