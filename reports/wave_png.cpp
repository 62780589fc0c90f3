#include "reports/wave_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "reports/report_style.h"

namespace isolink::reports {
namespace {

constexpr int kPanelHeight = 940;
constexpr int kSideWidth = 300;

constexpr Color kFrameDecoded = rgb(0xE2EBF7);
constexpr Color kFrameFailing = rgb(0xFAD9D9);
constexpr Color kFrameOther = rgb(0xECECEC);
constexpr Color kFrameTone = rgb(0xEEE4F5);
constexpr Color kFrameEdge = rgb(0x9DB4D3);
constexpr Color kFrameFailText = rgb(0x9B1C1C);  // darker than kFail: only pulses are kFail red
constexpr Color kGridOver = Color{0, 0, 0, 0.09f};

Status check_panels(const std::vector<WavePanel>& panels) {
  if (panels.empty()) return Status::Error("wave.png: no panels to draw");
  for (size_t i = 0; i < panels.size(); ++i) {
    const WavePanel& p = panels[i];
    const std::string name = fmt::format("wave.png panel {} ({})", i + 1, p.direction);
    if (!p.rules || !p.result) return Status::Error(name + ": rules or check result missing");
    if (p.time.size() < 2) return Status::Error(name + ": fewer than 2 samples");
    if (p.diff.size() != p.time.size())
      return Status::Error(
          fmt::format("{}: {} times but {} values", name, p.time.size(), p.diff.size()));
    if (!p.p.empty() && (p.p.size() != p.time.size() || p.n.size() != p.time.size()))
      return Status::Error(fmt::format("{}: P and N need {} values each (have {} and {})", name,
                                       p.time.size(), p.p.size(), p.n.size()));
  }
  return Status::Ok();
}

// The samples of (t, v) over [t0, t1], with values interpolated at both ends.
void clip_series(std::span<const double> t, std::span<const double> v, double t0, double t1,
                 std::vector<double>* xs, std::vector<double>* ys) {
  xs->clear();
  ys->clear();
  const size_t n = t.size();
  t0 = std::max(t0, t[0]);
  t1 = std::min(t1, t[n - 1]);
  if (!(t1 > t0)) return;
  auto at = [&](double tt) {
    const size_t hi = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), tt) - t.begin());
    if (hi == 0) return v[0];
    if (hi >= n) return v[n - 1];
    const double ta = t[hi - 1], tb = t[hi];
    return v[hi - 1] + (tt - ta) / (tb - ta) * (v[hi] - v[hi - 1]);
  };
  xs->push_back(t0);
  ys->push_back(at(t0));
  for (size_t i = static_cast<size_t>(std::upper_bound(t.begin(), t.end(), t0) - t.begin());
       i < n && t[i] < t1; ++i) {
    xs->push_back(t[i]);
    ys->push_back(v[i]);
  }
  xs->push_back(t1);
  ys->push_back(at(t1));
}

void shade_frames(Canvas& c, const PlotArea& a, const eye::CheckResult& r, bool tone,
                  style::LabelRow* labels) {
  const LineStyle edge{.color = kFrameEdge, .width = 1};
  for (size_t i = 0; i < r.frames.size(); ++i) {
    const eye::FrameResult& f = r.frames[i];
    if (f.last_pulse >= r.pulses.size()) continue;
    const double t0 = f.start, t1 = r.pulses[f.last_pulse].b;
    if (t1 < a.x.lo || t0 > a.x.hi) continue;  // outside the plot (a zoom inset)
    const Color fill = f.fails() ? kFrameFailing
                       : tone    ? kFrameTone
                       : f.byte  ? kFrameDecoded
                                 : kFrameOther;
    Rect span = a.data_rect(t0, t1, a.y.lo, a.y.hi);
    if (span.width() < 1) span.x1 = span.x0 + 1;
    c.fill_rect(span, fill);
    c.vline(a.col(t0), a.rect.y0, a.rect.y1, edge);
    std::string text = tone              ? "tone"
                       : f.byte          ? fmt::format("0x{:02X}", *f.byte)
                       : f.fault.empty() ? "?"
                                         : f.fault;
    text = fmt::format("F{} {}", i, text);
    const int w = c.measure(text, style::kLabelSize).width;
    // At the frame's start, or else just right of a reserved span (the marked pulse's box)
    // while still inside the frame.
    std::vector<double> xs{std::max(static_cast<double>(span.x0) + 3, a.rect.x0 + 3.0)};
    for (const auto& [r0, r1] : labels->reserved)
      if (r1 + 8 > xs.front() && r1 + 8 + w < span.x1) xs.push_back(r1 + 8);
    for (double x : xs)
      if (x + w < a.rect.x1 - 2 && labels->fits(x, x + w)) {
        c.text(x, a.rect.y1 - 6, text, style::kLabelSize, f.fails() ? kFrameFailText : kMuted,
               FontFace::kSans, HAlign::kLeft, VAlign::kBottom);
        break;
      }
  }
}

