#include "base/waveform.h"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <string>
#include <vector>

#include "base/csv.h"
#include "base/file_io.h"

namespace isolink {

void Waveform::add_column(std::string name, std::vector<double> values) {
  names.push_back(std::move(name));
  columns.push_back(std::move(values));
}

const std::vector<double>* Waveform::column(std::string_view name) const {
  for (size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return &columns[k];
  return nullptr;
}

double Waveform::value_at(size_t k, double t) const {
  const auto& v = columns[k];
  if (time.empty()) return 0.0;
  if (t <= time.front()) return v.front();
  if (t >= time.back()) return v.back();
  size_t i = std::upper_bound(time.begin(), time.end(), t) - time.begin();
  double t0 = time[i - 1], t1 = time[i];
  double f = (t - t0) / (t1 - t0);
  return v[i - 1] + f * (v[i] - v[i - 1]);
}

Waveform Waveform::resampled(double dt) const {
  Waveform out;
  out.names = names;
  out.columns.resize(columns.size());
  if (time.empty() || dt <= 0) return out;
  const double t0 = time.front(), t1 = time.back();
  size_t n = static_cast<size_t>((t1 - t0) / dt * (1 + 1e-12)) + 1;
  out.time.reserve(n);
  for (size_t i = 0; i < n; ++i) out.time.push_back(t0 + dt * static_cast<double>(i));
  for (size_t k = 0; k < columns.size(); ++k) {
    out.columns[k].reserve(n);
    size_t j = 1;
    for (double t : out.time) {
      while (j + 1 < time.size() && time[j] < t) ++j;
      if (time.size() < 2) {
        out.columns[k].push_back(columns[k][0]);
        continue;
      }
      double ta = time[j - 1], tb = time[j];
      double f = std::clamp((t - ta) / (tb - ta), 0.0, 1.0);
      out.columns[k].push_back(columns[k][j - 1] + f * (columns[k][j] - columns[k][j - 1]));
    }
  }
  return out;
}

namespace {

// Rows [begin, end) as CSV text: std::to_chars with a precision writes exactly what printf's
// %.12g / %.9g would (C locale), several times faster.
std::string csv_rows(const Waveform& w, size_t begin, size_t end) {
  std::string text;
  text.reserve((end - begin) * (20 + 17 * w.columns.size()));
  char cell[64];
  auto put = [&](double v, int precision) {
    const auto r =
        std::to_chars(cell, cell + sizeof cell, v, std::chars_format::general, precision);
    text.append(cell, r.ptr);
  };
  for (size_t i = begin; i < end; ++i) {
    put(w.time[i], 12);
    for (const auto& c : w.columns) {
      text += ',';
      put(c[i], 9);
    }
    text += '\n';
  }
  return text;
}

}  // namespace

// The rows are formatted in blocks on every core and written in order (oneTBB's pipeline, at most
// a few blocks in memory at once): formatting was 7 % of a nonlinear link's run (323,000 rows,
// 43 ms on one core).
Status write_waveform_csv(const Waveform& w, const std::string& path) {
  StatusOr<OutputFile> f = OutputFile::open(path);
  if (!f) return f.status();
  std::vector<std::string> header{"time"};
  header.insert(header.end(), w.names.begin(), w.names.end());
  if (Status s = f->write(csv_row(header)); !s.ok()) return s;
  constexpr size_t kBlockRows = 8192;
  const size_t rows = w.time.size();
  size_t next = 0;
  auto next_block = [&](tbb::flow_control& fc) -> size_t {  // its first row
    if (next >= rows) fc.stop();
    const size_t begin = next;
    next = std::min(rows, next + kBlockRows);
    return begin;
  };
  auto format_block = [&](size_t begin) {
    return csv_rows(w, begin, std::min(rows, begin + kBlockRows));
  };
  Status written = Status::Ok();
  auto write_block = [&](const std::string& text) {
    if (written.ok()) written = f->write(text);
  };
  const size_t tokens =
      2 * static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  tbb::parallel_pipeline(
      tokens,
      tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order, next_block) &
          tbb::make_filter<size_t, std::string>(tbb::filter_mode::parallel, format_block) &
          tbb::make_filter<std::string, void>(tbb::filter_mode::serial_in_order, write_block));
  if (!written.ok()) return written;
  return f->commit();
}

}  // namespace isolink
