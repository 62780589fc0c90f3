#include "reports/compare_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>

#include "reports/plot.h"

namespace isolink::reports {
namespace {

constexpr Color kCapture = rgb(0x1F3A5F);
constexpr Color kSimBefore = rgb(0xF28E00);
constexpr Color kSimAfter = rgb(0x1A8A2E);
constexpr int kFont = 18;

struct Series {
  std::span<const double> y;
  Color color;
  std::string label;
  double width = 1.5;
};

// The capture is drawn first and wide, the simulations narrow over it: a simulation that fits
// leaves the capture visible as a band around it (drawn last, the capture's noise hid them).
constexpr double kCaptureWidth = 4.0, kSimWidth = 1.3;

// One panel of waveforms over [t0, t1] (capture time), y range from the data.
void panel(Canvas& c, const Rect& rect, std::span<const double> t, const std::vector<Series>& s,
           double t0, double t1, const std::string& title, const std::string& y_title) {
  auto lo_it = std::lower_bound(t.begin(), t.end(), t0);
  auto hi_it = std::upper_bound(t.begin(), t.end(), t1);
  const size_t lo = static_cast<size_t>(lo_it - t.begin()),
               hi = static_cast<size_t>(hi_it - t.begin());
  double y0 = 0, y1 = 0;
  for (const Series& x : s)
    for (size_t i = lo; i < hi && i < x.y.size(); ++i) {
      y0 = std::min(y0, x.y[i]);
      y1 = std::max(y1, x.y[i]);
    }
  const double pad = std::max(1e-3, 0.08 * (y1 - y0));
  PlotArea a = PlotArea::make(rect, t0, t1, y0 - pad, y1 + pad);
  AxisTicks xt = make_ticks(a.x, si_scale(std::max(std::abs(t0), std::abs(t1)), "s"), 6);
  AxisTicks yt = make_ticks(a.y, si_scale(std::max(std::abs(y0), std::abs(y1)), "V"), 5);
  draw_grid(c, a, xt, yt);
  for (const Series& x : s)
    if (x.y.size() == t.size() && hi > lo)
      c.series(a, t.subspan(lo, hi - lo), x.y.subspan(lo, hi - lo),
               LineStyle{.color = x.color, .width = x.width});
  draw_axes(c, a, xt, yt, "capture time", y_title, kFont - 2);
  c.text(rect.x0, rect.y0 - 8, title, kFont, kInk, FontFace::kBold);
}

}  // namespace

Status write_compare_png(const analysis::CompareResult& r, const std::string& path) {
  if (r.time.size() < 2) return Status::Error(path + ": error: no waveform to draw");
  const bool fitted = r.sim_after_fit.size() == r.time.size();
  const int zooms = static_cast<int>(r.worst_frames.size());
  const int w = 1800, h = 1150 + (zooms > 0 ? 330 : 0);
  StatusOr<Canvas> cv = Canvas::create(w, h);
  if (!cv) return cv.status();
  Canvas& c = *cv;
  const std::span<const double> t = r.time;
  const bool simulated = r.sim.size() == t.size();  // not for an inconclusive record
  std::vector<double> res(simulated ? t.size() : 0), res_fit;
  // As the residual is counted: 0 where the capture sits on a rail the design exceeds (Clipping).
  for (size_t i = 0; i < res.size(); ++i) res[i] = r.clipping.difference(r.capture[i], r.sim[i]);
  if (fitted) {
    res_fit.resize(t.size());
    for (size_t i = 0; i < t.size(); ++i)
      res_fit[i] = r.clipping.difference(r.capture[i], r.sim_after_fit[i]);
  }
  const Color verdict = r.verdict == "match" ? kPass : kFail;
  // Runs placed by hand: draw_runs measures a run's ink, so a trailing space vanished
  // ("compare:mismatch").
  const std::string head = "isolink compare:";
  const double gap = c.measure("n", 24, FontFace::kBold).width;
  double x = 40;
  c.text(x, 20, head, 24, kInk, FontFace::kBold);
  x += c.measure(head, 24, FontFace::kBold).width + gap;
  c.text(x, 20, r.verdict, 24, verdict, FontFace::kBold);
  x += c.measure(r.verdict, 24, FontFace::kBold).width + 2 * gap;
  c.text(x, 20,
         fmt::format("{} ({}), traffic from the {}", r.direction, r.receiver_rules, r.traffic_from),
         24, kInk);
  std::string line2 = fmt::format("residual rms {:.1f} mV, max {:.0f} mV", r.residual.rms_v * 1e3,
                                  r.residual.max_v * 1e3);
  if (r.residual_after_fit)
    line2 += fmt::format("; after the fit rms {:.1f} mV, max {:.0f} mV",
                         r.residual_after_fit->rms_v * 1e3, r.residual_after_fit->max_v * 1e3);
  line2 += fmt::format("; match needs rms <= {:.1f} mV", r.threshold_rms_v * 1e3);
  c.text(40, 80, line2, kFont, kInk);
  // The findings (two lines at most; report.md lists them all), else what blocks a verdict.
  std::vector<std::string> lines;
  for (const analysis::Finding& f : r.findings) lines.push_back(f.text);
  if (lines.size() > 2) {
    const size_t more = lines.size() - 1;
    lines.resize(1);
    lines.push_back(fmt::format("and {} more findings (report.md)", more));
  }
  for (size_t i = 0; i < lines.size(); ++i)
    c.text(40, 106 + 24 * static_cast<double>(i), lines[i], kFont, kFail);
  double t0 = t.front(), t1 = t.back();
  if (!r.windows.empty()) {
    t0 = std::max(t0, r.windows.front().first - 0.5e-6);
    t1 = std::min(t1, r.windows.back().second + 0.5e-6);
  }
  std::vector<Series> wave = {{r.capture, kCapture, "capture", kCaptureWidth},
                              {r.sim, kSimBefore, "design", kSimWidth}};
  if (fitted) wave.push_back({r.sim_after_fit, kSimAfter, "after the fit", kSimWidth});
  panel(c, {130, 170, w - 60, 620}, t, wave, t0, t1, "capture and simulation", "v(rxp,rxn)");
  std::vector<Series> rs = {{res, kSimBefore, "design"}};
  if (fitted) rs.push_back({res_fit, kSimAfter, "after the fit"});
  panel(c, {130, 700, w - 60, 1020}, t, rs, t0, t1, "residual: capture - simulation", "residual");
  std::vector<LegendEntry> legend = {{"capture", LineStyle{.color = kCapture, .width = 5}},
                                     {"design", LineStyle{.color = kSimBefore, .width = 3}}};
  if (fitted) legend.push_back({"after the fit", LineStyle{.color = kSimAfter, .width = 3}});
  const Rect ls = legend_size(c, legend, kFont);
  draw_legend(c, w - 60 - ls.width() - 10, 180, legend, kFont);
  const int zw = zooms > 0 ? (w - 130 - 60 - (zooms - 1) * 90) / zooms : 0;
  for (int k = 0; k < zooms; ++k) {
    const auto& win = r.windows[r.worst_frames[static_cast<size_t>(k)]];
    const int x0 = 130 + k * (zw + 90);
    panel(c, {x0, 1130, x0 + zw, 1400}, t, wave, win.first, win.second,
          fmt::format("frame with the {} residual, {:.2f} us",
                      k == 0   ? "largest"
                      : k == 1 ? "2nd largest"
                               : "3rd largest",
                      win.first * 1e6),
          "v(rxp,rxn)");
  }
  return c.write_png(path);
}

}  // namespace isolink::reports
