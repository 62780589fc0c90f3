// A small drawing layer for report images: an RGB canvas, plot areas with
// data -> pixel axis mappings, nice ticks with SI units, grid, lines (solid / dashed,
// anti-aliased), min/max column envelopes for long series, translucent rectangles, text (DejaVu via
// OIIO's render_text, in the plug-in image_plugin.h loads on the first Canvas::create, horizontal
// or vertical), legends, colour maps (viridis, inferno) with a log scale and colour bars. eye_png
// and wave_png are built from it; a line chart, heatmap with contour or histogram needs only these
// pieces.
//
// Usage:
//   StatusOr<Canvas> c = Canvas::create(1920, 1080);            // white, fonts found or an error
//   PlotArea area = PlotArea::make({130, 100, 1330, 900}, 0, 500e-9, -3, 3);
//   AxisTicks xt = make_ticks(area.x, si_scale(500e-9, "s"));  // 0, 100, ... ns
//   AxisTicks yt = make_ticks(area.y, UnitScale{1, "V"});
//   draw_grid(*c, area, xt, yt);
//   c->series(area, t, v, LineStyle{.color = kTrace, .width = 2});  // data coordinates, any length
//   c->hline(area.py(1.2), area.rect.x0, area.rect.x1, LineStyle{.color = kThreshold, .width = 2});
//   draw_axes(*c, area, xt, yt, "time after anchor", "v(rxp,rxn)");
//   Status s = c->write_png("eye.png");                        // temp file + rename
// Pixel convention: pixel (i, j) covers [i, i+1) x [j, j+1), y grows downwards. A data value lands
// in pixel row floor(area.py(v)); horizontal lines of odd width are centred on that row.
// Text is ASCII: common Unicode signs (micro, +/-, <=, >=, dashes, arrows) are replaced by ASCII
// spellings, since OIIO 2.4's renderer garbles non-ASCII characters.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink::reports {

// A colour with opacity; channels in [0, 1].
struct Color {
  float r = 0, g = 0, b = 0, a = 1;
  Color with_alpha(float alpha) const { return {r, g, b, alpha}; }
};
// 0xRRGGBB -> Color.
constexpr Color rgb(uint32_t hex, float alpha = 1.0f) {
  return {static_cast<float>((hex >> 16) & 0xFF) / 255.0f,
          static_cast<float>((hex >> 8) & 0xFF) / 255.0f, static_cast<float>(hex & 0xFF) / 255.0f,
          alpha};
}

// The report palette (shared so images look alike and tests know the colours).
inline constexpr Color kWhite = rgb(0xFFFFFF);
inline constexpr Color kInk = rgb(0x1A1A1A);        // text, frames
inline constexpr Color kGrid = rgb(0xDDDDDD);       // gridlines
inline constexpr Color kMuted = rgb(0x666666);      // secondary text
inline constexpr Color kTrace = rgb(0x1F3A5F);      // a passing waveform (dark blue)
inline constexpr Color kFail = rgb(0xE00000);       // failing pulses, FAIL verdict
inline constexpr Color kPass = rgb(0x1A8A2E);       // PASS verdict
inline constexpr Color kThreshold = rgb(0xD4008F);  // +/- Vth lines (magenta)
inline constexpr Color kLevel = rgb(0x333333);      // VSTART levels (dashed)
inline constexpr Color kSeriesP = rgb(0x1F77B4);    // P line
inline constexpr Color kSeriesN = rgb(0xFF7F0E);    // N line
inline constexpr Color kSeriesCm = rgb(0x2CA02C);   // common mode
inline constexpr Color kMark = rgb(0xF28E00);       // a marked pulse (the worst case's)

enum class FontFace { kSans, kBold, kMono };
enum class HAlign { kLeft, kCenter, kRight };
enum class VAlign { kTop, kCenter, kBaseline, kBottom };

