#include "reports/sweep_plots.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "reports/report_style.h"

namespace isolink::reports {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kW = kSweepPlotWidth;
constexpr int kH = kSweepPlotHeight;
constexpr int kFont = style::kLabelSize;
constexpr Color kErrorCell = rgb(0xB8B8B8);
constexpr Color kEmptyCell = rgb(0xF2F2F2);

// The value order of an axis: ascending for numbers, as listed otherwise.
std::vector<size_t> axis_order(const SweepPlotAxis& a) {
  std::vector<size_t> o(a.labels.size());
  std::iota(o.begin(), o.end(), size_t{0});
  if (a.numeric())
    std::stable_sort(o.begin(), o.end(),
                     [&](size_t x, size_t y) { return a.values[x] < a.values[y]; });
  return o;
}

// Tick labels of an axis in one SI scale ("2.2" with unit "nF"); metres and degrees unscaled.
UnitScale axis_scale(const SweepPlotAxis& a) {
  if (!a.numeric()) return UnitScale{1, ""};
  if (a.unit == "m" || a.unit == "degC" || a.unit.empty()) return UnitScale{1, a.unit};
  double m = 0;
  for (double v : a.values) m = std::max(m, std::abs(v));
  return si_scale(m, a.unit);
}

std::string value_label(const SweepPlotAxis& a, size_t i, const UnitScale& u) {
  if (!a.numeric()) return a.labels[i];
  return fmt::format("{:.4g}", a.values[i] * u.factor);
}

struct Counts {
  size_t pass = 0, fail = 0, error = 0;
  size_t total() const { return pass + fail + error; }
};
Counts count(const SweepPlotData& d) {
  Counts c;
  for (const SweepPlotPoint& p : d.points) {
    c.pass += p.verdict == "pass";
    c.fail += p.verdict == "fail";
    c.error += p.verdict == "error";
  }
  return c;
}

// Title block: what, the sweep's name, pass counts; the source below.
void draw_header(Canvas& c, const std::string& what, const SweepPlotData& d,
                 const std::string& note) {
  const Counts n = count(d);
  std::vector<TextRun> runs{{what, kInk, FontFace::kBold}};
  if (!d.title.empty()) runs.push_back({"   " + d.title, kInk, FontFace::kSans});
  runs.push_back({fmt::format("   {} of {} pass", n.pass, n.total()),
                  n.pass == n.total() ? kPass : kFail, FontFace::kBold});
  draw_runs(c, 28, 16, runs, style::kTitleSize, VAlign::kTop);
  std::string line = d.source;
  for (const std::string& part : {d.note, note})
    if (!part.empty()) line += (line.empty() ? "" : "   |   ") + part;
  c.text(30, 64, line, kFont, kMuted, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
  c.fill_rect({0, style::kTitleHeight - 2, c.width(), style::kTitleHeight}, rgb(0xBBBBBB));
}

void fill_circle(Canvas& c, double cx, double cy, double r, Color col) {
  for (int y = static_cast<int>(std::floor(cy - r - 1)); y <= static_cast<int>(cy + r + 1); ++y)
    for (int x = static_cast<int>(std::floor(cx - r - 1)); x <= static_cast<int>(cx + r + 1); ++x) {
      const double dist = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const double cov = std::clamp(r + 0.5 - dist, 0.0, 1.0);
      if (cov > 0) c.blend(x, y, col, static_cast<float>(cov));
    }
}

void ring(Canvas& c, double cx, double cy, double r, double w, Color col) {
  for (int y = static_cast<int>(std::floor(cy - r - w)); y <= static_cast<int>(cy + r + w); ++y)
    for (int x = static_cast<int>(std::floor(cx - r - w)); x <= static_cast<int>(cx + r + w); ++x) {
      const double dist = std::abs(std::hypot(x + 0.5 - cx, y + 0.5 - cy) - r);
      const double cov = std::clamp(w / 2 + 0.5 - dist, 0.0, 1.0);
      if (cov > 0) c.blend(x, y, col, static_cast<float>(cov));
    }
}

void cross(Canvas& c, double cx, double cy, double r, Color col) {
  const LineStyle s{.color = col, .width = 3};
  c.line(cx - r, cy - r, cx + r, cy + r, s);
  c.line(cx - r, cy + r, cx + r, cy - r, s);
}

// A margin's (fraction) nice symmetric scale for colours: 5 %, 10 %, 20 %, 25 %, 50 %, 100 %.
double colour_limit(double max_abs) {
  for (double l : {0.05, 0.1, 0.2, 0.25, 0.5, 1.0})
    if (max_abs <= l) return l;
  return 1.0;
}

// Per (axis-0 value, axis-1 value) the worst point: margin min, verdict error > fail > pass.
struct Cell {
  bool any = false;
  double margin = kNaN;
  std::string verdict;
  std::string reason;  // of the first point with the cell's verdict
};
int verdict_rank(const std::string& v) {
  return v == "error" ? 2 : v == "fail" ? 1 : 0;
}

std::vector<Cell> cells_2d(const SweepPlotData& d, size_t nx, size_t ny) {
  std::vector<Cell> cells(nx * ny);
  for (const SweepPlotPoint& p : d.points) {
    if (p.axis.empty()) continue;
    const size_t ix = p.axis[0];
    const size_t iy = p.axis.size() > 1 ? p.axis[1] : 0;
    if (ix >= nx || iy >= ny) continue;
    Cell& c = cells[iy * nx + ix];
    if (!c.any || verdict_rank(p.verdict) > verdict_rank(c.verdict)) {
      c.verdict = p.verdict;
      c.reason = p.reason;
    }
    c.any = true;
    if (!std::isnan(p.margin) && (std::isnan(c.margin) || p.margin < c.margin)) c.margin = p.margin;
  }
  return cells;
}

std::string aggregation_note(const SweepPlotData& d, size_t drawn_axes) {
  std::string note;
  if (d.axes.size() > drawn_axes) {
    std::string rest;
    for (size_t k = drawn_axes; k < d.axes.size(); ++k)
      rest += (rest.empty() ? "" : ", ") + d.axes[k].name;
    note = "worst over " + rest;
  }
  if (d.samples > 0)
    note +=
        (note.empty() ? "worst over " : " and ") + fmt::format("{} Monte Carlo samples", d.samples);
  return note;
}

}  // namespace

Color sweep_series_color(size_t i) {
  static constexpr Color kColors[] = {rgb(0x1F77B4), rgb(0xFF7F0E), rgb(0x2CA02C), rgb(0x9467BD),
                                      rgb(0x8C564B), rgb(0x17BECF), rgb(0xBCBD22), rgb(0x7F7F7F),
                                      rgb(0xE377C2), rgb(0x393B79)};
  return kColors[i % std::size(kColors)];
}

Color diverging_color(double t) {
  // ColorBrewer RdBu ends (#B2182B red, #2166AC blue) through white.
  t = std::clamp(std::isnan(t) ? 0.0 : t, -1.0, 1.0);
  const Color red = rgb(0xB2182B), blue = rgb(0x2166AC), white = rgb(0xF7F7F7);
  const Color end = t < 0 ? red : blue;
  // Slightly faster away from white so small margins are visible.
  const float f = static_cast<float>(std::pow(std::abs(t), 0.8));
  return {white.r + (end.r - white.r) * f, white.g + (end.g - white.g) * f,
          white.b + (end.b - white.b) * f, 1};
}

// --- margin against axis 0 -----------------------------------------------------------------------

double margin_x(const SweepPlotData& d, size_t i) {
  const SweepPlotAxis& a = d.axes.at(0);
  if (!a.numeric()) return static_cast<double>(i);
  return a.log ? std::log10(a.values[i]) : a.values[i];
}

MarginLayout margin_layout(const SweepPlotData& d) {
  MarginLayout L;
  const Rect r{170, style::kTitleHeight + 70, kW - 420, kH - 130};
  double xlo = 0, xhi = 1;
  if (!d.axes.empty()) {
    const SweepPlotAxis& a = d.axes[0];
    if (a.numeric()) {
      xlo = xhi = margin_x(d, 0);
      for (size_t i = 0; i < a.values.size(); ++i) {
        xlo = std::min(xlo, margin_x(d, i));
        xhi = std::max(xhi, margin_x(d, i));
      }
      const double pad = xhi > xlo ? 0.04 * (xhi - xlo) : 0.5;
      xlo -= pad;
      xhi += pad;
    } else {
      xlo = -0.5;
      xhi = static_cast<double>(a.labels.size()) - 0.5;
    }
  }
  double lo = 0, hi = 0;
  for (const SweepPlotPoint& p : d.points)
    if (!std::isnan(p.margin)) lo = std::min(lo, p.margin), hi = std::max(hi, p.margin);
  const double span = std::max(hi - lo, 0.1);
  L.y_lo = (lo - 0.08 * span) * 100;
  L.y_hi = (hi + 0.08 * span) * 100;
  L.plot = PlotArea::make(r, xlo, xhi, L.y_lo / 100, L.y_hi / 100);
  return L;
}

namespace {

// A failing point's reason, where its label goes (pixels).
struct FailReason {
  double x, y;
  std::string text;
};

// The margin plot's x ticks: nice numbers on a linear numeric axis, else one label per value,
// leaving out those that would overlap.
AxisTicks margin_x_ticks(Canvas& c, const PlotArea& a, const SweepPlotData& d) {
  const SweepPlotAxis& ax = d.axes[0];
  const UnitScale xs = axis_scale(ax);
  AxisTicks xt;
  if (ax.numeric() && !ax.log) return make_ticks(a.x, xs, 10);
  xt.unit = xs;
  for (size_t i = 0; i < ax.labels.size(); ++i)
    xt.ticks.push_back({margin_x(d, i), value_label(ax, i, xs)});
  style::LabelRow row;
  std::vector<Tick> kept;
  for (size_t i : axis_order(ax)) {
    const Tick& t = xt.ticks[i];
    const double w = c.measure(t.label, kFont).width;
    if (row.fits(a.px(t.value) - w / 2, a.px(t.value) + w / 2, 12)) kept.push_back(t);
  }
  xt.ticks = kept;
  return xt;
}

// The line of axis-1 value iy, points in axis-0 order, failing points ringed; their reasons and
// the error points' x go to *reasons and *errors. Returns the line's legend entry.
LegendEntry draw_margin_line(Canvas& c, const PlotArea& a, const SweepPlotData& d,
                             const std::vector<Cell>& cells, size_t iy,
                             std::vector<std::pair<double, double>>* errors,
                             std::vector<FailReason>* reasons) {
  const SweepPlotAxis& ax = d.axes[0];
  const bool lines = d.axes.size() >= 2;
  const size_t nx = ax.labels.size();
  const std::vector<size_t> xo = axis_order(ax);
  const Color col = sweep_series_color(iy);
  const LineStyle s{.color = col, .width = 3};
  std::vector<double> px, py;
  auto flush = [&] {
    if (px.size() >= 2) c.polyline(px, py, s, a.rect);
    px.clear();
    py.clear();
  };
  for (size_t ix : xo) {
    const Cell& cell = cells[iy * nx + ix];
    if (!cell.any) continue;
    if (std::isnan(cell.margin)) {
      if (cell.verdict == "error") errors->push_back({a.px(margin_x(d, ix)), 0});
      flush();
      continue;
    }
    px.push_back(a.px(margin_x(d, ix)));
    py.push_back(a.py(cell.margin));
  }
  flush();
  for (size_t ix : xo) {
    const Cell& cell = cells[iy * nx + ix];
    if (!cell.any || std::isnan(cell.margin)) continue;
    const double x = a.px(margin_x(d, ix)), y = a.py(cell.margin);
    fill_circle(c, x, y, 7, col);
    if (cell.verdict != "pass") {
      ring(c, x, y, 11, 3, kFail);
      if (!cell.reason.empty()) reasons->push_back({x, y, cell.reason});
    }
  }
  const std::string label =
      lines ? fmt::format(
                  "{} = {}", d.axes[1].name,
                  value_label(d.axes[1], iy, axis_scale(d.axes[1])) +
                      (axis_scale(d.axes[1]).unit.empty() ? "" : " " + axis_scale(d.axes[1]).unit))
            : "worst margin";
  return {label, s};
}

// Why points fail: one label per distinct reason, at its lowest point, left of the points in the
// right third of the plot; a label that would cover another one is left out (the red rings
// still mark every failing point).
void draw_fail_reasons(Canvas& c, const PlotArea& a, std::vector<FailReason> reasons) {
  std::sort(reasons.begin(), reasons.end(),
            [](const FailReason& p, const FailReason& q) { return p.y > q.y; });
  std::vector<Rect> placed;
  for (size_t i = 0; i < reasons.size(); ++i) {
    bool shown = false;
    for (size_t j = 0; j < i; ++j) shown = shown || reasons[j].text == reasons[i].text;
    if (shown) continue;
    const bool left = reasons[i].x > a.rect.x0 + 0.66 * a.rect.width();
    const double lx = reasons[i].x + (left ? -14 : 14);
    const double ly = std::min(reasons[i].y + 14, a.rect.y1 - 30.0);
    const int w = c.measure(reasons[i].text, kFont - 2).width + 6;
    const Rect box{static_cast<int>(left ? lx - w : lx), static_cast<int>(ly),
                   static_cast<int>(left ? lx : lx + w), static_cast<int>(ly + kFont + 4)};
    bool overlaps = false;
    for (const Rect& r : placed)
      overlaps = overlaps || (box.x0 < r.x1 && r.x0 < box.x1 && box.y0 < r.y1 && r.y0 < box.y1);
    if (overlaps) continue;
    placed.push_back(box);
    draw_label(c, lx, ly, reasons[i].text, kFont - 2, kFail, left ? HAlign::kRight : HAlign::kLeft,
               VAlign::kTop, kWhite.with_alpha(0.8f), 2);
  }
}

}  // namespace

Status render_margin_png(const SweepPlotData& d, const std::string& path) {
  if (d.axes.empty()) return Status::Error(path + ": error: the margin plot needs a swept key");
  StatusOr<Canvas> cv = Canvas::create(kW, kH);
  if (!cv) return cv.status().with_context(path);
  Canvas& c = *cv;
  const MarginLayout L = margin_layout(d);
  const PlotArea& a = L.plot;
  const SweepPlotAxis& ax = d.axes[0];
  const bool lines = d.axes.size() >= 2;
  const size_t nx = ax.labels.size();
  const size_t ny = lines ? d.axes[1].labels.size() : 1;
  draw_header(c, "Worst margin vs " + ax.name, d, aggregation_note(d, lines ? 2 : 1));

  // Pass side shaded, grid, ticks.
  c.fill_rect(a.data_rect(a.x.lo, a.x.hi, 0, a.y.hi), kPassShade);
  const AxisTicks xt = margin_x_ticks(c, a, d);
  const AxisTicks yt = make_ticks(a.y, UnitScale{100, "%"}, 10);
  draw_grid(c, a, xt, yt);
  // The limit.
  c.hline(a.row(0.0), a.rect.x0, a.rect.x1, {.color = kLimitLine, .width = 3});
  draw_label(c, a.rect.x0 + 10, a.row(0.0) - 4, "limit: margin 0 (below fails)", kFont, kLimitLine,
             HAlign::kLeft, VAlign::kBottom, kPassShade.with_alpha(0.85f));

  // One line per axis-1 value, points in axis-0 order.
  const std::vector<Cell> cells = cells_2d(d, nx, ny);
  std::vector<LegendEntry> legend;
  std::vector<std::pair<double, double>> errors;
  std::vector<FailReason> reasons;
  for (size_t iy = 0; iy < ny; ++iy)
    legend.push_back(draw_margin_line(c, a, d, cells, iy, &errors, &reasons));
  draw_fail_reasons(c, a, std::move(reasons));
  for (const auto& [x, unused] : errors) {
    cross(c, x, a.rect.y1 - 22, 9, kMuted);
    c.text(x, a.rect.y1 - 38, "error", kFont, kMuted, FontFace::kSans, HAlign::kCenter,
           VAlign::kBottom);
  }
  draw_axes(c, a, xt, yt, ax.name + (ax.log ? " (log scale)" : ""),
            "worst relative margin (margin / limit)", kFont);

  legend.push_back({"red ring: the point fails", {.color = kFail, .width = 3}});
  legend.push_back({"limit (margin 0)", {.color = kLimitLine, .width = 3}});
  legend.push_back({"pass side", {.color = kPassShade}, true});
  if (!errors.empty()) legend.push_back({"x: point could not be simulated", {.color = kMuted}});
  draw_legend(c, a.rect.x1 + 24, a.rect.y0, legend, kFont);
  return c.write_png(path);
}

// --- heatmap -------------------------------------------------------------------------------------

HeatmapCells heatmap_cells(const SweepPlotData& d) {
  HeatmapCells h;
  if (d.axes.size() < 2) return h;
  const std::vector<size_t> xo = axis_order(d.axes[0]), yo = axis_order(d.axes[1]);
  h.nx = static_cast<int>(xo.size());
  h.ny = static_cast<int>(yo.size());
  const std::vector<Cell> cells = cells_2d(d, xo.size(), yo.size());
  for (int iy = 0; iy < h.ny; ++iy)
    for (int ix = 0; ix < h.nx; ++ix) {
      const Cell& c = cells[yo[static_cast<size_t>(iy)] * xo.size() + xo[static_cast<size_t>(ix)]];
      h.verdict.push_back(c.any ? c.verdict : "");
      h.margin.push_back(c.margin);
      h.reason.push_back(c.reason);
    }
  return h;
}

HeatmapLayout heatmap_layout(const SweepPlotData& d) {
  HeatmapLayout L;
  const HeatmapCells h = heatmap_cells(d);
  L.nx = std::max(h.nx, 1);
  L.ny = std::max(h.ny, 1);
  // Square-ish cells where they fit.
  const int x0 = 230, y0 = style::kTitleHeight + 60;
  const int max_w = kW - 420 - x0, max_h = kH - 150 - y0;
  L.plot = PlotArea::make({x0, y0, x0 + max_w, y0 + max_h}, 0, L.nx, 0, L.ny);
  L.colorbar = {kW - 300, y0 + 40, kW - 270, y0 + max_h - 260};
  double lo = 0, hi = 0;
  for (double v : h.margin)
    if (!std::isnan(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  L.limit_neg = colour_limit(-lo);
  L.limit_pos = colour_limit(hi);
  return L;
}

namespace {

size_t cell_index(const HeatmapCells& h, int ix, int iy) {
  return static_cast<size_t>(iy * h.nx + ix);
}

// The cells coloured by margin (grey when empty or an error), white separators, failing cells
// hatched (a point can fail with every margin positive: a dip, a frame that does not decode).
void draw_heatmap_cells(Canvas& c, const PlotArea& a, const HeatmapLayout& L,
                        const HeatmapCells& h) {
  auto at = [&](int ix, int iy) { return cell_index(h, ix, iy); };
  fill_cells(c, a, h.nx, h.ny, [&](int ix, int iy) -> std::optional<Color> {
    const std::string& v = h.verdict[at(ix, iy)];
    if (v.empty()) return kEmptyCell;
    if (v == "error" || std::isnan(h.margin[at(ix, iy)])) return kErrorCell;
    return diverging_color(L.norm(h.margin[at(ix, iy)]));
  });
  // Thin white separators between cells.
  for (int ix = 1; ix < h.nx; ++ix)
    c.vline(a.col(ix), a.rect.y0, a.rect.y1, {.color = kWhite, .width = 1});
  for (int iy = 1; iy < h.ny; ++iy)
    c.hline(a.row(iy), a.rect.x0, a.rect.x1, {.color = kWhite, .width = 1});
  // Failing cells hatched.
  for (int iy = 0; iy < h.ny; ++iy)
    for (int ix = 0; ix < h.nx; ++ix) {
      if (h.verdict[at(ix, iy)] != "fail") continue;
      const Rect cell{a.col(ix) + 1, a.row(iy + 1) + 1, a.col(ix + 1), a.row(iy) + 1};
      const LineStyle hatch{.color = kFail.with_alpha(0.45f), .width = 2};
      for (int k = -cell.height(); k < cell.width(); k += 18)
        c.line(cell.x0 + k, cell.y1, cell.x0 + k + cell.height(), cell.y0, hatch, cell);
    }
}

// Each cell's margin (and a failing cell's reason) where the cells have room for text.
void draw_heatmap_labels(Canvas& c, const PlotArea& a, const HeatmapLayout& L,
                         const HeatmapCells& h) {
  auto at = [&](int ix, int iy) { return cell_index(h, ix, iy); };
  const double cw = a.rect.width() / static_cast<double>(h.nx);
  const double ch = a.rect.height() / static_cast<double>(h.ny);
  const int fs = cw >= 110 && ch >= 48 ? 20 : cw >= 80 && ch >= 36 ? 16 : 0;
  if (fs > 0)
    for (int iy = 0; iy < h.ny; ++iy)
      for (int ix = 0; ix < h.nx; ++ix) {
        const std::string& v = h.verdict[at(ix, iy)];
        if (v.empty()) continue;
        const double m = h.margin[at(ix, iy)];
        const std::string text = std::isnan(m) ? v : fmt::format("{:+.1f} %", m * 100);
        const double t = std::isnan(m) ? 0 : std::abs(L.norm(m));
        const Color ink = t > 0.55 ? kWhite : kInk;
        const bool two = v != "pass" && !std::isnan(m);
        const double cx = a.px(ix + 0.5), cy = a.py(iy + 0.5);
        draw_label(c, cx, cy + (two ? -fs * 0.6 : 0), text, fs, ink, HAlign::kCenter,
                   VAlign::kCenter, Color{0, 0, 0, 0}, 2);
        if (two) {
          std::string why = v + (h.reason[at(ix, iy)].empty() ? "" : ": " + h.reason[at(ix, iy)]);
          while (why.size() > 6 && c.measure(why, fs - 2, FontFace::kBold).width > cw - 12)
            why = why.substr(0, why.size() - 4) + "...";
          draw_label(c, cx, cy + fs * 0.7, why, fs - 2, kWhite, HAlign::kCenter, VAlign::kCenter,
                     kFail.with_alpha(0.85f), 3, FontFace::kBold);
        }
      }
}

// The boundary: every cell edge between a passing cell and a failing (or error) one.
void draw_heatmap_boundary(Canvas& c, const PlotArea& a, const HeatmapCells& h,
                           const LineStyle& b) {
  auto at = [&](int ix, int iy) { return cell_index(h, ix, iy); };
  auto passes = [&](int ix, int iy) { return h.verdict[at(ix, iy)] == "pass"; };
  auto known = [&](int ix, int iy) { return !h.verdict[at(ix, iy)].empty(); };
  for (int iy = 0; iy < h.ny; ++iy)
    for (int ix = 0; ix < h.nx; ++ix) {
      if (!known(ix, iy)) continue;
      if (ix + 1 < h.nx && known(ix + 1, iy) && passes(ix, iy) != passes(ix + 1, iy))
        c.vline(a.col(ix + 1), a.row(iy + 1) - 2, a.row(iy) + 3, b);
      if (iy + 1 < h.ny && known(ix, iy + 1) && passes(ix, iy) != passes(ix, iy + 1))
        c.hline(a.row(iy + 1), a.col(ix) - 2, a.col(ix + 1) + 3, b);
    }
}

// Axes: a tick per value at the cell centres, labels that would overlap left out.
void draw_heatmap_axes(Canvas& c, const PlotArea& a, const SweepPlotData& d,
                       const HeatmapCells& h) {
  const SweepPlotAxis &ax = d.axes[0], &ay = d.axes[1];
  const UnitScale xs = axis_scale(ax), ys = axis_scale(ay);
  const std::vector<size_t> xo = axis_order(ax), yo = axis_order(ay);
  AxisTicks xt, yt;
  xt.unit = xs;
  yt.unit = ys;
  style::LabelRow row;
  for (int ix = 0; ix < h.nx; ++ix) {
    const std::string lab = value_label(ax, xo[static_cast<size_t>(ix)], xs);
    const double w = c.measure(lab, kFont).width;
    if (row.fits(a.px(ix + 0.5) - w / 2, a.px(ix + 0.5) + w / 2, 10))
      xt.ticks.push_back({ix + 0.5, lab});
  }
  double last_y = 1e18;
  for (int iy = 0; iy < h.ny; ++iy) {
    const double y = a.py(iy + 0.5);
    if (last_y - y < kFont + 4) continue;
    last_y = y;
    yt.ticks.push_back({iy + 0.5, value_label(ay, yo[static_cast<size_t>(iy)], ys)});
  }
  draw_axes(c, a, xt, yt, ax.name, ay.name, kFont);
}

// The colour bar (each half on its own scale) and the legend.
void draw_heatmap_key(Canvas& c, const HeatmapLayout& L, const HeatmapCells& h,
                      const LineStyle& b) {
  const Rect& cb = L.colorbar;
  for (int y = cb.y0; y < cb.y1; ++y) {
    const double t = 1.0 - 2.0 * (y + 0.5 - cb.y0) / cb.height();
    c.fill_rect({cb.x0, y, cb.x1, y + 1}, diverging_color(t));
  }
  c.stroke_rect({cb.x0 - 1, cb.y0 - 1, cb.x1 + 1, cb.y1 + 1}, kInk, 1);
  // Each half of the bar has its own scale (the pass side above the 0 % mark, the fail side below).
  for (int k = -4; k <= 4; ++k) {
    const double v = k < 0 ? k * L.limit_neg / 4 : k * L.limit_pos / 4;
    const double y = cb.y0 + (1.0 - (L.norm(v) + 1.0) / 2.0) * cb.height();
    const bool zero = k == 0;
    c.hline(std::floor(std::min(y, cb.y1 - 1.0)), cb.x1, cb.x1 + (zero ? 14 : 7),
            {.color = zero ? kLimitLine : kInk, .width = zero ? 3.0 : 1.0});
    c.text(cb.x1 + 18, y, fmt::format("{}{:g} %", k > 0 ? "+" : "", v * 100), kFont,
           zero ? kLimitLine : kInk, FontFace::kSans, HAlign::kLeft, VAlign::kCenter);
  }
  c.text(cb.x0 - 10, cb.y0 - 16, "worst relative margin", kFont, kInk, FontFace::kSans,
         HAlign::kLeft, VAlign::kBottom);
  std::vector<LegendEntry> legend{
      {"pass / fail boundary", b},
      {"margin < 0", {.color = diverging_color(-0.8)}, true},
      {"margin > 0", {.color = diverging_color(0.8)}, true},
      {"hatched: the point fails", {.color = kFail.with_alpha(0.45f)}, true}};
  bool any_error = false, any_empty = false;
  for (size_t i = 0; i < h.verdict.size(); ++i) {
    any_error = any_error || h.verdict[i] == "error";
    any_empty = any_empty || h.verdict[i].empty();
  }
  if (any_error) legend.push_back({"could not be simulated", {.color = kErrorCell}, true});
  if (any_empty) legend.push_back({"not run", {.color = kEmptyCell}, true});
  draw_legend(c, cb.x0 - 20, cb.y1 + 40, legend, kFont);
}

}  // namespace

Status render_heatmap_png(const SweepPlotData& d, const std::string& path) {
  if (d.axes.size() < 2) return Status::Error(path + ": error: the heatmap needs two swept keys");
  StatusOr<Canvas> cv = Canvas::create(kW, kH);
  if (!cv) return cv.status().with_context(path);
  Canvas& c = *cv;
  const HeatmapLayout L = heatmap_layout(d);
  const HeatmapCells h = heatmap_cells(d);
  const PlotArea& a = L.plot;
  const SweepPlotAxis &ax = d.axes[0], &ay = d.axes[1];
  draw_header(c, "Pass/fail map: " + ay.name + " vs " + ax.name, d, aggregation_note(d, 2));
  draw_heatmap_cells(c, a, L, h);
  draw_heatmap_labels(c, a, L, h);
  const LineStyle b{.color = kBoundary, .width = 5};
  draw_heatmap_boundary(c, a, h, b);
  draw_heatmap_axes(c, a, d, h);
  draw_heatmap_key(c, L, h, b);
  return c.write_png(path);
}

// --- Monte Carlo histogram -----------------------------------------------------------------------

HistogramLayout histogram_layout(const SweepPlotData& d) {
  HistogramLayout L;
  double lo = 0, hi = 0;
  bool any = false;
  for (const SweepPlotPoint& p : d.points) {
    if (std::isnan(p.margin)) continue;
    lo = any ? std::min(lo, p.margin * 100) : p.margin * 100;
    hi = any ? std::max(hi, p.margin * 100) : p.margin * 100;
    any = true;
  }
  // The limit (0 %) always in view.
  lo = std::min(lo, 0.0);
  hi = std::max(hi, 0.0);
  L.bin = nice_step(std::max(hi - lo, 1.0), 40);
  L.x_lo = (std::floor(lo / L.bin) - 1) * L.bin;
  L.x_hi = (std::floor(hi / L.bin) + 2) * L.bin;
  size_t max_count = 1;
  std::vector<size_t> counts(static_cast<size_t>(std::lround((L.x_hi - L.x_lo) / L.bin)) + 1, 0);
  for (const SweepPlotPoint& p : d.points) {
    if (std::isnan(p.margin)) continue;
    const long k = static_cast<long>(std::floor((p.margin * 100 - L.x_lo) / L.bin));
    if (k >= 0 && static_cast<size_t>(k) < counts.size())
      max_count = std::max(max_count, ++counts[static_cast<size_t>(k)]);
  }
  const Rect r{170, style::kTitleHeight + 70, kW - 460, kH - 130};
  L.plot = PlotArea::make(r, L.x_lo, L.x_hi, 0, std::ceil(max_count * 1.12 + 0.5));
  return L;
}

Status render_mc_histogram_png(const SweepPlotData& d, const std::string& path) {
  StatusOr<Canvas> cv = Canvas::create(kW, kH);
  if (!cv) return cv.status().with_context(path);
  Canvas& c = *cv;
  const HistogramLayout L = histogram_layout(d);
  const PlotArea& a = L.plot;
  const Counts n = count(d);
  std::string note = d.samples > 0 ? fmt::format("{} Monte Carlo samples", d.samples) : "";
  const size_t grid = d.samples > 0 ? (d.points.size() + d.samples - 1) / d.samples : 0;
  if (!d.axes.empty()) note += fmt::format(", pooled over the grid points");
  draw_header(c, "Monte Carlo: worst margin", d, note);

  std::vector<double> ms;
  for (const SweepPlotPoint& p : d.points)
    if (!std::isnan(p.margin)) ms.push_back(p.margin * 100);
  std::vector<size_t> counts(static_cast<size_t>(std::lround((L.x_hi - L.x_lo) / L.bin)) + 1, 0);
  for (double m : ms) {
    const long k = static_cast<long>(std::floor((m - L.x_lo) / L.bin));
    if (k >= 0 && static_cast<size_t>(k) < counts.size()) ++counts[static_cast<size_t>(k)];
  }
  const AxisTicks xt = make_ticks(a.x, UnitScale{1, "%"}, 12);
  AxisTicks yt = make_ticks(a.y, UnitScale{1, ""}, 8);
  if (yt.step < 1) yt = ticks_at(tick_values(a.y.lo, a.y.hi, 1), 1, UnitScale{1, ""});
  draw_grid(c, a, xt, yt);
  for (size_t k = 0; k < counts.size(); ++k) {
    if (counts[k] == 0) continue;
    const double x0 = L.x_lo + k * L.bin, x1 = x0 + L.bin;
    const Color col = x0 >= 0 ? kHistPass : kHistFail;
    Rect bar = a.data_rect(x0, x1, 0, static_cast<double>(counts[k]));
    bar.x0 += 1;  // a gap between bars
    c.fill_rect(bar, col);
  }
  // The limit.
  c.vline(a.col(0.0), a.rect.y0, a.rect.y1, {.color = kLimitLine, .width = 3});
  draw_label(c, a.col(0.0) + 8, a.rect.y0 + 10, "limit: margin 0", kFont, kLimitLine, HAlign::kLeft,
             VAlign::kTop);
  draw_axes(c, a, xt, yt, "worst relative margin (margin / limit)", "points", kFont);

  // Statistics.
  double mean = 0, sd = 0, mn = kNaN;
  for (double m : ms) {
    mean += m;
    mn = std::isnan(mn) ? m : std::min(mn, m);
  }
  if (!ms.empty()) mean /= ms.size();
  for (double m : ms) sd += (m - mean) * (m - mean);
  sd = ms.size() > 1 ? std::sqrt(sd / (ms.size() - 1)) : 0;
  const double yield = n.total() ? 100.0 * n.pass / n.total() : 0;
  const int x = a.rect.x1 + 30;
  int y = a.rect.y0;
  c.text(x, y, fmt::format("yield {:.1f} %", yield), 30, n.pass == n.total() ? kPass : kFail,
         FontFace::kBold, HAlign::kLeft, VAlign::kTop);
  y += 50;
  auto line = [&](const std::string& s, Color col = kInk) {
    c.text(x, y, s, kFont, col, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
    y += 28;
  };
  line(fmt::format("{} of {} points pass", n.pass, n.total()));
  line(fmt::format("{} fail, {} could not run", n.fail, n.error), n.fail + n.error ? kFail : kInk);
  if (grid > 1) line(fmt::format("{} grid points x {} samples", grid, d.samples));
  y += 12;
  line(fmt::format("mean margin {:+.2f} %", mean));
  line(fmt::format("sigma {:.2f} %", sd));
  if (!std::isnan(mn)) line(fmt::format("worst {:+.2f} %", mn), mn < 0 ? kFail : kInk);
  line(fmt::format("bin width {:g} %", L.bin), kMuted);
  y += 20;
  std::vector<LegendEntry> legend{{"passing points", {.color = kHistPass}, true},
                                  {"failing points", {.color = kHistFail}, true},
                                  {"limit (margin 0)", {.color = kLimitLine, .width = 3}}};
  draw_legend(c, x, y, legend, kFont);
  return c.write_png(path);
}

}  // namespace isolink::reports
