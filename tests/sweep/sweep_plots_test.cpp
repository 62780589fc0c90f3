// The sweep charts, read back with OpenImageIO: size, content, and the limit line / boundary
// pixels where the layouts' mappings put them.
#include "reports/sweep_plots.h"

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace isolink::reports {
namespace {

struct Png {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> px;
  const uint8_t* at(int x, int y) const {
    return &px[(static_cast<size_t>(y) * width + x) * channels];
  }
  bool is(int x, int y, Color c, int tol = 2) const {
    const uint8_t* p = at(x, y);
    return std::abs(p[0] - std::lround(c.r * 255)) <= tol &&
           std::abs(p[1] - std::lround(c.g * 255)) <= tol &&
           std::abs(p[2] - std::lround(c.b * 255)) <= tol;
  }
  size_t count(Color c, Rect r) const {
    size_t n = 0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) n += is(x, y, c);
    return n;
  }
};

Png read_png(const std::string& path) {
  Png out;
  OIIO::ImageBuf in(path);
  if (!in.read(0, 0, true, OIIO::TypeDesc::UINT8)) {
    ADD_FAILURE() << "cannot read " << path << ": " << in.geterror();
    return out;
  }
  const OIIO::ImageSpec& s = in.spec();
  out.width = s.width;
  out.height = s.height;
  out.channels = s.nchannels;
  out.px.resize(static_cast<size_t>(s.width) * s.height * s.nchannels);
  in.get_pixels(OIIO::ROI(0, s.width, 0, s.height, 0, 1, 0, s.nchannels), OIIO::TypeDesc::UINT8,
                out.px.data());
  return out;
}

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "isolink_sweep_plots_" + name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// Length 1..40 m (log) x two isolation variants: cap passes up to 10 m, transformer up to 20 m;
// margins fall linearly in log(length).
SweepPlotData length_by_isolation() {
  SweepPlotData d;
  d.title = "test";
  d.source = "sweep.yaml";
  SweepPlotAxis len{.name = "cable.length",
                    .unit = "m",
                    .labels = {"1", "2", "5", "10", "20", "40"},
                    .values = {1, 2, 5, 10, 20, 40},
                    .log = true};
  SweepPlotAxis iso{.name = "isolation", .labels = {"cap", "transformer"}};
  d.axes = {len, iso};
  for (size_t i = 0; i < 6; ++i)
    for (size_t k = 0; k < 2; ++k) {
      const double limit = k == 0 ? 14.0 : 28.0;  // the margin crosses 0 here
      const double m = 0.2 * std::log10(limit / len.values[i]);
      d.points.push_back({{i, k}, m, m >= 0 ? "pass" : "fail", m >= 0 ? "" : "vstart"});
    }
  return d;
}

TEST(SweepPlots, MarginChartHasTheLimitLineAndPassShading) {
  const SweepPlotData d = length_by_isolation();
  const std::string path = temp_dir("margin") + "/sweep_margin.png";
  ASSERT_TRUE(render_margin_png(d, path).ok());
  const Png img = read_png(path);
  ASSERT_EQ(img.width, kSweepPlotWidth);
  ASSERT_EQ(img.height, kSweepPlotHeight);
  EXPECT_GE(img.width, 1600);
  EXPECT_GE(img.height, 1000);
  const MarginLayout L = margin_layout(d);
  const PlotArea& a = L.plot;
  // Margins span -0.09..+0.26: the y range holds them and 0.
  EXPECT_LT(L.y_lo, -9.0);
  EXPECT_GT(L.y_hi, 26.0);
  // The 0 % line (3 px, magenta) across the plot, away from labels and markers.
  const int row = a.row(0.0);
  size_t on_line = 0;
  for (int x = a.rect.x0 + 400; x < a.rect.x1 - 10; x += 7) on_line += img.is(x, row, kLimitLine);
  EXPECT_GT(on_line, 80u) << "row " << row;
  // Shaded above the line, white below it (sampled where no series passes).
  EXPECT_TRUE(img.is(a.rect.x0 + 5, a.row(0.0) - 30, kPassShade)) << "pass side";
  EXPECT_TRUE(img.is(a.rect.x0 + 5, a.row(0.0) + 30, kWhite)) << "fail side";
  // The x mapping is log10: 10 m is the centre of 1..100 in log space.
  EXPECT_DOUBLE_EQ(margin_x(d, 3), 1.0);
  // Each series' marker at its data position.
  for (size_t k = 0; k < 2; ++k) {
    const double m = d.points[2 * 2 + k].margin;  // 5 m
    EXPECT_TRUE(img.is(static_cast<int>(a.px(margin_x(d, 2))), static_cast<int>(a.py(m)),
                       sweep_series_color(k), 40))
        << "series " << k;
  }
}

TEST(SweepPlots, HeatmapDrawsTheBoundaryBetweenPassAndFailCells) {
  const SweepPlotData d = length_by_isolation();
  const HeatmapCells h = heatmap_cells(d);
  ASSERT_EQ(h.nx, 6);
  ASSERT_EQ(h.ny, 2);
  EXPECT_EQ(h.verdict[3], "pass");      // cap, 10 m
  EXPECT_EQ(h.verdict[4], "fail");      // cap, 20 m
  EXPECT_EQ(h.verdict[6 + 4], "pass");  // transformer, 20 m
  EXPECT_EQ(h.verdict[6 + 5], "fail");  // transformer, 40 m
  const std::string path = temp_dir("heatmap") + "/sweep_heatmap.png";
  ASSERT_TRUE(render_heatmap_png(d, path).ok());
  const Png img = read_png(path);
  ASSERT_EQ(img.width, kSweepPlotWidth);
  ASSERT_EQ(img.height, kSweepPlotHeight);
  const HeatmapLayout L = heatmap_layout(d);
  const PlotArea& a = L.plot;
  // Boundary: the vertical edge x = 4 in the cap row (iy 0), x = 5 in the transformer row (iy 1),
  // and the horizontal edge y = 1 over column 4 (cap fails, transformer passes).
  auto boundary_at = [&](int x, int y) { return img.is(x, y, kBoundary, 10); };
  EXPECT_TRUE(boundary_at(a.col(4.0), a.row(0.2)));
  EXPECT_TRUE(boundary_at(a.col(5.0), a.row(1.8)));
  EXPECT_TRUE(boundary_at(a.col(4.3), a.row(1.0)));
  // No boundary between two passing cells.
  EXPECT_FALSE(boundary_at(a.col(2.0), a.row(0.2)));
  EXPECT_FALSE(boundary_at(a.col(2.2), a.row(1.0)));
  // Cell colours from the diverging map: blue where it passes, red where it fails (sampled near a
  // corner, away from text and hatching).
  EXPECT_TRUE(img.is(a.col(0.04) + 1, a.row(0.06), diverging_color(L.norm(h.margin[0])), 3));
  const Color pass_col = diverging_color(L.norm(h.margin[0]));
  EXPECT_GT(pass_col.b, pass_col.r);
  const Color fail_col = diverging_color(L.norm(h.margin[5]));
  EXPECT_GT(fail_col.r, fail_col.b);
  EXPECT_GT(img.count(fail_col, {a.col(5.0), a.row(1.0), a.col(6.0), a.row(0.0)}), 500u);
  // Margins -0.072..+0.289: the colour scale is -10 %..0..+50 %.
  EXPECT_DOUBLE_EQ(L.limit_neg, 0.1);
  EXPECT_DOUBLE_EQ(L.limit_pos, 0.5);
  EXPECT_DOUBLE_EQ(L.norm(-0.05), -0.5);
  EXPECT_DOUBLE_EQ(L.norm(0.25), 0.5);
}

TEST(SweepPlots, HistogramShowsTheLimitAndTheBars) {
  SweepPlotData d;
  d.title = "mc";
  d.samples = 200;
  for (int i = 0; i < 200; ++i) {
    const double m = -0.02 + 0.001 * (i % 100);  // -2 % .. +7.9 %
    d.points.push_back({{}, m, m >= 0 ? "pass" : "fail", ""});
  }
  const std::string path = temp_dir("hist") + "/mc_histogram.png";
  ASSERT_TRUE(render_mc_histogram_png(d, path).ok());
  const Png img = read_png(path);
  ASSERT_EQ(img.width, kSweepPlotWidth);
  const HistogramLayout L = histogram_layout(d);
  const PlotArea& a = L.plot;
  EXPECT_LE(L.x_lo, -2.0);
  EXPECT_GE(L.x_hi, 7.9);
  // Bins align on 0: the limit is a bin edge.
  EXPECT_NEAR(std::remainder(L.x_lo, L.bin), 0.0, 1e-9);
  // The limit line (magenta) at 0 %, from top to bottom.
  size_t on = 0;
  for (int y = a.rect.y0 + 60; y < a.rect.y1 - 5; y += 5) on += img.is(a.col(0.0), y, kLimitLine);
  EXPECT_GT(on, static_cast<size_t>((a.rect.height() - 65) / 5 - 2));
  // Red bars left of it, green ones right of it (at their bottom row).
  EXPECT_TRUE(img.is(a.col(-1.0 + L.bin / 2), a.rect.y1 - 2, kHistFail));
  EXPECT_TRUE(img.is(a.col(4.0 + L.bin / 2), a.rect.y1 - 2, kHistPass));
  // Each bin of 0.1 % width (when bins are 0.25 %, 2.5 points per bin x 2).
  EXPECT_GT(img.count(kHistPass, a.rect), 1000u);
}

TEST(SweepPlots, CategoricalAxesAndErrors) {
  SweepPlotData d;
  d.title = "materials";
  d.axes = {SweepPlotAxis{.name = "cable.material", .labels = {"pp", "pvc"}},
            SweepPlotAxis{.name = "cable.temperature",
                          .unit = "degC",
                          .labels = {"-40", "25", "85"},
                          .values = {-40, 25, 85}}};
  for (size_t i = 0; i < 2; ++i)
    for (size_t k = 0; k < 3; ++k) {
      const bool err = i == 1 && k == 2;
      d.points.push_back({{i, k}, err ? NAN : 0.1 - 0.05 * k * i, err ? "error" : "pass", ""});
    }
  const std::string dir = temp_dir("categorical");
  ASSERT_TRUE(render_margin_png(d, dir + "/m.png").ok());
  ASSERT_TRUE(render_heatmap_png(d, dir + "/h.png").ok());
  const MarginLayout L = margin_layout(d);
  EXPECT_DOUBLE_EQ(L.plot.x.lo, -0.5);
  EXPECT_DOUBLE_EQ(L.plot.x.hi, 1.5);
  const HeatmapCells h = heatmap_cells(d);
  EXPECT_EQ(h.verdict[2 * 2 + 1], "error");  // pvc (ix 1) at 85 degC (iy 2)
  const Png img = read_png(dir + "/h.png");
  const HeatmapLayout hl = heatmap_layout(d);
  EXPECT_TRUE(img.is(hl.plot.col(1.05), hl.plot.row(2.05), rgb(0xB8B8B8)));  // error cell grey
  // A boundary between the error cell and its passing neighbours.
  EXPECT_TRUE(img.is(hl.plot.col(1.0), hl.plot.row(2.5), kBoundary, 10));
  EXPECT_TRUE(img.is(hl.plot.col(1.5), hl.plot.row(2.0), kBoundary, 10));
}

TEST(SweepPlots, DivergingColourMap) {
  const Color w = diverging_color(0);
  EXPECT_NEAR(w.r, w.b, 1e-6);
  EXPECT_GT(w.r, 0.9f);
  EXPECT_LT(diverging_color(1).r, 0.2f);
  EXPECT_GT(diverging_color(-1).r, 0.6f);
  EXPECT_LT(diverging_color(-1).b, 0.2f);
  // Clamped.
  EXPECT_EQ(diverging_color(3).b, diverging_color(1).b);
}

}  // namespace
}  // namespace isolink::reports
