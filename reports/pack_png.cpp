#include "reports/pack_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace isolink::reports {

namespace {

constexpr int kBoxW = 132, kBoxH = 64;  // device boxes
constexpr int kLeft = 150, kTop = 150;  // first box's top-left corner
constexpr int kHopWidth = 9;
constexpr int kLabelPad = 2;   // text to the edge of its backing box
constexpr int kLineClear = 7;  // a label's distance from the hop line's centre
constexpr int kFrame = 4;      // the weakest hop's frame, outside its label
constexpr int kClear = 10;     // free space between a label (with frame) and anything else

Color mix(Color a, Color b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  return {static_cast<float>(a.r + (b.r - a.r) * t), static_cast<float>(a.g + (b.g - a.g) * t),
          static_cast<float>(a.b + (b.b - a.b) * t), 1.0f};
}

std::string length_text(double m) {
  return m < 0.1 ? fmt::format("{:g} cm", std::round(m * 1000) / 10) : fmt::format("{:g} m", m);
}

// A hop label's lines: number, length, isolation, margin.
struct LabelLine {
  std::string text;
  int size = 15;
  FontFace face = FontFace::kSans;
  Color color = kInk;
};
std::vector<LabelLine> label_lines(const PackDiagram& d, const PackDiagram::Hop& h) {
  const bool weak = h.index == d.weakest;
  const std::string m = !h.pass                   ? "FAIL"
                        : std::isfinite(h.margin) ? fmt::format("{:+.1f} %", h.margin * 100)
                                                  : "-";
  return {{fmt::format("hop {}", h.index), 16, weak ? FontFace::kBold : FontFace::kSans,
           weak ? kFail : kInk},
          {length_text(h.length), 15, FontFace::kSans, kInk},
          {h.isolation, 15, FontFace::kSans, kMuted},
          {m, 15, h.pass ? FontFace::kSans : FontFace::kBold, h.pass ? kInk : kFail}};
}

// Backing-box sizes of a label's lines.
std::vector<std::pair<int, int>> line_sizes(const Canvas& c, const std::vector<LabelLine>& ls) {
  std::vector<std::pair<int, int>> out;
  for (const LabelLine& l : ls) {
    const Canvas::TextExtent e = c.measure(l.text, l.size, l.face);
    out.emplace_back(e.width + 2 * kLabelPad, e.ascent + e.descent + 2 * kLabelPad);
  }
  return out;
}

// Lines stacked downwards from top, centred on x.
std::vector<Rect> stack_lines(const std::vector<std::pair<int, int>>& sz, double x, int top,
                              size_t from, size_t to) {
  std::vector<Rect> r;
  for (size_t i = from; i < to; ++i) {
    const int x0 = static_cast<int>(std::lround(x - sz[i].first / 2.0));
    r.push_back({x0, top, x0 + sz[i].first, top + sz[i].second});
    top += sz[i].second;
  }
  return r;
}

Rect bounds_of(const std::vector<Rect>& rs) {
  Rect b = rs.front();
  for (const Rect& r : rs)
    b = {std::min(b.x0, r.x0), std::min(b.y0, r.y0), std::max(b.x1, r.x1), std::max(b.y1, r.y1)};
  return b;
}

}  // namespace