// Font files in use.
struct Fonts {
  std::string sans, bold, mono;
  std::string dir;  // the directory they were found in
};
// The directories find_fonts searches, in order ($ISOLINK_FONT_DIR first when set).
std::vector<std::string> font_search_dirs();
// DejaVuSans.ttf, DejaVuSans-Bold.ttf and DejaVuSansMono.ttf from the first directory in
// font_search_dirs() (or a subdirectory "dejavu" of it) holding all three; an error names them all.
StatusOr<Fonts> find_fonts();
// The same search over the given directories.
StatusOr<Fonts> find_fonts_in(const std::vector<std::string>& dirs);
// Text as the renderer can draw it: ASCII, with Unicode signs spelt out (u, +/-, <=, ->, ...).
std::string ascii_text(std::string_view s);

// Pixel rectangle [x0, x1) x [y0, y1).
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  Rect inset(int d) const { return {x0 + d, y0 + d, x1 - d, y1 - d}; }
};

// Linear map of data [lo, hi] onto pixel coordinates [p_lo, p_hi] (p_hi < p_lo for a y axis).
struct Axis {
  double lo = 0, hi = 1;
  double p_lo = 0, p_hi = 1;
  double to_px(double v) const { return p_lo + (v - lo) / (hi - lo) * (p_hi - p_lo); }
  double from_px(double p) const { return lo + (p - p_lo) / (p_hi - p_lo) * (hi - lo); }
  int pixel(double v) const;  // floor(to_px(v)): the pixel column / row holding v
  double per_px() const { return (hi - lo) / std::abs(p_hi - p_lo); }  // data units per pixel
};

// A data area: x runs left to right over rect, y bottom to top.
struct PlotArea {
  Rect rect;
  Axis x, y;
  static PlotArea make(Rect r, double x_lo, double x_hi, double y_lo, double y_hi);
  double px(double xv) const { return x.to_px(xv); }
  double py(double yv) const { return y.to_px(yv); }
  int row(double yv) const { return y.pixel(yv); }                   // pixel row of a y value
  int col(double xv) const { return x.pixel(xv); }                   // pixel column of an x value
  Rect data_rect(double x0, double x1, double y0, double y1) const;  // clipped to rect
};

// Line style: colour, width in px, optional dash pattern (dash on, gap off, in px).
struct LineStyle {
  Color color = kInk;
  double width = 1.5;
  double dash = 0;  // 0 = solid
  double gap = 0;
};

// Per pixel column, the range of a series (data units).
struct ColumnRange {
  double lo = 0, hi = 0;
  bool valid = false;
};

// Loads the image plug-in now rather than on the first Canvas::create (OpenImageIO and its
// libraries: about 0.3 s of relocations); thread-safe, and a create waits for a load under way.
// `isolink sweep` loads it on a low-priority thread while its points run.
void load_image_plugin();

class Canvas {
 public:
  // A width x height RGB image filled with background, with the DejaVu fonts located.
  static StatusOr<Canvas> create(int width, int height, Color background = kWhite);

  int width() const { return w_; }
  int height() const { return h_; }
  Rect bounds() const { return {0, 0, w_, h_}; }
  const Fonts& fonts() const { return fonts_; }
  const std::vector<uint8_t>& rgb() const { return px_; }  // 8-bit RGB, row-major
  Color pixel(int x, int y) const;                         // opaque colour at (x, y)

  // "Over" compositing of c (its alpha times coverage) at one pixel; ignored outside.
  void blend(int x, int y, Color c, float coverage = 1.0f);
  void fill_rect(const Rect& r, Color c);                   // clipped, alpha-blended
  void stroke_rect(const Rect& r, Color c, int width = 1);  // outline inside r
  // Horizontal line across [x0, x1) at pixel row floor(y) (width rounded, odd widths centred).
  void hline(double y, double x0, double x1, const LineStyle& s);
  // Vertical line down [y0, y1) at pixel column floor(x).
  void vline(double x, double y0, double y1, const LineStyle& s);
  // Anti-aliased segment between pixel coordinates (dash pattern follows its length).
  void line(double x0, double y0, double x1, double y1, const LineStyle& s, Rect clip = {});
  // Connected segments through pixel points (xs[i], ys[i]).
  void polyline(std::span<const double> xs, std::span<const double> ys, const LineStyle& s,
                Rect clip = {});
  // A series in data coordinates, x increasing, drawn as per-column min/max envelopes: exact for
  // long records (one vertical span per pixel column) and fast. Dashes are ignored.
  void series(const PlotArea& a, std::span<const double> x, std::span<const double> y,
              const LineStyle& s);
  // Draws precomputed envelopes (column_ranges), columns a.rect.x0 + i.
  void envelope(const PlotArea& a, const std::vector<ColumnRange>& cols, const LineStyle& s);

