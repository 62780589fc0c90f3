#include "analysis/link_run_wave.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isolink::analysis {

const char* wave_rows_name(WaveRows r) {
  switch (r) {
    case WaveRows::Thinned:
      return "thinned";
    case WaveRows::Rows:
      return "rows";
    case WaveRows::Grid:
      return "grid";
  }
  return "thinned";
}

StatusOr<WaveRows> parse_wave_rows(const std::string& text) {
  for (WaveRows r : {WaveRows::Thinned, WaveRows::Rows, WaveRows::Grid})
    if (text == wave_rows_name(r)) return r;
  return Status::Error("wave rows '" + text + "' is none of thinned, rows, grid");
}

std::vector<size_t> thin_rows(std::span<const double> time,
                              const std::vector<std::span<const double>>& columns,
                              double tolerance) {
  const std::vector<double> tolerances(columns.size(), tolerance);
  return thin_rows(time, columns, tolerances);
}

namespace {

// thin_rows's pass: keep(i) for each row kept, in order.
template <typename Keep>
void thin_pass(std::span<const double> time, const std::vector<std::span<const double>>& columns,
               std::span<const double> tolerances, Keep&& keep) {
  const size_t n = time.size();
  if (n == 0) return;
  const size_t nc = columns.size();
  auto finite_row = [&](size_t i) {
    for (const auto& c : columns)
      if (!std::isfinite(c[i])) return false;
    return std::isfinite(time[i]);
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> lo(nc), hi(nc);
  size_t a = 0;  // the last row kept
  keep(0);
  bool anchor_finite = finite_row(0);
  std::fill(lo.begin(), lo.end(), -kInf);
  std::fill(hi.begin(), hi.end(), kInf);
  for (size_t j = 1; j < n; ++j) {
    const double dt = time[j] - time[a];
    bool reach = anchor_finite && finite_row(j) && dt > 0;
    // The slope to j within [lo, hi], as d within [lo dt, hi dt] (dt > 0): no division per row.
    for (size_t c = 0; c < nc && reach; ++c) {
      const double d = columns[c][j] - columns[c][a];
      reach = d >= lo[c] * dt && d <= hi[c] * dt;
    }
    if (!reach && j - 1 > a) {
      // Row j cannot be reached from a in one straight line: j - 1 (which could) is kept and
      // becomes the anchor, and j is tried again from there.
      a = j - 1;
      keep(a);
      std::fill(lo.begin(), lo.end(), -kInf);
      std::fill(hi.begin(), hi.end(), kInf);
      anchor_finite = finite_row(a);
      --j;
      continue;
    }
    if (!reach) {  // j = a + 1 with a non-finite value on either side: both rows kept
      a = j;
      keep(a);
      anchor_finite = finite_row(a);
      continue;
    }
    const double inv_dt = 1.0 / (time[j] - time[a]);
    for (size_t c = 0; c < nc; ++c) {
      const double d = columns[c][j] - columns[c][a];
      lo[c] = std::max(lo[c], (d - tolerances[c]) * inv_dt);
      hi[c] = std::min(hi[c], (d + tolerances[c]) * inv_dt);
    }
  }
  if (a != n - 1) keep(n - 1);
}

}  // namespace

std::vector<size_t> thin_rows(std::span<const double> time,
                              const std::vector<std::span<const double>>& columns,
                              std::span<const double> tolerances) {
  std::vector<size_t> kept;
  thin_pass(time, columns, tolerances, [&](size_t i) { kept.push_back(i); });
  return kept;
}

size_t thin_rows_count(std::span<const double> time,
                       const std::vector<std::span<const double>>& columns, double tolerance) {
  const std::vector<double> tolerances(columns.size(), tolerance);
  size_t count = 0;
  thin_pass(time, columns, tolerances, [&](size_t) { ++count; });
  return count;
}

size_t finest_fitting(std::span<const double> ladder, const std::function<bool(double)>& fits) {
  size_t lo = 0, hi = ladder.size();  // every rung below lo fails; hi fits (or is past the end)
  while (lo < hi) {
    const size_t mid = lo + (hi - lo) / 2;
    if (fits(ladder[mid]))
      hi = mid;
    else
      lo = mid + 1;
  }
  return hi;
}

namespace {

// Column c of direction d at the merged times, linearly between its kept rows.
std::vector<double> on_axis(const std::vector<double>& t, const std::vector<double>& v,
                            const std::vector<size_t>& kept, const std::vector<double>& axis) {
  std::vector<double> out(axis.size());
  size_t k = 0;  // kept[k] <= the present time's row
  for (size_t i = 0; i < axis.size(); ++i) {
    const double x = axis[i];
    while (k + 1 < kept.size() && t[kept[k + 1]] <= x) ++k;
    const size_t a = kept[k];
    if (k + 1 >= kept.size() || t[a] == x || x < t[a]) {
      out[i] = v[a];
      continue;
    }
    const size_t b = kept[k + 1];
    out[i] = v[a] + (x - t[a]) / (t[b] - t[a]) * (v[b] - v[a]);
  }
  return out;
}

}  // namespace

double wave_file_bytes(size_t rows, size_t columns) {
  return static_cast<double>(rows) * (14.0 + 11.0 * static_cast<double>(columns));
}

namespace {

// The union of each direction's kept times (up to t_end), and every column on it.
Waveform merged(const LinkRun& run, const std::vector<std::vector<size_t>>& kept, double t_end) {
  Waveform out;
  for (size_t k = 0; k < kept.size(); ++k) {
    const std::vector<double>& t = run.directions[k].sim.wave.time;
    std::vector<double> mine;
    mine.reserve(kept[k].size());
    for (size_t i : kept[k])
      if (t[i] <= t_end) mine.push_back(t[i]);
    std::vector<double> both;
    both.reserve(out.time.size() + mine.size());
    std::set_union(out.time.begin(), out.time.end(), mine.begin(), mine.end(),
                   std::back_inserter(both));
    out.time = std::move(both);
  }
  for (size_t k = 0; k < kept.size(); ++k) {
    const DirectionRun& d = run.directions[k];
    const char* dir = link::direction_name(d.link.direction);
    for (size_t c = 0; c < d.sim.wave.columns.size(); ++c)
      out.add_column(fmt::format("{} {}", dir, d.sim.wave.names[c]),
                     on_axis(d.sim.wave.time, d.sim.wave.columns[c], kept[k], out.time));
  }
  return out;
}

// Per direction, the rows thinned with tol; *rows the most the merged axis can have (their sum).
std::vector<std::vector<size_t>> thin_each(const LinkRun& run, double tol, size_t* rows) {
  std::vector<std::vector<size_t>> kept;
  *rows = 0;
  for (const DirectionRun& d : run.directions) {
    const Waveform& w = d.sim.wave;
    std::vector<std::span<const double>> cols(w.columns.begin(), w.columns.end());
    kept.push_back(thin_rows(w.time, cols, tol));
    *rows += kept.back().size();
  }
  return kept;
}

}  // namespace

WaveFile run_wave_file(const LinkRun& run, const WaveFileOptions& opt) {
  WaveFile f;
  f.rows = opt.rows;
  double t_end = std::numeric_limits<double>::infinity();
  size_t columns = 0;
  double record_tol = 0;  // the runs' own thinning (SimulationResult::record_tol)
  for (const DirectionRun& d : run.directions) {
    const Waveform& w = d.sim.wave;
    t_end = std::min(t_end, w.time.empty() ? 0.0 : w.time.back());
    // A thinned record holds fewer rows than the engine made: count the engine's.
    f.engine_rows += d.sim.record_tol > 0 ? static_cast<size_t>(d.sim.grid.rows) : w.time.size();
    record_tol = std::max(record_tol, d.sim.record_tol);
    columns += w.columns.size();
  }
  f.record_tol = record_tol;
  if (run.directions.empty()) return f;
  if (opt.rows == WaveRows::Grid) {
    f.wave = run_waveforms(run, opt.grid_step);
    return f;
  }
  std::vector<std::vector<size_t>> kept;
  if (opt.rows == WaveRows::Rows) {
    for (const DirectionRun& d : run.directions) {
      std::vector<size_t> all(d.sim.wave.time.size());
      for (size_t i = 0; i < all.size(); ++i) all[i] = i;
      kept.push_back(std::move(all));
    }
  } else {
    std::vector<double> ladder(std::begin(kWaveTolerances), std::end(kWaveTolerances));
    if (opt.tolerance > 0) ladder = {opt.tolerance};
    // Each tolerance's rows counted without keeping their indices (a long record's would take
    // hundreds of MB beside it), then the chosen one's kept.
    const size_t k = finest_fitting(ladder, [&](double tol) {
      size_t rows = 0;
      for (const DirectionRun& d : run.directions) {
        const Waveform& w = d.sim.wave;
        std::vector<std::span<const double>> cols(w.columns.begin(), w.columns.end());
        rows += thin_rows_count(w.time, cols, tol);
      }
      return wave_file_bytes(rows, columns) <= kWaveFileBytes;
    });
    f.over_budget = k == ladder.size();
    const double chosen = f.over_budget ? ladder.back() : ladder[k];
    // Within chosen of the record's rows, which are within record_tol of the engine's: the kept
    // line and the record's differ by at most chosen at the record's rows and are straight
    // between them.
    f.tolerance = chosen + record_tol;
    size_t rows = 0;
    kept = thin_each(run, chosen, &rows);
  }
  f.wave = merged(run, kept, t_end);
  return f;
}

std::string wave_file_note(const WaveFile& f) {
  switch (f.rows) {
    case WaveRows::Rows:
      if (f.record_tol > 0)
        return fmt::format(
            "wave.csv: every row of the run's record ({} of the engine's {} rows, within {:g} mV "
            "of every engine row)",
            f.wave.time.size(), f.engine_rows, f.record_tol * 1e3);
      return fmt::format("wave.csv: every engine row ({} rows)", f.wave.time.size());
    case WaveRows::Grid:
      return fmt::format("wave.csv: every probe resampled linearly onto a uniform grid ({} rows)",
                         f.wave.time.size());
    case WaveRows::Thinned:
      break;
  }
  return fmt::format(
      "wave.csv: {} of the engine's {} rows, those that linear interpolation needs to stay within "
      "{:g} mV of every engine row on every probe{} (`isolink run --wave rows` writes them all)",
      f.wave.time.size(), f.engine_rows, f.tolerance * 1e3,
      f.over_budget ? fmt::format(", still over the {:g} MB the file is meant to stay under",
                                  kWaveFileBytes / 1e6)
                    : "");
}

}  // namespace isolink::analysis
