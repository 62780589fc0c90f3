#include "reports/stress_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>

namespace isolink::reports {
namespace {

constexpr int kWidth = 1800, kHead = 150, kPanelH = 330, kPanelGap = 70, kLeft = 130, kRight = 260,
              kFont = 18;
constexpr Color kWindow = rgb(0xF28E00, 0.12f);

double limit_value(const analysis::StressResult& r, const std::string& key, double fallback) {
  for (const analysis::StressLimit& l : r.limits)
    if (l.key == key) return l.value;
  return fallback;
}

// How close a scenario's pins came to the limit: the largest |v| over its pins.
double peak_abs(const analysis::StressScenario& s) {
  double m = 0;
  for (const auto& [node, p] : s.peak_pin_v) m = std::max({m, std::abs(p.max), std::abs(p.min)});
  return m;
}

// The text fits in `width` px: cut with "..." at a word boundary when it does not.
std::string fit(const Canvas& c, const std::string& s, int size, int width, FontFace face) {
  if (c.measure(s, size, face).width <= width) return s;
  std::string t = s;
  while (!t.empty() && c.measure(t + " ...", size, face).width > width) {
    const size_t cut = t.find_last_of(' ');
    t.resize(cut == std::string::npos || cut == 0 ? t.size() - 1 : cut);
  }
  return t + " ...";
}

// The pins in the order an engineer reads them: txp, txn, rxp, rxn, then any other.
std::vector<size_t> pin_order(const Waveform& w) {
  std::vector<size_t> order;
  const size_t n = std::min(w.columns.size(), w.names.size());
  for (const char* name : {"txp", "txn", "rxp", "rxn"})
    for (size_t k = 0; k < n; ++k)
      if (w.names[k] == name) order.push_back(k);
  for (size_t k = 0; k < n; ++k)
    if (std::find(order.begin(), order.end(), k) == order.end()) order.push_back(k);
  return order;
}

void draw_panel(Canvas& c, const PlotArea& a, const analysis::StressScenario& s, double limit) {
  const Waveform& w = s.pins;
  const UnitScale tu = si_scale(std::max(std::abs(a.x.lo), std::abs(a.x.hi)), "s");
  const AxisTicks xt = make_ticks(a.x, tu, 8);
  const AxisTicks yt = make_ticks(a.y, UnitScale{1, "V"}, 6);
  draw_grid(c, a, xt, yt);
  c.fill_rect(a.data_rect(s.t_start, std::max(s.t_end, s.t_start + a.x.per_px()), a.y.lo, a.y.hi),
              kWindow);
  const LineStyle lim{.color = kStressLimit, .width = 2, .dash = 10, .gap = 6};
  for (double v : {limit, -limit}) c.hline(a.py(v), a.rect.x0, a.rect.x1, lim);
  std::vector<LegendEntry> legend;
  for (size_t k : pin_order(w)) {
    const LineStyle st{.color = stress_pin_color(w.names[k]), .width = 2};
    c.series(a, w.time, w.columns[k], st);
    const auto g = s.pin_ground.find(w.names[k]);
    legend.push_back({w.names[k] + (g == s.pin_ground.end() ? "" : " to " + g->second), st});
  }
  legend.push_back({fmt::format("pin limit +-{:g} V", limit), lim});
  legend.push_back({"disturbance", LineStyle{.color = kWindow.with_alpha(0.35f)}, true});
  draw_axes(c, a, xt, yt, "time", "pin to its ground", kFont - 2);
  draw_legend(c, a.rect.x1 + 16, a.rect.y0, legend, kFont - 3);
  const std::string head =
      s.first_broken.empty()
          ? fmt::format("{}: nothing broken; pins' largest |v| {:.3g} V", s.id, peak_abs(s))
          : s.id + ": " + s.first_broken;
  c.text(a.rect.x0, a.rect.y0 - 12, fit(c, head, kFont, kWidth - kLeft - 40, FontFace::kBold),
         kFont, s.first_broken.empty() ? kInk : kFail, FontFace::kBold);
}

}  // namespace

Color stress_pin_color(const std::string& node) {
  if (node == "txp") return rgb(0x1F77B4);
  if (node == "txn") return rgb(0xFF7F0E);
  if (node == "rxp") return rgb(0x2CA02C);
  if (node == "rxn") return rgb(0x9467BD);
  return rgb(0x7F7F7F);
}

StressPngLayout stress_png_layout(const analysis::StressResult& r) {
  StressPngLayout L;
  L.width = kWidth;
  L.pin_limit_v = limit_value(r, "pin_abs_max_V", 20.0);
  for (size_t i = 0; i < r.scenarios.size(); ++i)
    if (!r.scenarios[i].first_broken.empty() && L.scenarios.size() < kStressPanels)
      L.scenarios.push_back(i);
  if (L.scenarios.empty() && !r.scenarios.empty()) {
    size_t best = 0;
    for (size_t i = 1; i < r.scenarios.size(); ++i)
      if (peak_abs(r.scenarios[i]) > peak_abs(r.scenarios[best])) best = i;
    L.scenarios.push_back(best);
  }
  int y = kHead;
  for (size_t i : L.scenarios) {
    const analysis::StressScenario& s = r.scenarios[i];
    double lo = -L.pin_limit_v, hi = L.pin_limit_v;
    for (const auto& [node, p] : s.peak_pin_v) lo = std::min(lo, p.min), hi = std::max(hi, p.max);
    const double pad = 0.08 * (hi - lo);
    const double t0 = s.pins.time.empty() ? 0 : s.pins.time.front();
    const double t1 = s.pins.time.empty() ? 1 : s.pins.time.back();
    L.areas.push_back(PlotArea::make({kLeft, y + 40, kWidth - kRight, y + kPanelH}, t0,
                                     t1 > t0 ? t1 : t0 + 1e-9, lo - pad, hi + pad));
    y += kPanelH + kPanelGap;
  }
  L.height = y + 10;
  return L;
}

Status write_stress_png(const analysis::StressResult& r, const std::string& title,
                        const std::string& path) {
  const StressPngLayout L = stress_png_layout(r);
  if (L.scenarios.empty()) return Status::Error(path + ": error: no stress scenario to draw");
  for (size_t i : L.scenarios)
    if (r.scenarios[i].pins.samples() < 2)
      return Status::Error(fmt::format("{}: error: scenario {} has no pin waveform to draw", path,
                                       r.scenarios[i].id));
  StatusOr<Canvas> cv = Canvas::create(L.width, L.height);
  if (!cv) return cv.status();
  Canvas& c = *cv;
  const bool ok = r.survives && r.communicates;
  draw_runs(c, 40, 24,
            {{"isolink stress: " + title + "  ", kInk, FontFace::kBold},
             {ok ? "SURVIVES" : "BREAKS", ok ? kPass : kFail, FontFace::kBold}},
            26);
  c.text(40, 90, fit(c, r.verdict, kFont, kWidth - 80, FontFace::kSans), kFont, kInk);
  size_t broken = 0;
  for (const analysis::StressScenario& s : r.scenarios) broken += s.first_broken.empty() ? 0 : 1;
  const std::string sub =
      broken == 0 ? "Nothing broke; below, the scenario whose pins came closest to the limit."
      : broken > L.scenarios.size()
          ? fmt::format("The first {} of {} scenarios that break something (report.md lists all).",
                        L.scenarios.size(), broken)
          : "Each scenario that breaks something: its pins against their own device's ground.";
  c.text(40, 118, sub, kFont - 2, kMuted);
  for (size_t k = 0; k < L.scenarios.size(); ++k)
    draw_panel(c, L.areas[k], r.scenarios[L.scenarios[k]], L.pin_limit_v);
  return c.write_png(path);
}

}  // namespace isolink::reports