  // Draws text; (x, y) is the anchor point that halign / valign refer to. vertical = rotated a
  // quarter turn counter-clockwise (reads bottom to top; alignment then refers to the rotated box).
  // Returns the box it covers.
  Rect text(double x, double y, std::string_view s, int size, Color c,
            FontFace face = FontFace::kSans, HAlign ha = HAlign::kLeft,
            VAlign va = VAlign::kBaseline, bool vertical = false);
  // Width of s and its ascent / descent (above / below the baseline) in px.
  struct TextExtent {
    int width = 0, ascent = 0, descent = 0;
  };
  TextExtent measure(std::string_view s, int size, FontFace face = FontFace::kSans) const;

  // Encodes the PNG in memory, then write_file_atomic (base/file_io.h); errors name the path.
  Status write_png(const std::string& path) const;

 private:
  Canvas() = default;
  const std::string& font(FontFace f) const;
  void line_impl(double x0, double y0, double x1, double y1, const LineStyle& s, Rect clip,
                 double dash_offset);
  int w_ = 0, h_ = 0;
  std::vector<uint8_t> px_;  // RGB, row-major
  Fonts fonts_;
};

// A piece of a line of text with its own colour and face (e.g. a verdict in green or red).
struct TextRun {
  std::string text;
  Color color = kInk;
  FontFace face = FontFace::kSans;
};
// Draws runs one after another from (x, y) (left edge; valign as in Canvas::text); returns the box.
Rect draw_runs(Canvas& c, double x, double y, const std::vector<TextRun>& runs, int size,
               VAlign va = VAlign::kTop);
// Text on a filled box (pad px around the text), e.g. a label over data; returns the box.
Rect draw_label(Canvas& c, double x, double y, std::string_view s, int size, Color text, HAlign ha,
                VAlign va, Color background = kWhite.with_alpha(0.85f), int pad = 3,
                FontFace face = FontFace::kSans);
// Moves label centres (wanted, any order) apart to at least min_gap, staying inside [lo, hi] where
// possible and as close to where they were wanted as it can; returns them in the input order.
std::vector<double> spread_labels(const std::vector<double>& wanted, double min_gap, double lo,
                                  double hi);

// --- ticks and units ---------------------------------------------------------------------------

// Values are shown as value * factor followed by unit ("ns", "us", "V").
struct UnitScale {
  double factor = 1;
  std::string unit;
};
// An SI prefix for values up to max_abs of base_unit: 3e-7 s -> {1e9, "ns"}; 4e-4 -> {1e6, "us"}.
UnitScale si_scale(double max_abs, std::string_view base_unit);
// A step of 1, 2, 2.5 or 5 x 10^k giving about target intervals over span.
double nice_step(double span, int target);
// The multiples of step inside [lo, hi] (with a small tolerance at the ends).
std::vector<double> tick_values(double lo, double hi, double step);
// A tick label: the value scaled, with as many decimals as the step needs ("-1.5", "250").
std::string tick_label(double value, double step, const UnitScale& u);

struct Tick {
  double value = 0;
  std::string label;
};
struct AxisTicks {
  std::vector<Tick> ticks;
  UnitScale unit;
  double step = 0;
};
// Nice ticks over the axis range, about target of them.
AxisTicks make_ticks(const Axis& a, const UnitScale& u, int target = 8);
// Ticks at the given values.
AxisTicks ticks_at(std::vector<double> values, double step, const UnitScale& u);
// A value with an SI prefix and neither space nor unit ("1M", "2.5k", "100m"): the decade labels
// of decade_ticks on frequency and magnitude axes.
std::string si_label(double v);
// Ticks at the decades 10^k inside [lo, hi], for an axis of log10 values, each labelled
// label(10^k) (e.g. "1M" on an axis titled in Hz).
AxisTicks decade_ticks(double lo, double hi, const std::string& unit,
                       const std::function<std::string(double)>& label);

