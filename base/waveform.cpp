#include "base/waveform.h"

#include <algorithm>
#include <charconv>
#include <cstdio>

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

Status write_waveform_csv(const Waveform& w, const std::string& path) {
  StatusOr<OutputFile> f = OutputFile::open(path);
  if (!f) return f.status();
  std::vector<std::string> header{"time"};
  header.insert(header.end(), w.names.begin(), w.names.end());
  std::string line = csv_row(header);
  if (Status s = f->write(line); !s.ok()) return s;
  // std::to_chars with a precision writes exactly what printf's %.12g / %.9g would (C locale),
  // several times faster; rows are written in blocks.
  char cell[64];
  auto put = [&](double v, int precision) {
    const auto r =
        std::to_chars(cell, cell + sizeof cell, v, std::chars_format::general, precision);
    line.append(cell, r.ptr);
  };
  line.clear();
  for (size_t i = 0; i < w.time.size(); ++i) {
    put(w.time[i], 12);
    for (const auto& c : w.columns) {
      line += ',';
      put(c[i], 9);
    }
    line += '\n';
    if (line.size() >= (1 << 16) || i + 1 == w.time.size()) {
      if (Status s = f->write(line); !s.ok()) return s;
      line.clear();
    }
  }
  return f->commit();
}

}  // namespace isolink
