// wave.png of the `isolink run` bundle: per link direction, the receiver's differential waveform
// over the whole record (frames shaded, failing pulses in red with their index), and below it the
// single-ended pins P, N and their common mode.
//
// Usage (one panel per direction; the caller keeps the samples, rules and results alive):
//   std::vector<WavePanel> panels;
//   panels.push_back({.direction = "down: bq79600 -> bq7961x", .time = w.time,
//                     .diff = *w.column("v(rxp,rxn)"), .p = *w.column("v(rxp)"),
//                     .n = *w.column("v(rxn)"), .rules = &rules, .result = &*check});
//   Status s = render_wave_png(panels, {.spec = "cap_2m"}, dir + "/wave.png");
// Long records are drawn per pixel column as the min/max envelope of the samples in the column
// (with the values interpolated at its edges), so every excursion shows and drawing stays fast.
// Frames (CheckResult.frames) are shaded from the preamble's start to the last pulse's end:
// blue = decoded, light red = failing, grey otherwise; labelled with the byte (or fault) where
// there is room. A failing pulse (PulseMetrics.failing) is drawn in kFail red from the start of the
// edge into it to its end b, marked at the top and labelled "#index" (its index in
// CheckResult.pulses) where there is room; nothing else in the image is that red except a FAIL
// verdict. A `marked` pulse (isolink worst's worst pulse) is drawn in kMark orange, framed by a
// dashed box, and shown again magnified in a zoom inset under the plot (4 half bits either side),
// which carries its label: the label never sits on the frames' byte labels in the plot.
// Optional `tones` (a tone check of the same record) adds its failing pulses as "tone #i".
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "base/status.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "reports/plot.h"

namespace isolink::reports {

// One link direction.
struct WavePanel {
  std::string direction;                     // e.g. "down: bq79600 -> bq7961x"
  std::span<const double> time;              // seconds, strictly increasing (not owned)
  std::span<const double> diff;              // v(rxp,rxn) at time (not owned)
  std::span<const double> p;                 // v(rxp) at time; empty = no P/N plot (not owned)
  std::span<const double> n;                 // v(rxn) at time (not owned)
  const eye::Rules* rules = nullptr;         // the rules result was judged with (not owned)
  const eye::CheckResult* result = nullptr;  // the data check of diff (not owned)
  const eye::CheckResult* tones = nullptr;   // optional: a tone check of diff (not owned)
  std::optional<size_t> marked;              // a pulse of result to mark (the worst case's)
  std::string mark_label;                    // its label, e.g. "lowest VSTART 1.83 V"
};

struct WaveReportInfo {
  std::string spec;    // link spec name, in the title
  std::string source;  // a second title line ("" = none)
  int width = 1920;    // image width (px), at least 1600
};

struct WavePanelLayout {
  Rect panel;                    // the whole panel
  PlotArea diff;                 // x = time (s), y = differential volts
  std::optional<PlotArea> pins;  // P, N and common mode (when p and n are given)
  std::optional<PlotArea> zoom;  // the marked pulse magnified (when a pulse is marked)
  Rect zoom_label;               // the band above the zoom inset that holds the marked label
  Rect side;                     // legends and notes, right of the plots
};
struct WaveLayout {
  int width = 0, height = 0;
  double v_range = 3;  // the differential plots span -v_range .. +v_range (V)
  std::vector<WavePanelLayout> panels;
};

WaveLayout wave_layout(const std::vector<WavePanel>& panels, const WaveReportInfo& info);
// Draws the panels into a new canvas.
StatusOr<Canvas> draw_wave(const std::vector<WavePanel>& panels, const WaveReportInfo& info);
// draw_wave, written to path (through path + ".tmp.png" and a rename).
Status render_wave_png(const std::vector<WavePanel>& panels, const WaveReportInfo& info,
                       const std::string& path);

}  // namespace isolink::reports
