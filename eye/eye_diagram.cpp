#include "eye/eye_diagram.h"

#include <algorithm>
#include <cmath>

namespace isolink::eye {

EyeGrid EyeGrid::for_rules(const Rules& r, int nx, int ny, double v_lo, double v_hi) {
  EyeGrid g;
  g.period = r.pulse_time;
  g.t_lo = -0.25 * r.pulse_time;
  g.t_hi = 2.25 * r.pulse_time;
  g.v_lo = v_lo;
  g.v_hi = v_hi;
  g.nx = nx;
  g.ny = ny;
  return g;
}

EyeHistogram::EyeHistogram(const EyeGrid& grid) : grid_(grid) {
  grid_.nx = std::max(grid_.nx, 1);
  grid_.ny = std::max(grid_.ny, 1);
  counts_.assign(static_cast<size_t>(grid_.nx) * static_cast<size_t>(grid_.ny), 0);
}

double EyeHistogram::x_of(double t_rel) const {
  return (t_rel - grid_.t_lo) / (grid_.t_hi - grid_.t_lo) * grid_.nx;
}

double EyeHistogram::y_of(double v) const {
  return (v - grid_.v_lo) / (grid_.v_hi - grid_.v_lo) * grid_.ny;
}

int EyeHistogram::column_of(double t_rel) const {
  return static_cast<int>(std::floor(x_of(t_rel)));
}

int EyeHistogram::row_of(double v) const {
  return static_cast<int>(std::floor(y_of(v)));
}

uint32_t EyeHistogram::max_count() const {
  return counts_.empty() ? 0 : *std::max_element(counts_.begin(), counts_.end());
}

void EyeHistogram::hit(double x, double y) {
  double fx = std::floor(x), fy = std::floor(y);
  // Consecutive hits are one Chebyshev step apart, so their cells differ by at most one in x and
  // y; clamping to that removes floating-point jitter at cell edges, which could skip a row.
  if (have_prev_) {
    fx = std::clamp(fx, prev_x_ - 1, prev_x_ + 1);
    fy = std::clamp(fy, prev_y_ - 1, prev_y_ + 1);
  }
  have_prev_ = true;
  prev_x_ = fx;
  prev_y_ = fy;
  if (fx < 0 || fy < 0 || fx >= grid_.nx || fy >= grid_.ny) {
    ++outside_;
    return;
  }
  ++counts_[static_cast<size_t>(fy) * static_cast<size_t>(grid_.nx) + static_cast<size_t>(fx)];
  ++total_;
}

void EyeHistogram::add_segment(double t0, double v0, double t1, double v1, bool continues) {
  if (!continues) {  // a new trace: its first step's midpoint is half a pixel in
    phase_ = 0.5;
    have_prev_ = false;
  }
  const double x0 = x_of(t0), y0 = y_of(v0);
  const double dx = x_of(t1) - x0, dy = y_of(v1) - y0;
  const double len = std::max(std::abs(dx), std::abs(dy));
  if (!(len > 0)) return;  // a repeated point (or NaN): the next segment starts at it
  double s = phase_;
  for (; s < len; s += 1.0) hit(x0 + dx * (s / len), y0 + dy * (s / len));
  phase_ = s - len;
}

void EyeHistogram::add_window(std::span<const double> t, std::span<const double> v, double origin) {
  const size_t n = std::min(t.size(), v.size());
  if (n < 2) return;
  const double w0 = std::max(origin + grid_.t_lo, t[0]);
  const double w1 = std::min(origin + grid_.t_hi, t[n - 1]);
  if (!(w1 > w0)) return;
  ++windows_;
  // Samples strictly inside (w0, w1): [i0, i1).
  const size_t i0 = static_cast<size_t>(std::upper_bound(t.begin(), t.begin() + n, w0) - t.begin());
  const size_t i1 = static_cast<size_t>(std::lower_bound(t.begin(), t.begin() + n, w1) - t.begin());
  auto interp = [&](double tt, size_t hi) {  // t[hi - 1] <= tt <= t[hi]
    if (hi == 0) return v[0];
    if (hi >= n) return v[n - 1];
    const double ta = t[hi - 1], tb = t[hi];
    return tb == ta ? v[hi] : v[hi - 1] + (tt - ta) / (tb - ta) * (v[hi] - v[hi - 1]);
  };
  double pt = w0 - origin, pv = interp(w0, i0);
  bool continues = false;
  for (size_t i = i0; i < i1; ++i) {
    add_segment(pt, pv, t[i] - origin, v[i], continues);
    continues = true;
    pt = t[i] - origin;
    pv = v[i];
  }
  add_segment(pt, pv, w1 - origin, interp(w1, i1), continues);
}

std::vector<double> fold_origins(const CheckResult& r, double period) {
  std::vector<double> out;
  if (!(period > 0)) return out;
  for (const FrameResult& f : r.frames) {
    if (f.last_pulse >= r.pulses.size()) continue;
    const double end = r.pulses[f.last_pulse].b;
    for (int k = 0;; ++k) {
      const double o = f.start + k * period;
      if (!(o < end)) break;
      out.push_back(o);
    }
  }
  return out;
}

size_t EyeHistogram::accumulate(std::span<const double> t, std::span<const double> v,
                                const CheckResult& r) {
  const size_t before = windows_;
  for (double o : fold_origins(r, grid_.period)) add_window(t, v, o);
  return windows_ - before;
}

}  // namespace isolink::eye
