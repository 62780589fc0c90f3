// Sweep charts (isolink sweep): worst margin against the first swept key, a heatmap over the first
// two keys with the pass/fail boundary, and the Monte Carlo histogram of the worst margin.
// Plain data in (no cli/ types): the sweep's axes and one entry per finished point.
//
//   SweepPlotData d;  d.title = "cap-vs-length";  d.axes = {...};  d.points = {...};
//   Status s = render_margin_png(d, "out/sweep_margin.png");      // needs >= 1 axis
//   s = render_heatmap_png(d, "out/sweep_heatmap.png");           // needs >= 2 axes
//   s = render_mc_histogram_png(d, "out/mc_histogram.png");        // needs Monte Carlo samples
// The margin is the relative worst margin (margin / |limit|, shown in %): 0 is the limit. Where a
// grid cell holds several points (Monte Carlo samples, or keys beyond the ones drawn) the chart
// shows the worst of them, and a cell passes only when all of them pass. The *_layout functions
// give the mappings the images are drawn with (tests read pixels back through them).
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the
// image plug-in or its fonts not found, a write that fails); the PNG is written to a temporary
// name and renamed, so a failure leaves no file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "reports/plot.h"

namespace isolink::reports {

struct SweepPlotAxis {
  std::string name;                 // the dotted key ("cable.length")
  std::string unit;                 // SI base unit ("m", "F", "degC", "") for tick labels
  std::vector<std::string> labels;  // the values as text (categories)
  std::vector<double> values;       // numeric values (empty: categorical)
  bool log = false;                 // draw on a log scale (numeric, > 0)
  bool numeric() const { return !values.empty() && values.size() == labels.size(); }
};

struct SweepPlotPoint {
  std::vector<size_t> axis;  // value index per axis
  double margin = 0;         // relative worst margin (fraction; NaN: none, e.g. an error)
  std::string verdict;       // pass | fail | error
  std::string reason;        // why it fails, short ("dip; decode: weak bit"), "" otherwise
};

struct SweepPlotData {
  std::string title;   // the sweep's name
  std::string source;  // the sweep file
  std::string note;    // shown after the source (e.g. the keys held fixed)
  std::vector<SweepPlotAxis> axes;
  std::vector<SweepPlotPoint> points;
  int samples = 0;  // Monte Carlo samples per grid point (0: none)
};

inline constexpr int kSweepPlotWidth = 1800;
inline constexpr int kSweepPlotHeight = 1100;

// Worst margin [%] against axis 0, one line per value of axis 1.
struct MarginLayout {
  PlotArea plot;  // x: axis 0 (log10 of the value on a log axis; the index if categorical)
  double y_lo = 0, y_hi = 0;  // margin range in %
};
MarginLayout margin_layout(const SweepPlotData& d);
// x position of axis 0's value i in the plot's data coordinates.
double margin_x(const SweepPlotData& d, size_t i);
Status render_margin_png(const SweepPlotData& d, const std::string& path);

// Cells over axis 0 (x) and axis 1 (y), coloured by the worst margin; the boundary is drawn on
// the cell edges between passing and failing cells.
struct HeatmapLayout {
  PlotArea plot;  // data coordinates: cell (ix, iy) spans [ix, ix+1) x [iy, iy+1)
  int nx = 0, ny = 0;
  Rect colorbar;
  // Colour scale (fractions): -limit_neg..0 from red to white, 0..+limit_pos from white to blue,
  // each a nice value (5, 10, 20, 25, 50 or 100 %) above the largest margin on its side.
  double limit_neg = 0.05, limit_pos = 0.05;
  double norm(double m) const { return m < 0 ? m / limit_neg : m / limit_pos; }  // -> [-1, 1]
};
HeatmapLayout heatmap_layout(const SweepPlotData& d);
// Per cell (row-major, iy * nx + ix): "pass" | "fail" | "error" | "" (no point), and the worst
// margin (NaN when none).
struct HeatmapCells {
  int nx = 0, ny = 0;
  std::vector<std::string> verdict;
  std::vector<double> margin;
  std::vector<std::string> reason;
};
HeatmapCells heatmap_cells(const SweepPlotData& d);
Status render_heatmap_png(const SweepPlotData& d, const std::string& path);
// The diverging map of the heatmap: red (fail) - white (0) - blue (pass), t in [-1, 1].
Color diverging_color(double t);

// Histogram of every point's worst margin [%], the 0 % limit line and the pass yield.
struct HistogramLayout {
  PlotArea plot;   // x: margin in %, y: points per bin
  double bin = 1;  // bin width in %
  double x_lo = 0, x_hi = 0;
};
HistogramLayout histogram_layout(const SweepPlotData& d);
Status render_mc_histogram_png(const SweepPlotData& d, const std::string& path);

// The heatmap's and the margin plot's colours for a line number.
Color sweep_series_color(size_t i);
inline constexpr Color kBoundary = rgb(0x111111);   // pass/fail boundary on the heatmap
inline constexpr Color kLimitLine = rgb(0xD4008F);  // the 0 % limit (magenta, as Vth)
inline constexpr Color kPassShade = rgb(0xE3F4E1);  // margin plot: the pass side
inline constexpr Color kHistPass = rgb(0x4C9A5A);
inline constexpr Color kHistFail = rgb(0xD64541);

}  // namespace isolink::reports
