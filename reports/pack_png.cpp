#include "reports/pack_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace isolink::reports {

namespace {

constexpr int kBoxW = 132, kBoxH = 64;  // device boxes
constexpr int kPitchX = 196, kPitchY = 200;
constexpr int kLeft = 150, kTop = 150;  // first box's top-left corner
constexpr int kHopWidth = 9;
constexpr double kGreenAt = 0.12;  // relative margin drawn fully green (the width cap)

Color mix(Color a, Color b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  return {static_cast<float>(a.r + (b.r - a.r) * t), static_cast<float>(a.g + (b.g - a.g) * t),
          static_cast<float>(a.b + (b.b - a.b) * t), 1.0f};
}

std::string length_text(double m) {
  return m < 0.1 ? fmt::format("{:g} cm", std::round(m * 1000) / 10) : fmt::format("{:g} m", m);
}

}  // namespace

Color margin_color(bool pass, double margin) {
  if (!pass) return kFail;
  if (!std::isfinite(margin)) return kMuted;
  const Color orange = rgb(0xF28E00), yellow = rgb(0xD8C100), green = rgb(0x1A8A2E);
  return margin < 0.25 ? mix(orange, yellow, margin / 0.25)
                       : mix(yellow, green, (margin - 0.25) / 0.25);
}

Status draw_pack_png(const PackDiagram& d, const std::string& path) {
  const int nodes = d.devices + 1;
  const int rows = (nodes + 8) / 9;  // at most 9 boxes a row, rows filled evenly
  const int per_row = (nodes + rows - 1) / rows;
  const int width = std::max(1400, kLeft + (per_row - 1) * kPitchX + kBoxW + 150);
  const int height = kTop + (rows - 1) * kPitchY + kBoxH + (d.ring ? 170 : 90) + 110;
  StatusOr<Canvas> cs = Canvas::create(width, height);
  if (!cs) return cs.status();
  Canvas& c = *cs;

  // Node k's box (snake order: odd rows run right to left).
  auto box = [&](int k) {
    const int r = k / per_row, col = r % 2 == 0 ? k % per_row : per_row - 1 - k % per_row;
    const int x = kLeft + col * kPitchX, y = kTop + r * kPitchY;
    return Rect{x, y, x + kBoxW, y + kBoxH};
  };
  const PackDiagram::Hop* weakest = nullptr;
  for (const PackDiagram::Hop& h : d.hops)
    if (h.index == d.weakest) weakest = &h;

  c.text(40, 50, d.title, 30, kInk, FontFace::kBold, HAlign::kLeft, VAlign::kCenter);
  c.text(width - 40, 50, d.verdict, 30, d.verdict == "PASS" ? kPass : kFail, FontFace::kBold,
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

  // A hop's label: its number above the line, length and isolation below (beside a vertical
  // line: all three centred on it); the weakest hop's framed in red.
  auto label = [&](const PackDiagram::Hop& h, double x, double y, bool across) {
    const bool weak = h.index == d.weakest;
    const Color bg = kWhite.with_alpha(0.92f);
    const double gap = across ? 0 : 9, up = across ? 28 : 0;
    Rect a = draw_label(c, x, y - gap - up, fmt::format("hop {}", h.index), 16, weak ? kFail : kInk,
                        HAlign::kCenter, VAlign::kBottom, bg, 2,
                        weak ? FontFace::kBold : FontFace::kSans);
    Rect b = draw_label(c, x, y + gap - up, length_text(h.length), 15, kInk, HAlign::kCenter,
                        VAlign::kTop, bg, 2);
    Rect e = draw_label(c, x, b.y1, h.isolation, 15, kMuted, HAlign::kCenter, VAlign::kTop, bg, 2);
    const std::string m = !h.pass                   ? "FAIL"
                          : std::isfinite(h.margin) ? fmt::format("{:+.1f} %", h.margin * 100)
                                                    : "-";
    Rect f = draw_label(c, x, e.y1, m, 15, h.pass ? kInk : kFail, HAlign::kCenter, VAlign::kTop, bg,
                        2, h.pass ? FontFace::kSans : FontFace::kBold);
    if (weak)
      c.stroke_rect({std::min({a.x0, b.x0, e.x0, f.x0}) - 4, a.y0 - 4,
                     std::max({a.x1, b.x1, e.x1, f.x1}) + 4, f.y1 + 4},
                    kFail, 3);
  };

  // Chain hops.
  for (const PackDiagram::Hop& h : d.hops) {
    if (h.ring_return || h.index < 1 || h.index > d.devices) continue;
    const Rect a = box(h.index - 1), b = box(h.index);
    const LineStyle st{.color = margin_color(h.pass, h.margin), .width = kHopWidth};
    if (a.y0 == b.y0) {
      const double y = (a.y0 + a.y1) / 2.0;
      const double x0 = std::min(a.x1, b.x1), x1 = std::max(a.x0, b.x0);
      c.hline(y, x0, x1, st);
      label(h, (x0 + x1) / 2, y, false);
    } else {
      const double x = (a.x0 + a.x1) / 2.0;
      c.vline(x, a.y1, b.y0, st);
      label(h, x, (a.y1 + b.y0) / 2.0, true);
    }
  }
  // The return hop: down from the top device, along the bottom, up the left side to the bridge.
  for (const PackDiagram::Hop& h : d.hops) {
    if (!h.ring_return) continue;
    const Rect top = box(d.devices), bridge = box(0);
    const double y_bottom = kTop + (rows - 1) * kPitchY + kBoxH + 70;
    const double x_left = kLeft - 80;
    const double xt = (top.x0 + top.x1) / 2.0, yb = (bridge.y0 + bridge.y1) / 2.0;
    const LineStyle st{.color = margin_color(h.pass, h.margin), .width = kHopWidth};
    const std::vector<double> xs{xt, xt, x_left, x_left, static_cast<double>(bridge.x0)};
    const std::vector<double> ys{static_cast<double>(top.y1), y_bottom, y_bottom, yb, yb};
    c.polyline(xs, ys, st);
    label(h, (xt + x_left) / 2, y_bottom, false);
    c.text(x_left - 10, (yb + y_bottom) / 2, "ring", 16, kMuted, FontFace::kSans, HAlign::kCenter,
           VAlign::kBottom, true);
  }
  // Boxes over the line ends.
  for (int k = 0; k < nodes; ++k) {
    const Rect r = box(k);
    c.fill_rect(r, k == 0 ? rgb(0xDCE6F2) : rgb(0xF4F4F4));
    c.stroke_rect(r, kInk, 2);
    const std::string name = k == 0 ? "bridge" : fmt::format("device {}", k);
    c.text((r.x0 + r.x1) / 2.0, (r.y0 + r.y1) / 2.0, name, 18, kInk,
           k == 0 ? FontFace::kBold : FontFace::kSans, HAlign::kCenter, VAlign::kCenter);
  }

  // Legend: the colour scale of the margin.
  const int ly = height - 70, lx = 40;
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
