#include "reports/noise_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "netlists/link/cards.h"
#include "reports/plot.h"

namespace isolink::reports {

namespace {

constexpr int kW = 1800, kH = 1650, kFont = 20;
constexpr Color kDirColor[2] = {kSeriesP, kSeriesN};
constexpr Color kLimit = kFail;

struct Panel {
  PlotArea area;
  AxisTicks xt, yt;
};

Panel make_panel(Rect r, double flo, double fhi, double ylo, double yhi, bool ylog,
                 const std::string& yunit) {
  Panel p;
  p.area = PlotArea::make(r, flo, fhi, ylo, yhi);
  p.xt = decade_ticks(flo, fhi, "Hz", si_label);
  if (ylog)
    p.yt = decade_ticks(ylo, yhi, yunit, si_label);
  else
    p.yt = make_ticks(p.area.y, UnitScale{1, yunit}, 7);
  return p;
}

// The y range of the values (log10 when log), padded, at least `min_span` wide.
std::pair<double, double> range_of(const std::vector<double>& v, bool log, double min_span) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double x : v) {
    const double y = log ? std::log10(std::max(x, 1e-30)) : x;
    if (!std::isfinite(y)) continue;
    lo = std::min(lo, y), hi = std::max(hi, y);
  }
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  if (log) lo = std::floor(lo), hi = std::ceil(hi);
  if (hi - lo < min_span) {
    const double mid = (lo + hi) / 2;
    lo = mid - min_span / 2, hi = mid + min_span / 2;
  }
  if (!log) {
    const double pad = (hi - lo) * 0.06;
    lo -= pad, hi += pad;
  }
  return {lo, hi};
}

void line_series(Canvas& c, const PlotArea& a, const std::vector<double>& x,
                 const std::vector<double>& y, const LineStyle& s) {
  std::vector<double> px, py;
  for (size_t i = 0; i < x.size(); ++i) {
    px.push_back(a.px(x[i]));
    py.push_back(a.py(std::clamp(y[i], a.y.lo, a.y.hi)));
  }
  c.polyline(px, py, s, a.rect);
}

}  // namespace