struct FailDrawn {
  std::vector<std::string> names;  // "#12", "tone #3"
  size_t unlabelled = 0;           // failing pulses without a label (no room)
};

// A failing pulse to label: its centre column and name.
struct FailMark {
  double x;
  std::string name;
};

void draw_failing(Canvas& c, const PlotArea& a, const WavePanel& p, const eye::CheckResult& r,
                  double T, const std::string& prefix, std::vector<FailMark>* marks,
                  FailDrawn* out) {
  std::vector<double> xs, ys;
  for (const eye::PulseMetrics& pm : r.pulses) {
    if (!pm.failing()) continue;
    const double lead = pm.edge.measured() ? pm.edge.value : 0.1 * T;
    const double t0 = pm.a - lead, t1 = pm.b;
    clip_series(p.time, p.diff, t0, t1, &xs, &ys);
    c.series(a, xs, ys, LineStyle{.color = kFail, .width = 3});
    const double xm = a.px((t0 + t1) / 2);
    c.fill_rect({static_cast<int>(xm) - 3, a.rect.y0, static_cast<int>(xm) + 4, a.rect.y0 + 10},
                kFail);
    const std::string name = prefix + "#" + std::to_string(pm.index);
    out->names.push_back(name);
    marks->push_back({xm, name});
  }
}

// Labels the failing pulses at the top of the plot: neighbours too close for a label each share
// one ("#49 #50", or "#49..#60 (12)" for longer runs); labels that still collide are dropped.
void label_failing(Canvas& c, const PlotArea& a, std::vector<FailMark> marks, FailDrawn* out) {
  std::sort(marks.begin(), marks.end(),
            [](const FailMark& l, const FailMark& r) { return l.x < r.x; });
  const int fs = style::kLabelSize;
  std::vector<std::vector<FailMark>> groups;
  for (const FailMark& m : marks) {
    if (!groups.empty()) {
      const FailMark& last = groups.back().back();
      const double half = c.measure(last.name, fs, FontFace::kBold).width / 2.0 +
                          c.measure(m.name, fs, FontFace::kBold).width / 2.0 + 10;
      if (m.x - last.x < half) {
        groups.back().push_back(m);
        continue;
      }
    }
    groups.push_back({m});
  }
  style::LabelRow row;
  for (const std::vector<FailMark>& g : groups) {
    std::string text;
    if (g.size() <= 3) {
      for (const FailMark& m : g) text += (text.empty() ? "" : " ") + m.name;
    } else {
      text = fmt::format("{}..{} ({})", g.front().name, g.back().name, g.size());
    }
    const double xm = (g.front().x + g.back().x) / 2;
    const int w = c.measure(text, fs, FontFace::kBold).width;
    const double left = std::clamp(xm - w / 2.0, a.rect.x0 + 4.0, a.rect.x1 - 4.0 - w);
    if (row.fits(left, left + w, 10))
      draw_label(c, left, a.rect.y0 + 14, text, fs, kFail, HAlign::kLeft, VAlign::kTop,
                 kWhite.with_alpha(0.85f), 2, FontFace::kBold);
    else
      out->unlabelled += g.size();
  }
}

// Wraps words into lines no wider than width px.
std::vector<std::string> wrap(const Canvas& c, const std::vector<std::string>& words, int width,
                              int size) {
  std::vector<std::string> lines;
  std::string cur;
  for (const std::string& w : words) {
    const std::string next = cur.empty() ? w : cur + " " + w;
    if (!cur.empty() && c.measure(next, size).width > width) {
      lines.push_back(cur);
      cur = w;
    } else {
      cur = next;
    }
  }
  if (!cur.empty()) lines.push_back(cur);
  return lines;
}

