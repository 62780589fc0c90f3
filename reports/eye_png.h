// eye.png of the `isolink run` bundle: per link direction, a density eye diagram of the receiver's
// differential voltage with the rule set's levels, TI-style zones, the width windows and a box of
// worst margins.
//
// Usage (one panel per direction; the caller keeps the samples, rules and results alive):
//   std::vector<EyePanel> panels;
//   panels.push_back({.direction = "down: bq79600 -> bq7961x",
//                     .time = w.time, .diff = *w.column("v(rxp,rxn)"),
//                     .rules = &rules, .result = &*check});
//   Status s = render_eye_png(panels, {.spec = "cap_2m"}, dir + "/eye.png");
//   if (!s.ok()) ...  // the message names the file (and OIIO's error, or the fonts it looked for)
// Eye: eye/eye_diagram.h's histogram, folded every T from each frame's preamble +Vth crossing, on
// a pixel grid of the plot area (one cell per pixel; the s/px and V/px are printed). Colour =
// log10(hits) on viridis, zero-hit pixels show the zone tint underneath. Overlays: +/-Vth (solid
// magenta), the VSTART minima (dashed), the idle level (dotted), zones green (past the higher
// VSTART minimum), orange (between Vth and it), red (inside +/-Vth: may not be detected), and the
// width windows of the rules as blue bands (220-280 ns, 470-530 ns for data); the fold holding each
// failing pulse is traced in red over the density. The image is
// eye_layout(...).width x height: 1920 wide, about 1060 high per panel (>= 1600 x 1000).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "base/status.h"
#include "eye/check.h"
#include "eye/eye_diagram.h"
#include "eye/rules.h"
#include "reports/plot.h"

namespace isolink::reports {

// One link direction.
struct EyePanel {
  std::string direction;                     // e.g. "down: bq79600 -> bq7961x"
  std::span<const double> time;              // seconds, strictly increasing (not owned)
  std::span<const double> diff;              // v(rxp,rxn) at time (not owned)
  const eye::Rules* rules = nullptr;         // the rules result was judged with (not owned)
  const eye::CheckResult* result = nullptr;  // check_samples(time, diff, *rules) (not owned)
};

struct EyeReportInfo {
  std::string spec;    // link spec name, in the title
  std::string source;  // a second title line, e.g. the spec's path ("" = none)
  int width = 1920;    // image width (px), at least 1600
};

// Where each panel's parts go; render_eye_png draws exactly this.
struct EyePanelLayout {
  Rect panel;         // the whole panel
  PlotArea plot;      // the eye: x = time after the fold origin (s), y = volts
  eye::EyeGrid grid;  // histogram grid: the plot's range, one cell per pixel
  Rect colorbar;      // horizontal colour bar
  Rect notes;         // margins, counts and legend
};
struct EyeLayout {
  int width = 0, height = 0;
  double v_range = 3;  // the plots span -v_range .. +v_range (V), the same for every panel
  std::vector<EyePanelLayout> panels;
};

// The layout for these panels (the voltage range covers every panel's samples).
EyeLayout eye_layout(const std::vector<EyePanel>& panels, const EyeReportInfo& info);
// Draws the panels into a new canvas.
StatusOr<Canvas> draw_eye(const std::vector<EyePanel>& panels, const EyeReportInfo& info);
// draw_eye, written to path (through path + ".tmp.png" and a rename).
Status render_eye_png(const std::vector<EyePanel>& panels, const EyeReportInfo& info,
                      const std::string& path);

}  // namespace isolink::reports