namespace {

// The title with the verdict, and the test level's line.
void draw_noise_title(Canvas& c, const analysis::NoiseResult& r, const std::string& title) {
  const link::NoiseSpec& n = r.spec;
  const std::string what = n.injection == "bci"  ? "BCI (CM current into both wires)"
                           : n.injection == "dm" ? "DM current"
                                                 : "ground shift (CM voltage between grounds)";
  draw_runs(c, 40, 24,
            {{fmt::format("{}: noise immunity, {} ", title, what), kInk, FontFace::kBold},
             {r.pass ? "PASS" : "FAIL", r.pass ? kPass : kFail, FontFace::kBold}},
            30);
  c.text(40, 90,
         fmt::format("test level {} RMS {} (peak x{:.2f}), worst corner of the part tolerances; "
                     "solid: worst case, dashed: nominal",
                     link::format_si(n.level, n.level_unit()),
                     n.modulation == "am" ? "AM 80 % 1 kHz" : "CW", r.peak_factor),
         kFont, kMuted, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
}

// The three panels over log frequency and the ranges of the two log panels (log10 of V and of
// the level's unit).
struct NoisePanels {
  Panel conversion, pins, immunity;
  double v_lo = 0, v_hi = 0, i_lo = 0, i_hi = 0;
};

NoisePanels make_noise_panels(Canvas& c, const analysis::NoiseResult& r, const Rect& r1,
                              const Rect& r2, const Rect& r3) {
  const link::NoiseSpec& n = r.spec;
  const double flo = std::log10(n.f_start), fhi = std::log10(n.f_stop);
  // Panel 1: conversion.
  std::vector<double> all;
  for (const auto& d : r.directions)
    for (const auto& p : d.points)
      all.push_back(p.cm_to_dm_db), all.push_back(p.cm_to_dm_nominal_db);
  auto [c_lo, c_hi] = range_of(all, false, 20);
  c_lo = std::max(c_lo, c_hi - 200);
  Panel p1 = make_panel(r1, flo, fhi, c_lo, c_hi, false, "dB");
  draw_grid(c, p1.area, p1.xt, p1.yt);
  // Panel 2: pin common mode at the level (log).
  all.clear();
  for (const auto& d : r.directions)
    for (const auto& p : d.points) all.push_back(p.pin_cm_v);
  all.push_back(n.pin_limit);
  auto [v_lo, v_hi] = range_of(all, true, 2);
  v_lo = std::max(v_lo, v_hi - 8);
  Panel p2 = make_panel(r2, flo, fhi, v_lo, v_hi, true, "V");
  draw_grid(c, p2.area, p2.xt, p2.yt);
  // Panel 3: immunity (log), test level.
  all.clear();
  for (const auto& d : r.directions)
    for (const auto& p : d.points) all.push_back(p.immunity);
  all.push_back(n.level);
  auto [i_lo, i_hi] = range_of(all, true, 2);
  i_lo = std::max(i_lo, std::log10(n.level) - 5);
  i_hi = std::min(i_hi, std::log10(n.level) + 5);
  Panel p3 = make_panel(r3, flo, fhi, i_lo, i_hi, true, n.level_unit());
  draw_grid(c, p3.area, p3.xt, p3.yt);
  return {p1, p2, p3, v_lo, v_hi, i_lo, i_hi};
}

// Direction k's curves in the three panels, its failing frequencies shaded and its weakest point
// marked; returns its legend entry.
LegendEntry draw_noise_direction(Canvas& c, const NoisePanels& P, const analysis::NoiseResult& r,
                                 size_t k) {
  const link::NoiseSpec& n = r.spec;
  const char* unit = n.level_unit();
  const analysis::NoiseDirection& d = r.directions[k];
  const Color col = kDirColor[k % 2];
  std::vector<double> f, worst, nom, pin, imm;
  for (const auto& p : d.points) {
    f.push_back(std::log10(p.freq_hz));
    worst.push_back(p.cm_to_dm_db);
    nom.push_back(p.cm_to_dm_nominal_db);
    pin.push_back(std::log10(std::max(p.pin_cm_v, 1e-30)));
    imm.push_back(std::log10(std::max(p.immunity, 1e-30)));
  }
  // Failing frequencies: shaded in panel 3.
  for (size_t i = 0; i < d.points.size(); ++i)
    if (d.points[i].immunity < n.level) {
      const double a = i > 0 ? (f[i - 1] + f[i]) / 2 : f[i];
      const double b = i + 1 < f.size() ? (f[i] + f[i + 1]) / 2 : f[i];
      c.fill_rect(P.immunity.area.data_rect(a, b, P.i_lo, std::log10(n.level)),
                  kFail.with_alpha(0.12f));
    }
  line_series(c, P.conversion.area, f, worst, {.color = col, .width = 3});
  line_series(c, P.conversion.area, f, nom, {.color = col, .width = 2, .dash = 10, .gap = 7});
  line_series(c, P.pins.area, f, pin, {.color = col, .width = 3});
  line_series(c, P.immunity.area, f, imm, {.color = col, .width = 3});
  // The weakest point.
  const double xm = P.immunity.area.px(std::log10(d.immunity_min_freq));
  const double ym =
      P.immunity.area.py(std::clamp(std::log10(std::max(d.immunity_min, 1e-30)), P.i_lo, P.i_hi));
  c.stroke_rect(Rect{static_cast<int>(xm) - 7, static_cast<int>(ym) - 7, static_cast<int>(xm) + 8,
                     static_cast<int>(ym) + 8},
                d.pass ? col : kFail, 3);
  draw_label(c, xm + 12, ym + 10,
             fmt::format("{} min {} at {}", link::direction_name(d.direction),
                         link::format_si(d.immunity_min, unit),
                         link::format_si(d.immunity_min_freq, "Hz")),
             kFont - 2, d.pass ? kInk : kFail, HAlign::kLeft, VAlign::kTop);
  return {d.description, {.color = col, .width = 3}};
}

// The pin limit (panel 2) and the test level (panel 3), dashed and labelled.
void draw_noise_limits(Canvas& c, const NoisePanels& P, const link::NoiseSpec& n) {
  const Panel &p2 = P.pins, &p3 = P.immunity;
  const double y = std::log10(n.pin_limit);
  if (y >= P.v_lo && y <= P.v_hi)
    c.hline(p2.area.py(y), p2.area.rect.x0, p2.area.rect.x1,
            {.color = kLimit, .width = 3, .dash = 14, .gap = 8});
  c.hline(p3.area.py(std::log10(n.level)), p3.area.rect.x0, p3.area.rect.x1,
          {.color = kLimit, .width = 3, .dash = 14, .gap = 8});
  draw_label(c, p2.area.rect.x1 - 8,
             p2.area.py(std::clamp(std::log10(n.pin_limit), P.v_lo, P.v_hi)) - 4,
             fmt::format("pin limit +/-{:g} V", n.pin_limit), kFont - 2, kLimit, HAlign::kRight,
             VAlign::kBottom);
  draw_label(c, p3.area.rect.x1 - 8, p3.area.py(std::log10(n.level)) - 4,
             fmt::format("test level {}", link::format_si(n.level, n.level_unit())), kFont - 2,
             kLimit, HAlign::kRight, VAlign::kBottom);
}

}  // namespace

Status write_noise_png(const analysis::NoiseResult& r, const std::string& title,
                       const std::string& path) {
  StatusOr<Canvas> cv = Canvas::create(kW, kH);
  if (!cv) return cv.status();
  Canvas& c = *cv;
  const link::NoiseSpec& n = r.spec;
  draw_noise_title(c, r, title);
  const int x0 = 150, x1 = 1400;
  const Rect r1{x0, 150, x1, 580}, r2{x0, 660, x1, 1060}, r3{x0, 1140, x1, 1560};
  const NoisePanels P = make_noise_panels(c, r, r1, r2, r3);
  std::vector<LegendEntry> legend;
  for (size_t k = 0; k < r.directions.size(); ++k)
    legend.push_back(draw_noise_direction(c, P, r, k));
  draw_noise_limits(c, P, n);
  draw_axes(c, P.conversion.area, P.conversion.xt, P.conversion.yt, "frequency",
            "CM -> DM at the receiver pins", kFont);
  draw_axes(c, P.pins.area, P.pins.xt, P.pins.yt, "frequency", "pin common mode at the test level",
            kFont);
  draw_axes(c, P.immunity.area, P.immunity.xt, P.immunity.yt, "frequency",
            fmt::format("immunity (highest {} level)",
                        n.injection == "ground_shift" ? "voltage" : "current"),
            kFont);
  legend.push_back({"worst corner", {.color = kInk, .width = 3}});
  legend.push_back({"nominal parts", {.color = kInk, .width = 2, .dash = 10, .gap = 7}});
  legend.push_back({"limit / test level", {.color = kLimit, .width = 3, .dash = 14, .gap = 8}});
  legend.push_back({"level fails here", {.color = kFail.with_alpha(0.25f)}, true});
  draw_legend(c, x1 + 30, r1.y0, legend, kFont - 2);
  return c.write_png(path);
}

}  // namespace isolink::reports