// The dashed box in the plot around the zoom inset's time window.
Rect marked_box(const WavePanelLayout& L) {
  const PlotArea& a = L.diff;
  Rect box{a.col(L.zoom->x.lo), a.rect.y0 + 2, a.col(L.zoom->x.hi) + 1, a.rect.y1 - 2};
  if (box.width() < 6) box.x0 -= 3, box.x1 += 3;
  return box;
}

// The marked pulse: orange in the plot inside a dashed orange box, and magnified in the zoom inset
// below (framed in the same orange), with its label above the inset.
void draw_marked(Canvas& c, const WavePanelLayout& L, const WavePanel& p, const AxisTicks& yt) {
  const PlotArea& a = L.diff;
  const PlotArea& z = *L.zoom;
  const eye::CheckResult& r = *p.result;
  const eye::PulseMetrics& pm = r.pulses[*p.marked];
  const double lead = pm.edge.measured() ? pm.edge.value : 0.1 * p.rules->pulse_time;
  std::vector<double> xs, ys;
  clip_series(p.time, p.diff, pm.a - lead, pm.b, &xs, &ys);
  c.series(a, xs, ys, LineStyle{.color = kMark, .width = 4});
  const LineStyle dashed{.color = kMark, .width = 2, .dash = 6, .gap = 4};
  const Rect box = marked_box(L);
  c.line(box.x0, box.y0, box.x1, box.y0, dashed);
  c.line(box.x0, box.y1, box.x1, box.y1, dashed);
  c.line(box.x0, box.y0, box.x0, box.y1, dashed);
  c.line(box.x1, box.y0, box.x1, box.y1, dashed);

  const UnitScale tu = si_scale(std::max(std::abs(z.x.lo), std::abs(z.x.hi)), "s");
  const AxisTicks zt = make_ticks(z.x, tu, 10);
  style::LabelRow none;
  shade_frames(c, z, r, r.tone, &none);
  draw_grid(c, z, zt, yt, kGridOver);
  clip_series(p.time, p.diff, z.x.lo, z.x.hi, &xs, &ys);
  c.series(z, xs, ys, LineStyle{.color = kTrace, .width = 2});
  for (double s : {+1.0, -1.0})
    c.hline(z.row(s * p.rules->vth), z.rect.x0, z.rect.x1,
            LineStyle{.color = kThreshold, .width = 2});
  clip_series(p.time, p.diff, pm.a - lead, pm.b, &xs, &ys);
  c.series(z, xs, ys, LineStyle{.color = kMark, .width = 4});
  c.stroke_rect(z.rect.inset(-1), kMark, 2);
  draw_axes(c, z, zt, yt, "time", "zoom", style::kLabelSize);
  const std::string label = p.mark_label.empty() ? "marked pulse" : p.mark_label;
  draw_runs(c, L.zoom_label.x0, L.zoom_label.y0 + 4,
            {{"zoom on the worst pulse:  ", kInk, FontFace::kSans},
             {label, kMark, FontFace::kBold},
             {fmt::format("   (pulse {} at {})", pm.index, style::time_us(pm.a)), kMuted,
              FontFace::kSans}},
            style::kLabelSize, VAlign::kTop);
}

