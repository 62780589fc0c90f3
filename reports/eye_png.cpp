#include "reports/eye_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "reports/report_style.h"

namespace isolink::reports {
namespace {

constexpr int kPanelHeight = 960;
constexpr int kNotesWidth = 476;

// Zone tints (TI's eye figures): good, near the threshold, may not be detected.
constexpr Color kZoneGreen = rgb(0xDDF1DA);
constexpr Color kZoneOrange = rgb(0xFFE6C7);
constexpr Color kZoneRed = rgb(0xFBDADA);
constexpr Color kBand = rgb(0x3A7BD5, 0.16f);  // width windows
constexpr Color kBandText = rgb(0x1D4F91);
constexpr Color kGridOver = Color{0, 0, 0, 0.09f};  // gridlines over the tints

// The level from which the eye is "green": the highest VSTART minimum of the rule set.
double green_level(const eye::Rules& r) {
  return r.amplitude == eye::AmplitudeRule::kBq7961x ? std::max(r.vstart_min, r.vstart_min_low_vend)
                                                     : r.vstart_min;
}

// The VSTART minima drawn as dashed levels.
std::vector<double> vstart_levels(const eye::Rules& r) {
  std::vector<double> v{r.vstart_min};
  if (r.amplitude == eye::AmplitudeRule::kBq7961x && r.vstart_min_low_vend != r.vstart_min)
    v.push_back(r.vstart_min_low_vend);
  std::sort(v.begin(), v.end());
  return v;
}

Status check_panels(const std::vector<EyePanel>& panels) {
  if (panels.empty()) return Status::Error("eye.png: no panels to draw");
  for (size_t i = 0; i < panels.size(); ++i) {
    const EyePanel& p = panels[i];
    const std::string name = fmt::format("eye.png panel {} ({})", i + 1, p.direction);
    if (!p.rules || !p.result) return Status::Error(name + ": rules or check result missing");
    if (p.time.size() != p.diff.size())
      return Status::Error(
          fmt::format("{}: {} times but {} values", name, p.time.size(), p.diff.size()));
  }
  return Status::Ok();
}

bool is_time_metric(const std::string& m) {
  return m == "width" || m == "edge";
}

std::string metric_name(const std::string& m) {
  if (m == "vstart") return "VSTART";
  if (m == "vend") return "VEND";
  return m;
}

// value / limit / margin of one worst margin, in the metric's unit.
struct MarginText {
  std::string value, limit, margin;
};
MarginText margin_text(const eye::WorstMargin& w) {
  const bool t = is_time_metric(w.metric);
  const double k = t ? 1e9 : 1.0;
  const char* unit = t ? "ns" : "V";
  const int dec = t ? 1 : 2;
  const eye::Judged& j = w.j;
  // An upper limit when margin = limit - value, a lower one when margin = value - limit.
  const bool upper =
      std::abs(j.margin - (j.limit - j.value)) <= std::abs(j.margin - (j.value - j.limit));
  MarginText m;
  m.value = fmt::format("{:.{}f} {}", j.value * k, dec, unit);
  m.limit = fmt::format("{} {:.{}f}", upper ? "<=" : ">=", j.limit * k, dec);
  m.margin = fmt::format("{:+.{}f} {}", j.margin * k, dec, unit);
  return m;
}

std::string where_text(const eye::WorstMargin& w) {
  std::string s = fmt::format("pulse {} at {}", w.pulse, style::time_us(w.time));
  if (w.frame >= 0) s += fmt::format(", frame {}", w.frame);
  if (!w.role.empty()) s += ", " + w.role;
  return s;
}

void draw_notes(Canvas& c, const EyePanelLayout& L, const EyePanel& p, const eye::EyeHistogram& h) {
  const eye::Rules& rules = *p.rules;
  const eye::CheckResult& r = *p.result;
  const Rect& n = L.notes;
  c.fill_rect(n, rgb(0xF6F6F6));
  c.stroke_rect(n, rgb(0xC8C8C8), 1);
  const int fs = style::kLabelSize;
  const double step = 23;
  const double x = n.x0 + 14;
  double y = n.y0 + 12;
  const int max_w = n.width() - 24;
  auto line = [&](const std::string& s, Color col, FontFace f = FontFace::kMono) {
    std::string shown = s;  // cut to the box
    while (shown.size() > 4 && c.measure(shown, fs, f).width > max_w)
      shown = shown.substr(0, shown.size() - 4) + "...";
    c.text(x, y, shown, fs, col, f, HAlign::kLeft, VAlign::kTop);
    y += step;
  };
  line("Worst margins", kInk, FontFace::kBold);
  line(fmt::format("{:<7}{:>10} {:>9} {:>11}", "", "value", "limit", "margin"), kMuted);
  static const char* kOrder[] = {"vstart", "vend", "width", "edge", "droop"};
  bool any = false;
  for (const char* m : kOrder)
    for (const eye::WorstMargin& w : r.worst) {
      if (w.metric != m || !w.j.judged()) continue;
      any = true;
      const MarginText t = margin_text(w);
      const bool warning = w.metric == "droop";  // over its limit is a warning, not a failure
      const Color bad = warning ? style::kWarn : kFail;
      line(fmt::format("{:<7}{:>10} {:>9} {:>11}", metric_name(w.metric), t.value, t.limit,
                       t.margin),
           w.j.margin < 0 ? bad : kInk);
      line((warning && w.j.margin < 0 ? "  warning: " : "  ") + where_text(w),
           w.j.margin < 0 ? bad : kMuted, FontFace::kSans);
    }
  if (!any) line("no pulse was judged", kMuted, FontFace::kSans);
  y += 10;
  size_t frames_failing = 0, decoded = 0;
  for (const eye::FrameResult& f : r.frames) {
    frames_failing += f.fails() ? 1 : 0;
    decoded += f.byte ? 1 : 0;
  }
  line(fmt::format("pulses {}, failing {}", r.pulses.size(), r.failing()),
       r.failing() ? kFail : kInk, FontFace::kSans);
  if (r.tone)
    line(fmt::format("tone runs {}", r.frames.size()), kInk, FontFace::kSans);
  else
    line(fmt::format("frames {}, decoded {}, failing {}", r.frames.size(), decoded, frames_failing),
         frames_failing ? kFail : kInk, FontFace::kSans);
  line(fmt::format("warnings: ringing {}, idle undershoot {}", r.ringing.size(), r.idle.size()),
       kInk, FontFace::kSans);
  const double T = rules.pulse_time;
  const UnitScale tu = si_scale(T, "s");
  line(fmt::format("folds {}: every T = {:g} {} from each", h.windows(), T * tu.factor, tu.unit),
       kInk, FontFace::kSans);
  line(fmt::format("  {} +{:g} V crossing", r.tone ? "run's first" : "frame's preamble", rules.vth),
       kInk, FontFace::kSans);
  line(fmt::format("resolution {:.3g} ns/px x {:.3g} mV/px", L.grid.dt_per_px() * 1e9,
                   L.grid.dv_per_px() * 1e3),
       kInk, FontFace::kSans);
  if (h.outside() > 0)
    line(fmt::format("{} hits beyond +/-{:g} V not shown", h.outside(), L.grid.v_hi), kMuted,
         FontFace::kSans);

  // Legend of the overlays, at the bottom of the box.
  const double gl = green_level(rules);
  const std::vector<double> vs = vstart_levels(rules);
  std::string vs_text;
  for (double v : vs) vs_text += (vs_text.empty() ? "" : " / ") + fmt::format("{:g}", v);
  std::string windows;
  for (const eye::WidthWindow& w : rules.width) {
    const UnitScale u = si_scale(w.max, "s");
    windows += (windows.empty() ? "" : ", ") +
               fmt::format("{:g}-{:g} {}", w.min * u.factor, w.max * u.factor, u.unit);
  }
  std::vector<LegendEntry> legend{
      {fmt::format("above {:g} V: good", gl), {.color = kZoneGreen}, true},
      {fmt::format("{:g}-{:g} V: near threshold", rules.vth, gl), {.color = kZoneOrange}, true},
      {fmt::format("inside +/-{:g} V: may not detect", rules.vth), {.color = kZoneRed}, true},
      {fmt::format("+/-Vth {:g} V", rules.vth), {.color = kThreshold, .width = 3}},
      {fmt::format("VSTART min {} V", vs_text), {.color = kLevel, .width = 2, .dash = 9, .gap = 5}},
      {fmt::format("idle level {:g} V", rules.idle_level),
       {.color = kMuted, .width = 2, .dash = 2, .gap = 4}},
      {"width window " + windows, {.color = kBand}, true},
      {"fold origin (t = 0)", {.color = kMuted, .width = 2, .dash = 6, .gap = 4}},
  };
  if (r.failing() > 0)
    legend.insert(legend.begin(), {"failing pulse's fold", {.color = kFail, .width = 2}});
  const Rect ls = legend_size(c, legend, fs);
  const int ly = std::max(static_cast<int>(y) + 10, n.y1 - 12 - ls.height());
  draw_legend(c, n.x0 + 14, ly, legend, fs);
}

void draw_panel(Canvas& c, const EyePanelLayout& L, const EyePanel& p) {
  const eye::Rules& rules = *p.rules;
  const eye::CheckResult& r = *p.result;
  style::draw_panel_header(c, L.panel, p.direction, rules, r);
  const PlotArea& a = L.plot;
  const double vlo = L.grid.v_lo, vhi = L.grid.v_hi;
  const double tlo = L.grid.t_lo, thi = L.grid.t_hi;

  // Zones.
  const double gl = green_level(rules), vth = rules.vth;
  c.fill_rect(a.rect, kWhite);
  c.fill_rect(a.data_rect(tlo, thi, gl, vhi), kZoneGreen);
  c.fill_rect(a.data_rect(tlo, thi, vlo, -gl), kZoneGreen);
  c.fill_rect(a.data_rect(tlo, thi, vth, gl), kZoneOrange);
  c.fill_rect(a.data_rect(tlo, thi, -gl, -vth), kZoneOrange);
  c.fill_rect(a.data_rect(tlo, thi, -vth, vth), kZoneRed);
  // Width windows.
  for (const eye::WidthWindow& w : rules.width)
    c.fill_rect(a.data_rect(w.min, w.max, vlo, vhi), kBand);
  const AxisTicks xt = make_ticks(a.x, si_scale(std::max(std::abs(tlo), std::abs(thi)), "s"), 8);
  const AxisTicks yt = make_ticks(a.y, UnitScale{1, "V"}, 12);
  draw_grid(c, a, xt, yt, kGridOver);

  // Density.
  eye::EyeHistogram h(L.grid);
  h.accumulate(p.time, p.diff, r);
  const LogScale scale{static_cast<double>(std::max<uint32_t>(h.max_count(), 1))};
  const ColorMap& map = ColorMap::viridis();
  const int nx = L.grid.nx, ny = L.grid.ny;
  fill_cells(c, a, nx, ny, [&](int ix, int iy) -> std::optional<Color> {
    const uint32_t n = h.count(ix, iy);
    if (n == 0) return std::nullopt;
    return map.at(scale.norm(n));
  });

  // Failing pulses: the fold that starts at each one's half bit, traced in red over the density.
  const std::vector<double> origins = eye::fold_origins(r, rules.pulse_time);
  std::vector<double> xs, ys;
  for (const eye::PulseMetrics& pm : r.pulses) {
    if (!pm.failing()) continue;
    auto it = std::upper_bound(origins.begin(), origins.end(), pm.a + 0.5 * rules.pulse_time);
    if (it == origins.begin()) continue;
    const double o = *(it - 1);
    xs.clear();
    ys.clear();
    const auto b = std::lower_bound(p.time.begin(), p.time.end(), o + tlo);
    const auto e = std::upper_bound(p.time.begin(), p.time.end(), o + thi);
    for (auto i = b; i != e; ++i) {
      const size_t k = static_cast<size_t>(i - p.time.begin());
      xs.push_back(a.px(p.time[k] - o));
      ys.push_back(a.py(p.diff[k]));
    }
    c.polyline(xs, ys, {.color = kFail, .width = 2}, a.rect);
  }

  // Levels.
  const LineStyle origin{.color = kMuted, .width = 2, .dash = 6, .gap = 4};
  c.vline(a.col(0.0), a.rect.y0, a.rect.y1, origin);
  const LineStyle idle{.color = kMuted, .width = 2, .dash = 2, .gap = 4};
  const LineStyle vstart{.color = kLevel, .width = 2, .dash = 9, .gap = 5};
  const LineStyle thr{.color = kThreshold, .width = 3};
  struct Tag {
    double v;
    Color color;
  };
  std::vector<Tag> tags;
  for (double s : {+1.0, -1.0}) {
    if (rules.idle_level > 0 && rules.idle_level < vhi) {
      c.hline(a.row(s * rules.idle_level), a.rect.x0, a.rect.x1, idle);
      tags.push_back({s * rules.idle_level, kMuted});
    }
    for (double v : vstart_levels(rules)) {
      c.hline(a.row(s * v), a.rect.x0, a.rect.x1, vstart);
      tags.push_back({s * v, kLevel});
    }
    c.hline(a.row(s * vth), a.rect.x0, a.rect.x1, thr);
    tags.push_back({s * vth, kThreshold});
  }
  // Value tags right of the plot, pushed apart where levels are close.
  std::vector<double> want;
  for (const Tag& t : tags) want.push_back(a.row(t.v) + 0.5);
  const std::vector<double> at =
      spread_labels(want, style::kLabelSize + 3, a.rect.y0 + 10, a.rect.y1 - 10);
  for (size_t i = 0; i < tags.size(); ++i) {
    c.line(a.rect.x1 + 1, want[i], a.rect.x1 + 9, at[i], {.color = tags[i].color, .width = 1.5});
    c.text(a.rect.x1 + 12, at[i], fmt::format("{:+g}", tags[i].v), style::kLabelSize, tags[i].color,
           FontFace::kSans, HAlign::kLeft, VAlign::kCenter);
  }
  // Width window labels at the top of their bands.
  for (const eye::WidthWindow& w : rules.width) {
    const UnitScale u = si_scale(w.max, "s");
    draw_label(c, a.px((w.min + w.max) / 2), a.rect.y0 + 8,
               fmt::format("{:g}-{:g} {}", w.min * u.factor, w.max * u.factor, u.unit),
               style::kLabelSize, kBandText, HAlign::kCenter, VAlign::kTop);
  }
  if (h.windows() == 0)
    draw_label(c, (a.rect.x0 + a.rect.x1) / 2.0, (a.rect.y0 + a.rect.y1) / 2.0,
               fmt::format("no frames: nothing past +/-{:g} V to fold", vth), style::kHeaderSize,
               kInk, HAlign::kCenter, VAlign::kCenter);

  const std::string x_title =
      fmt::format("time after fold origin (every T = {:g} {} from the {} +{:g} V crossing)",
                  rules.pulse_time * si_scale(rules.pulse_time, "s").factor,
                  si_scale(rules.pulse_time, "s").unit, r.tone ? "run's first" : "preamble's", vth);
  draw_axes(c, a, xt, yt, x_title, "differential voltage v(P) - v(N)", style::kLabelSize);
  draw_colorbar(c, L.colorbar, map, scale, "hits per pixel (log scale)", style::kLabelSize);
  draw_notes(c, L, p, h);
}

}  // namespace

EyeLayout eye_layout(const std::vector<EyePanel>& panels, const EyeReportInfo& info) {
  EyeLayout L;
  L.width = std::max(info.width, 1600);
  const int n = static_cast<int>(std::max<size_t>(panels.size(), 1));
  L.height = style::kTitleHeight + n * kPanelHeight + 8;
  double m = 0;
  for (const EyePanel& p : panels) m = std::max(m, style::max_abs(p.diff));
  L.v_range = style::symmetric_range(m);
  for (int i = 0; i < static_cast<int>(panels.size()); ++i) {
    EyePanelLayout P;
    const int py = style::kTitleHeight + i * kPanelHeight;
    P.panel = {0, py, L.width, py + kPanelHeight};
    const int notes_x0 = L.width - 24 - kNotesWidth;
    const Rect plot{150, py + 100, notes_x0 - 90, py + kPanelHeight - 100};
    const eye::Rules* rules = panels[static_cast<size_t>(i)].rules;
    eye::Rules fallback;
    P.grid = eye::EyeGrid::for_rules(rules ? *rules : fallback, plot.width(), plot.height(),
                                     -L.v_range, L.v_range);
    P.plot = PlotArea::make(plot, P.grid.t_lo, P.grid.t_hi, P.grid.v_lo, P.grid.v_hi);
    P.colorbar = {notes_x0 + 4, plot.y0 + 30, notes_x0 + kNotesWidth - 30, plot.y0 + 54};
    P.notes = {notes_x0, plot.y0 + 100, notes_x0 + kNotesWidth, plot.y1 + 64};
    L.panels.push_back(P);
  }
  return L;
}

StatusOr<Canvas> draw_eye(const std::vector<EyePanel>& panels, const EyeReportInfo& info) {
  if (Status s = check_panels(panels); !s.ok()) return s;
  const EyeLayout L = eye_layout(panels, info);
  StatusOr<Canvas> c = Canvas::create(L.width, L.height);
  if (!c) return c.status();
  bool pass = true;
  for (const EyePanel& p : panels) pass = pass && p.result->pass;
  style::draw_title(*c, "Eye diagram", info.spec, info.source, pass);
  for (size_t i = 0; i < panels.size(); ++i) {
    if (i > 0)
      c->fill_rect({20, L.panels[i].panel.y0, L.width - 20, L.panels[i].panel.y0 + 1},
                   rgb(0xCCCCCC));
    draw_panel(*c, L.panels[i], panels[i]);
  }
  return c;
}

Status render_eye_png(const std::vector<EyePanel>& panels, const EyeReportInfo& info,
                      const std::string& path) {
  StatusOr<Canvas> c = draw_eye(panels, info);
  if (!c) return c.status().with_context(path);
  return c->write_png(path);
}

}  // namespace isolink::reports