// Gridlines at the ticks (inside a.rect).
void draw_grid(Canvas& c, const PlotArea& a, const AxisTicks& xt, const AxisTicks& yt,
               Color color = kGrid);
// The frame, tick marks, tick labels (font_size px) and axis titles; the unit is appended to each
// title in brackets ("time [ns]"). Empty titles are left out.
void draw_axes(Canvas& c, const PlotArea& a, const AxisTicks& xt, const AxisTicks& yt,
               const std::string& x_title, const std::string& y_title, int font_size = 18);

// --- legends -------------------------------------------------------------------------------------

struct LegendEntry {
  std::string label;
  LineStyle line;    // drawn as a short line sample unless box
  bool box = false;  // a filled swatch of line.color instead
};
// The size a legend needs.
Rect legend_size(const Canvas& c, const std::vector<LegendEntry>& entries, int font_size = 18);
// Draws a legend box with its top-left corner at (x, y); returns the box.
Rect draw_legend(Canvas& c, int x, int y, const std::vector<LegendEntry>& entries,
                 int font_size = 18);

// --- colour maps ---------------------------------------------------------------------------------

// A 256-entry colour table.
class ColorMap {
 public:
  static const ColorMap& viridis();  // perceptually uniform, dark blue-violet -> yellow
  static const ColorMap& inferno();  // perceptually uniform, black -> pale yellow
  Color at(double t) const;          // t in [0, 1] (clamped)
  const std::array<Color, 256>& table() const { return table_; }

 private:
  explicit ColorMap(const std::array<Color, 256>& t) : table_(t) {}
  std::array<Color, 256> table_;
};

// Maps counts 1..max onto [0, 1] logarithmically (1 -> 0, max -> 1); zero counts have no colour.
struct LogScale {
  double max = 1;
  double norm(double count) const;
};

// A colour bar in r for counts 1..scale.max: vertical (labels right of it) when r is taller than
// wide, else horizontal (low counts left, labels below). Decade labels 1, 10, 100, 1k, ...
void draw_colorbar(Canvas& c, const Rect& r, const ColorMap& map, const LogScale& scale,
                   const std::string& title, int font_size = 18);

// Fills the nx x ny cells spanning a's data range [x.lo, x.hi] x [y.lo, y.hi] (cell (0, 0) at the
// lower left) with the colour cell(ix, iy) returns, or leaves it when that is empty. Heatmaps and
// the eye's density use it.
void fill_cells(Canvas& c, const PlotArea& a, int nx, int ny,
                const std::function<std::optional<Color>(int ix, int iy)>& cell);

// A straight piece of a contour line, in data coordinates.
struct ContourSegment {
  double x0, y0, x1, y1;
};
// Marching squares: where the field z crosses level. z is nx x ny values, row-major with row 0 at
// the bottom, sampled at the centres of the cells spanning a's data range (as fill_cells lays them
// out); crossings are interpolated linearly along cell edges. A heatmap's pass/fail boundary is
// contour_segments(margin, ..., 0.0).
std::vector<ContourSegment> contour_segments(const PlotArea& a, std::span<const double> z, int nx,
                                             int ny, double level);
// Draws the segments (clipped to a.rect).
void draw_contour(Canvas& c, const PlotArea& a, const std::vector<ContourSegment>& segs,
                  const LineStyle& s);

// Per-column min/max of a series y(x) (x increasing) over the columns of a: each column covers the
// data between its edges, including the values interpolated at the edges, so spans connect.
std::vector<ColumnRange> column_ranges(const PlotArea& a, std::span<const double> x,
                                       std::span<const double> y);
// column_ranges of the mean (y1 + y2) / 2 (a pair's common mode), without forming it whole: block
// by block, each block's ranges from its first sample to the next block's first (so the line
// stays joined), merged. A long record's mean would be one more column of its size (124 MB at
// 15 million rows).
std::vector<ColumnRange> mean_column_ranges(const PlotArea& a, std::span<const double> x,
                                            std::span<const double> y1, std::span<const double> y2);

}  // namespace isolink::reports