PackLayout pack_layout(const PackDiagram& d, const Canvas& c) {
  PackLayout L;
  const int nodes = d.devices + 1;
  const int rows = (nodes + 8) / 9;  // at most 9 boxes a row, rows filled evenly
  const int per_row = (nodes + rows - 1) / rows;
  // Extents of the labels: widest line; above a horizontal line ("hop N") and below it (the rest);
  // a vertical hop's whole stack.
  int widest = 0, above = 0, below = 0, stack = 0;
  for (const PackDiagram::Hop& h : d.hops) {
    const auto sz = line_sizes(c, label_lines(d, h));
    int b = 0, s = 0;
    for (size_t i = 0; i < sz.size(); ++i) {
      widest = std::max(widest, sz[i].first);
      s += sz[i].second;
      if (i > 0) b += sz[i].second;
    }
    above = std::max(above, sz[0].second);
    below = std::max(below, b);
    stack = std::max(stack, s);
  }
  const int reach_up = kLineClear + above + kFrame, reach_down = kLineClear + below + kFrame;
  // The gap between boxes holds the widest label and its frame with room on both sides.
  const int pitch_x = kBoxW + std::max(64, widest + 2 * (kFrame + kClear));
  // Between rows: the labels below one row's line, a turn's stack, the labels above the next's.
  const int down = std::max(reach_down, kBoxH / 2), up = std::max(reach_up, kBoxH / 2);
  const int pitch_y = std::max(200, down + up + stack + 2 * (kFrame + 2 * kClear));
  for (int k = 0; k < nodes; ++k) {
    const int r = k / per_row, col = r % 2 == 0 ? k % per_row : per_row - 1 - k % per_row;
    const int x = kLeft + col * pitch_x, y = kTop + r * pitch_y;
    L.boxes.push_back({x, y, x + kBoxW, y + kBoxH});
  }
  const int last_line = kTop + (rows - 1) * pitch_y + kBoxH / 2;
  L.ring_y = last_line + std::max(kBoxH / 2 + 40, reach_down + reach_up + kClear);
  L.ring_x = kLeft - 80;
  L.width = std::max(1400, kLeft + (per_row - 1) * pitch_x + kBoxW + 150);
  const int bottom = static_cast<int>(d.ring ? L.ring_y + reach_down : last_line + reach_down);
  L.legend_y = bottom + 60;
  L.height = L.legend_y + 60;

  for (const PackDiagram::Hop& h : d.hops) {
    const auto sz = line_sizes(c, label_lines(d, h));
    double x = 0, y = 0;
    bool across = false;  // a vertical line: the whole stack centred between the rows
    if (h.ring_return) {
      if (!d.ring) continue;
      const Rect& top = L.boxes[static_cast<size_t>(d.devices)];
      x = ((top.x0 + top.x1) / 2.0 + L.ring_x) / 2, y = L.ring_y;
    } else if (h.index >= 1 && h.index <= d.devices) {
      const Rect a = L.boxes[static_cast<size_t>(h.index - 1)];
      const Rect b = L.boxes[static_cast<size_t>(h.index)];
      if (a.y0 == b.y0) {
        x = (std::min(a.x1, b.x1) + std::max(a.x0, b.x0)) / 2.0, y = (a.y0 + a.y1) / 2.0;
      } else {
        across = true;
        x = (a.x0 + a.x1) / 2.0;
        // Centred in the band free of both rows' horizontal labels.
        const int band0 = std::min(a.y0, b.y0) + kBoxH / 2 + down + kFrame + 2 * kClear;
        const int band1 = std::max(a.y0, b.y0) + kBoxH / 2 - up - kFrame - 2 * kClear;
        y = (band0 + band1) / 2.0 - stack / 2.0;
      }
    } else {
      continue;
    }
    PackLayout::Label lab{.hop = h.index};
    if (across) {
      lab.lines = stack_lines(sz, x, static_cast<int>(std::lround(y)), 0, sz.size());
    } else {
      lab.lines =
          stack_lines(sz, x, static_cast<int>(std::lround(y)) - kLineClear - sz[0].second, 0, 1);
      for (const Rect& r :
           stack_lines(sz, x, static_cast<int>(std::lround(y)) + kLineClear, 1, sz.size()))
        lab.lines.push_back(r);
    }
    lab.bounds = bounds_of(lab.lines);
    L.labels.push_back(std::move(lab));
  }
  return L;
}

Color margin_color(bool pass, double margin) {
  if (!pass) return kFail;
  if (!std::isfinite(margin)) return kMuted;
  const Color orange = rgb(0xF28E00), yellow = rgb(0xD8C100), green = rgb(0x1A8A2E);
  return margin < 0.25 ? mix(orange, yellow, margin / 0.25)
                       : mix(yellow, green, (margin - 0.25) / 0.25);
}