void draw_panel(Canvas& c, const WavePanelLayout& L, const WavePanel& p) {
  const eye::Rules& rules = *p.rules;
  const eye::CheckResult& r = *p.result;
  style::draw_panel_header(c, L.panel, p.direction, rules, r);
  const PlotArea& a = L.diff;
  const UnitScale tu = si_scale(std::max(std::abs(a.x.lo), std::abs(a.x.hi)), "s");
  const AxisTicks xt = make_ticks(a.x, tu, 10);
  const AxisTicks yt = make_ticks(a.y, UnitScale{1, "V"}, 8);

  style::LabelRow frame_labels;
  if (L.zoom) {  // the dashed box's sides would cross a frame label inside it
    const Rect box = marked_box(L);
    frame_labels.reserved.emplace_back(box.x0, box.x1);
  }
  if (p.tones) shade_frames(c, a, *p.tones, true, &frame_labels);
  shade_frames(c, a, r, r.tone, &frame_labels);
  draw_grid(c, a, xt, yt, kGridOver);
  c.series(a, p.time, p.diff, LineStyle{.color = kTrace, .width = 2});
  const LineStyle thr{.color = kThreshold, .width = 2};
  for (double s : {+1.0, -1.0}) {
    c.hline(a.row(s * rules.vth), a.rect.x0, a.rect.x1, thr);
    c.text(a.rect.x1 + 8, a.row(s * rules.vth) + 0.5, fmt::format("{:+g}", s * rules.vth),
           style::kLabelSize, kThreshold, FontFace::kSans, HAlign::kLeft, VAlign::kCenter);
  }
  FailDrawn failed;
  std::vector<FailMark> marks;
  draw_failing(c, a, p, r, rules.pulse_time, "", &marks, &failed);
  if (p.tones) draw_failing(c, a, p, *p.tones, 1e-6, "tone ", &marks, &failed);
  label_failing(c, a, marks, &failed);
  if (L.zoom) draw_marked(c, L, p, yt);
  const bool last_plot = !L.pins && !L.zoom;
  draw_axes(c, a, xt, yt, last_plot ? "time" : "", "differential v(P) - v(N)", style::kLabelSize);

  // Side: legend and notes.
  const int fs = style::kLabelSize;
  // The legend names what is drawn: failing entries only when something fails.
  bool frame_fails = false;
  for (const eye::CheckResult* cr : {p.result, p.tones})
    if (cr)
      for (const eye::FrameResult& f : cr->frames) frame_fails = frame_fails || f.fails();
  std::vector<LegendEntry> legend{{"v(P) - v(N)", {.color = kTrace, .width = 2}}};
  if (!failed.names.empty())
    legend.push_back({"failing pulse #index", {.color = kFail, .width = 3}});
  if (p.marked) legend.push_back({"worst pulse", {.color = kMark, .width = 4}});
  legend.push_back({fmt::format("+/-Vth {:g} V", rules.vth), {.color = kThreshold, .width = 2}});
  legend.push_back({r.tone ? "tone run" : "frame, decoded",
                    {.color = r.tone ? kFrameTone : kFrameDecoded},
                    true});
  if (p.tones && !r.tone) legend.push_back({"tone run", {.color = kFrameTone}, true});
  if (frame_fails) legend.push_back({"frame, failing", {.color = kFrameFailing}, true});
  const Rect lb = draw_legend(c, L.side.x0, a.rect.y0, legend, fs);
  double y = lb.y1 + 16;
  auto line = [&](const std::string& s, Color col) {
    c.text(L.side.x0, y, s, fs, col, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
    y += 23;
  };
  line(fmt::format("record {:.4g} - {:.4g} {}", a.x.lo * tu.factor, a.x.hi * tu.factor, tu.unit),
       kInk);
  line(fmt::format("{} samples", p.time.size()), kInk);
  size_t decoded = 0, frames_failing = 0;
  for (const eye::FrameResult& f : r.frames) {
    decoded += f.byte ? 1 : 0;
    frames_failing += f.fails() ? 1 : 0;
  }
  line(fmt::format("pulses {}, failing {}", r.pulses.size(), r.failing()),
       r.failing() ? kFrameFailText : kInk);
  if (!r.tone)
    line(fmt::format("frames {}, decoded {}", r.frames.size(), decoded),
         frames_failing ? kFrameFailText : kInk);
  if (p.tones) line(fmt::format("tone runs {}", p.tones->frames.size()), kInk);
  if (!failed.names.empty()) {
    std::vector<std::string> words{"failing:"};
    const size_t shown = std::min<size_t>(failed.names.size(), 24);
    words.insert(words.end(), failed.names.begin(), failed.names.begin() + shown);
    if (shown < failed.names.size())
      words.push_back(fmt::format("(+{})", failed.names.size() - shown));
    for (const std::string& l : wrap(c, words, L.side.width(), fs)) line(l, kFrameFailText);
    if (failed.unlabelled)
      line(fmt::format("({} not labelled: no room)", failed.unlabelled), kMuted);
  }

  if (!L.pins) return;
  const PlotArea& b = *L.pins;
  const AxisTicks bt = make_ticks(b.x, tu, 10);
  const AxisTicks byt = make_ticks(b.y, UnitScale{1, "V"}, 6);
  draw_grid(c, b, bt, byt, kGrid);
  c.series(b, p.time, p.p, LineStyle{.color = kSeriesP, .width = 2});
  c.series(b, p.time, p.n, LineStyle{.color = kSeriesN, .width = 2});
  c.envelope(b, mean_column_ranges(b, p.time, p.p, p.n), LineStyle{.color = kSeriesCm, .width = 2});
  draw_axes(c, b, bt, byt, "time", "pins", style::kLabelSize);
  draw_legend(c, L.side.x0, b.rect.y0,
              {{"v(P)", {.color = kSeriesP, .width = 2}},
               {"v(N)", {.color = kSeriesN, .width = 2}},
               {"common mode (P + N) / 2", {.color = kSeriesCm, .width = 2}}},
              fs);
}

}  // namespace