Status draw_pack_png(const PackDiagram& d, const std::string& path) {
  StatusOr<Canvas> measure = Canvas::create(1, 1);
  if (!measure) return measure.status();
  const PackLayout L = pack_layout(d, *measure);
  StatusOr<Canvas> cs = Canvas::create(L.width, L.height);
  if (!cs) return cs.status();
  Canvas& c = *cs;
  const PackDiagram::Hop* weakest = nullptr;
  for (const PackDiagram::Hop& h : d.hops)
    if (h.index == d.weakest) weakest = &h;

  c.text(40, 50, d.title, 30, kInk, FontFace::kBold, HAlign::kLeft, VAlign::kCenter);
  c.text(L.width - 40, 50, d.verdict, 30, d.verdict == "PASS" ? kPass : kFail, FontFace::kBold,
         HAlign::kRight, VAlign::kCenter);
  if (weakest)
    c.text(40, 95,
           fmt::format("weakest: hop {} ({} {}), worst margin {}", weakest->index,
                       length_text(weakest->length), weakest->isolation,
                       !weakest->pass ? std::string("FAIL")
                       : std::isfinite(weakest->margin)
                           ? fmt::format("{:+.1f} %", weakest->margin * 100)
                           : std::string("-")),
           20, kMuted, FontFace::kSans, HAlign::kLeft, VAlign::kCenter);

  // Hop lines first, then the boxes over their ends, then the labels.
  for (const PackDiagram::Hop& h : d.hops) {
    const LineStyle st{.color = margin_color(h.pass, h.margin), .width = kHopWidth};
    if (h.ring_return) {
      if (!d.ring) continue;
      const Rect top = L.boxes[static_cast<size_t>(d.devices)], bridge = L.boxes[0];
      const double xt = (top.x0 + top.x1) / 2.0, yb = (bridge.y0 + bridge.y1) / 2.0;
      const std::vector<double> xs{xt, xt, L.ring_x, L.ring_x, static_cast<double>(bridge.x0)};
      const std::vector<double> ys{static_cast<double>(top.y1), L.ring_y, L.ring_y, yb, yb};
      c.polyline(xs, ys, st);
      c.text(L.ring_x - 10, (yb + L.ring_y) / 2, "ring", 16, kMuted, FontFace::kSans,
             HAlign::kCenter, VAlign::kBottom, true);
      continue;
    }
    if (h.index < 1 || h.index > d.devices) continue;
    const Rect a = L.boxes[static_cast<size_t>(h.index - 1)];
    const Rect b = L.boxes[static_cast<size_t>(h.index)];
    if (a.y0 == b.y0)
      c.hline((a.y0 + a.y1) / 2.0, std::min(a.x1, b.x1), std::max(a.x0, b.x0), st);
    else
      c.vline((a.x0 + a.x1) / 2.0, std::min(a.y1, b.y1), std::max(a.y0, b.y0), st);
  }
  for (size_t k = 0; k < L.boxes.size(); ++k) {
    const Rect& r = L.boxes[k];
    c.fill_rect(r, k == 0 ? rgb(0xDCE6F2) : rgb(0xF4F4F4));
    c.stroke_rect(r, kInk, 2);
    const std::string name = k == 0 ? "bridge" : fmt::format("device {}", k);
    c.text((r.x0 + r.x1) / 2.0, (r.y0 + r.y1) / 2.0, name, 18, kInk,
           k == 0 ? FontFace::kBold : FontFace::kSans, HAlign::kCenter, VAlign::kCenter);
  }
  for (const PackLayout::Label& lab : L.labels) {
    const PackDiagram::Hop* h = nullptr;
    for (const PackDiagram::Hop& x : d.hops)
      if (x.index == lab.hop) h = &x;
    const std::vector<LabelLine> lines = label_lines(d, *h);
    for (size_t i = 0; i < lines.size() && i < lab.lines.size(); ++i)
      draw_label(c, lab.lines[i].x0 + kLabelPad, lab.lines[i].y0 + kLabelPad, lines[i].text,
                 lines[i].size, lines[i].color, HAlign::kLeft, VAlign::kTop,
                 kWhite.with_alpha(0.92f), kLabelPad, lines[i].face);
    if (lab.hop == d.weakest) c.stroke_rect(lab.bounds.inset(-kFrame), kFail, 3);
  }

  // Legend: the colour scale of the margin.
  const int ly = L.legend_y, lx = 40;
  c.text(lx, ly, "worst relative margin per hop:", 18, kInk, FontFace::kSans, HAlign::kLeft,
         VAlign::kCenter);
  const int bx = lx + 300, bw = 420;
  for (int i = 0; i < bw; ++i)
    c.vline(bx + i, ly - 12, ly + 12,
            {.color = margin_color(true, 0.5 * i / (bw - 1)), .width = 1});
  c.stroke_rect({bx, ly - 12, bx + bw, ly + 12}, kInk, 1);
  for (int p : {0, 3, 6, 9, 12})
    c.text(bx + bw * p / 12.0, ly + 16, fmt::format("{}{} %", p == 12 ? ">= " : "", p), 15, kInk,
           FontFace::kSans, HAlign::kCenter, VAlign::kTop);
  const int fx = bx + bw + 50;
  c.hline(ly, fx, fx + 60, {.color = kFail, .width = kHopWidth});
  c.text(fx + 70, ly, "fails its rules", 18, kInk, FontFace::kSans, HAlign::kLeft, VAlign::kCenter);
  c.stroke_rect({fx + 250, ly - 14, fx + 290, ly + 14}, kFail, 3);
  c.text(fx + 300, ly, "weakest hop", 18, kInk, FontFace::kSans, HAlign::kLeft, VAlign::kCenter);
  return c.write_png(path);
}

}  // namespace isolink::reports