WaveLayout wave_layout(const std::vector<WavePanel>& panels, const WaveReportInfo& info) {
  WaveLayout L;
  L.width = std::max(info.width, 1600);
  const int n = static_cast<int>(std::max<size_t>(panels.size(), 1));
  L.height = style::kTitleHeight + n * kPanelHeight + 8;
  double m = 0;
  for (const WavePanel& p : panels) m = std::max(m, style::max_abs(p.diff));
  L.v_range = style::symmetric_range(m);
  for (int i = 0; i < static_cast<int>(panels.size()); ++i) {
    const WavePanel& p = panels[static_cast<size_t>(i)];
    WavePanelLayout P;
    const int py = style::kTitleHeight + i * kPanelHeight;
    P.panel = {0, py, L.width, py + kPanelHeight};
    P.side = {L.width - 20 - kSideWidth, py + 100, L.width - 20, py + kPanelHeight - 100};
    const int x0 = 150, x1 = P.side.x0 - 80;
    const double t0 = p.time.empty() ? 0 : p.time.front();
    const double t1 = p.time.size() < 2 ? t0 + 1e-6 : p.time.back();
    const bool pins = !p.p.empty() && p.p.size() == p.time.size() && p.n.size() == p.time.size();
    const bool zoom =
        !pins && p.marked && p.result && p.rules && *p.marked < p.result->pulses.size();
    P.diff = PlotArea::make({x0, py + 100, x1,
                             py + (pins   ? 560
                                   : zoom ? 500
                                          : 840)},
                            t0, t1, -L.v_range, L.v_range);
    if (zoom) {
      // Four half bits either side of the pulse, inside the record.
      const eye::PulseMetrics& pm = p.result->pulses[*p.marked];
      const double T = p.rules->pulse_time;
      const double z0 = std::max(t0, pm.a - 4 * T), z1 = std::min(t1, pm.b + 4 * T);
      P.zoom_label = {x0, py + 548, x1, py + 580};
      P.zoom = PlotArea::make({x0, py + 590, x1, py + 840}, z0, z1 > z0 ? z1 : z0 + T, -L.v_range,
                              L.v_range);
    }
    if (pins) {
      double lo = 1e300, hi = -1e300;
      for (std::span<const double> s : {p.p, p.n})
        for (double v : s)
          if (std::isfinite(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
      if (!(hi >= lo)) lo = hi = 0;
      const double pad = std::max(0.08 * (hi - lo), 0.25);
      P.pins = PlotArea::make({x0, py + 640, x1, py + 840}, t0, t1, lo - pad, hi + pad);
    }
    L.panels.push_back(P);
  }
  return L;
}

StatusOr<Canvas> draw_wave(const std::vector<WavePanel>& panels, const WaveReportInfo& info) {
  if (Status s = check_panels(panels); !s.ok()) return s;
  const WaveLayout L = wave_layout(panels, info);
  StatusOr<Canvas> c = Canvas::create(L.width, L.height);
  if (!c) return c.status();
  bool pass = true;
  for (const WavePanel& p : panels) pass = pass && p.result->pass && (!p.tones || p.tones->pass);
  style::draw_title(*c, "Waveforms", info.spec, info.source, pass);
  for (size_t i = 0; i < panels.size(); ++i) {
    if (i > 0)
      c->fill_rect({20, L.panels[i].panel.y0, L.width - 20, L.panels[i].panel.y0 + 1},
                   rgb(0xCCCCCC));
    draw_panel(*c, L.panels[i], panels[i]);
  }
  return c;
}

Status render_wave_png(const std::vector<WavePanel>& panels, const WaveReportInfo& info,
                       const std::string& path) {
  StatusOr<Canvas> c = draw_wave(panels, info);
  if (!c) return c.status().with_context(path);
  return c->write_png(path);
}

}  // namespace isolink::reports
