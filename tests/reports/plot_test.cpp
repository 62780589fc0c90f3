#include "reports/plot.h"

#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "fixtures.h"

namespace isolink::reports {
namespace {

using fixtures::read_png;
using fixtures::temp_dir;

Canvas canvas(int w, int h) {
  StatusOr<Canvas> c = Canvas::create(w, h);
  if (!c.ok()) {
    ADD_FAILURE() << c.status().message();
    std::abort();
  }
  return std::move(*c);
}

bool same(Color a, Color b) {
  return std::lround(a.r * 255) == std::lround(b.r * 255) &&
         std::lround(a.g * 255) == std::lround(b.g * 255) &&
         std::lround(a.b * 255) == std::lround(b.b * 255);
}
bool white(Color a) {
  return same(a, kWhite);
}

TEST(PlotArea, MapsDataOntoPixelsWithYUp) {
  const PlotArea a = PlotArea::make({100, 50, 1100, 550}, 0, 1e-6, -2, 2);
  EXPECT_DOUBLE_EQ(a.px(0), 100);
  EXPECT_DOUBLE_EQ(a.px(1e-6), 1100);
  EXPECT_DOUBLE_EQ(a.px(0.5e-6), 600);
  EXPECT_DOUBLE_EQ(a.py(-2), 550);
  EXPECT_DOUBLE_EQ(a.py(2), 50);
  EXPECT_EQ(a.row(0), 300);
  EXPECT_EQ(a.row(1.2), 150);  // 550 - 3.2 / 4 * 500
  EXPECT_EQ(a.col(0.25e-6), 350);
  EXPECT_DOUBLE_EQ(a.x.from_px(600), 0.5e-6);
  EXPECT_DOUBLE_EQ(a.y.per_px(), 4.0 / 500);
  const Rect r = a.data_rect(0.25e-6, 0.5e-6, -3, 1);  // clipped at the bottom
  EXPECT_EQ(r.x0, 350);
  EXPECT_EQ(r.x1, 600);
  EXPECT_EQ(r.y0, 175);
  EXPECT_EQ(r.y1, 550);
}

TEST(Ticks, NiceStepsAndValues) {
  EXPECT_DOUBLE_EQ(nice_step(625e-9, 8), 100e-9);
  EXPECT_DOUBLE_EQ(nice_step(6, 12), 0.5);
  EXPECT_DOUBLE_EQ(nice_step(10, 4), 2.5);
  EXPECT_DOUBLE_EQ(nice_step(62e-6, 10), 10e-6);
  const std::vector<double> v = tick_values(-62.5e-9, 562.5e-9, 100e-9);
  ASSERT_EQ(v.size(), 6u);
  EXPECT_DOUBLE_EQ(v[0], 0);
  EXPECT_NEAR(v[5], 500e-9, 1e-18);
  const std::vector<double> s = tick_values(-3, 3, 0.5);
  ASSERT_EQ(s.size(), 13u);
  EXPECT_DOUBLE_EQ(s.front(), -3);
  EXPECT_DOUBLE_EQ(s.back(), 3);
}

TEST(Ticks, UnitsAndLabels) {
  const UnitScale ns = si_scale(562.5e-9, "s");
  EXPECT_EQ(ns.unit, "ns");
  EXPECT_DOUBLE_EQ(ns.factor, 1e9);
  EXPECT_EQ(si_scale(400e-6, "s").unit, "us");
  EXPECT_EQ(si_scale(2.25e-6, "s").unit, "us");
  EXPECT_EQ(si_scale(3, "V").unit, "V");
  EXPECT_EQ(si_scale(0.05, "V").unit, "mV");
  EXPECT_EQ(si_scale(0, "V").factor, 1);
  EXPECT_EQ(tick_label(250e-9, 100e-9, ns), "250");
  EXPECT_EQ(tick_label(1.5, 0.5, {1, "V"}), "1.5");
  EXPECT_EQ(tick_label(-1, 0.5, {1, "V"}), "-1.0");
  EXPECT_EQ(tick_label(1e-12, 0.25, {1, "V"}), "0.00");  // no "-0.00"
  EXPECT_EQ(tick_label(-1e-12, 0.25, {1, "V"}), "0.00");
  const AxisTicks t = make_ticks(Axis{-62.5e-9, 562.5e-9, 0, 1000}, ns, 8);
  ASSERT_EQ(t.ticks.size(), 6u);
  EXPECT_EQ(t.ticks[3].label, "300");
}

TEST(Text, AsciiSpellings) {
  EXPECT_EQ(ascii_text("1 \xC2\xB5s \xC2\xB1 2 \xE2\x89\xA5 3 \xE2\x86\x92 x"),
            "1 us +/- 2 >= 3 -> x");
  EXPECT_EQ(ascii_text("a\xE2\x80\x93"
                       "b \xE2\x89\xA4 c"),
            "a-b <= c");
  EXPECT_EQ(ascii_text("\xE4\xB8\xAD!"), "?!");  // anything else: one '?' per character
  EXPECT_EQ(ascii_text("tab\there"), "tab here");
}

TEST(Fonts, FoundInTheStandardPlaces) {
  StatusOr<Fonts> f = find_fonts();
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_TRUE(std::filesystem::exists(f->sans));
  EXPECT_TRUE(std::filesystem::exists(f->bold));
  EXPECT_TRUE(std::filesystem::exists(f->mono));
  EXPECT_NE(f->sans.find("DejaVuSans.ttf"), std::string::npos);
}

TEST(Fonts, EnvironmentDirectoryIsSearchedFirst) {
  ::setenv("ISOLINK_FONT_DIR", "/nonexistent/isolink-fonts", 1);
  const std::vector<std::string> d = font_search_dirs();
  ::unsetenv("ISOLINK_FONT_DIR");
  ASSERT_FALSE(d.empty());
  EXPECT_EQ(d.front(), "/nonexistent/isolink-fonts");
  EXPECT_NE(std::find(d.begin(), d.end(), "/usr/share/fonts/truetype/dejavu"), d.end());
}

TEST(Fonts, MissingFontsNameEveryPlaceLookedIn) {
  StatusOr<Fonts> f = find_fonts_in({"/nonexistent/a", "/nonexistent/b"});
  ASSERT_FALSE(f.ok());
  const std::string& m = f.status().message();
  EXPECT_NE(m.find("DejaVuSans.ttf"), std::string::npos) << m;
  EXPECT_NE(m.find("/nonexistent/a"), std::string::npos) << m;
  EXPECT_NE(m.find("/nonexistent/b/dejavu"), std::string::npos) << m;
  EXPECT_NE(m.find("ISOLINK_FONT_DIR"), std::string::npos) << m;
}

TEST(Canvas, StartsWhiteAndBlends) {
  Canvas c = canvas(200, 100);
  EXPECT_TRUE(white(c.pixel(0, 0)));
  EXPECT_TRUE(white(c.pixel(199, 99)));
  c.fill_rect({10, 10, 20, 20}, Color{0, 0, 0, 0.5f});
  EXPECT_NEAR(c.pixel(15, 15).r * 255, 128, 0.5);
  EXPECT_TRUE(white(c.pixel(20, 15)));   // x1 is exclusive
  c.fill_rect({-50, -50, 5, 5}, kFail);  // clipped
  EXPECT_TRUE(same(c.pixel(0, 0), kFail));
}

TEST(Canvas, HorizontalAndVerticalLinesLandOnTheirRow) {
  Canvas c = canvas(200, 100);
  c.hline(40.7, 10, 190, {.color = kThreshold, .width = 1});
  for (int x = 10; x < 190; ++x) ASSERT_TRUE(same(c.pixel(x, 40), kThreshold)) << x;
  EXPECT_TRUE(white(c.pixel(9, 40)));
  EXPECT_TRUE(white(c.pixel(190, 40)));
  EXPECT_TRUE(white(c.pixel(50, 39)));
  EXPECT_TRUE(white(c.pixel(50, 41)));
  c.hline(70, 10, 190, {.color = kInk, .width = 3});  // odd widths are centred
  EXPECT_TRUE(same(c.pixel(50, 69), kInk));
  EXPECT_TRUE(same(c.pixel(50, 71), kInk));
  EXPECT_TRUE(white(c.pixel(50, 72)));
  c.vline(120.2, 0, 100, {.color = kTrace, .width = 1, .dash = 5, .gap = 5});
  int on = 0;
  for (int y = 0; y < 100; ++y) on += same(c.pixel(120, y), kTrace) ? 1 : 0;
  EXPECT_GE(on, 45);
  EXPECT_LE(on, 55);
}

TEST(Canvas, AntiAliasedLinesHaveNoGaps) {
  Canvas c = canvas(200, 200);
  c.line(10, 10, 190, 150, {.color = kInk, .width = 2});
  for (int x = 12; x < 188; ++x) {
    bool dark = false;
    for (int y = 0; y < 200; ++y) dark = dark || c.pixel(x, y).r < 0.5f;
    ASSERT_TRUE(dark) << "column " << x;
  }
  EXPECT_TRUE(white(c.pixel(100, 20)));
  c.line(50, 5, 60, 195, {.color = kInk, .width = 2});  // steep
  for (int y = 8; y < 192; ++y) {
    bool dark = false;
    for (int x = 40; x < 70; ++x) dark = dark || c.pixel(x, y).r < 0.5f;
    ASSERT_TRUE(dark) << "row " << y;
  }
}

TEST(ColumnRanges, CoverTheSamplesAndConnectNeighbours) {
  const PlotArea a = PlotArea::make({0, 0, 100, 100}, 0, 1, 0, 1);
  const std::vector<double> x{0, 0.25, 0.5, 0.75, 1}, y{0, 0.25, 0.5, 0.75, 1};
  const std::vector<ColumnRange> r = column_ranges(a, x, y);
  ASSERT_EQ(r.size(), 100u);
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(r[i].valid);
    EXPECT_NEAR(r[i].lo, i / 100.0, 1e-12);
    EXPECT_NEAR(r[i].hi, (i + 1) / 100.0, 1e-12);
  }
  // A one-sample spike inside a column shows in that column's range.
  std::vector<double> xs, ys;
  for (int i = 0; i <= 100000; ++i) {
    xs.push_back(i / 100000.0);
    ys.push_back(i == 43217 ? 5.0 : 0.0);
  }
  const std::vector<ColumnRange> s = column_ranges(a, xs, ys);
  EXPECT_DOUBLE_EQ(s[43].hi, 5.0);
  EXPECT_DOUBLE_EQ(s[42].hi, 0.0);
  EXPECT_DOUBLE_EQ(s[44].hi, 0.0);
}

// The common mode's ranges block by block (mean_column_ranges) against column_ranges of the mean
// formed whole: 300,001 samples are four blocks of 65,536 and a remainder. Where two blocks meet
// (sample 65,536) the samples jump 0.1 s, 64 columns: those columns hold only the line between
// the two blocks, and a spike sits on the meeting sample.
TEST(ColumnRanges, MeanByBlocksMatchesTheMeanFormedWhole) {
  const PlotArea a = PlotArea::make({0, 0, 640, 100}, 0, 1, -2, 2);
  std::vector<double> x, p, n, mean;
  for (int i = 0; i <= 300000; ++i) {
    x.push_back(0.9 * i / 300000.0 + (i >= 65536 ? 0.1 : 0.0));
    p.push_back(std::sin(0.001 * i) + (i == 65536 ? 3.0 : 0.0));
    n.push_back(0.5 * std::cos(0.0037 * i));
    mean.push_back(0.5 * (p.back() + n.back()));
  }
  const std::vector<ColumnRange> whole = column_ranges(a, x, mean);
  const std::vector<ColumnRange> blocks = mean_column_ranges(a, x, p, n);
  ASSERT_EQ(blocks.size(), whole.size());
  for (size_t k = 0; k < whole.size(); ++k) {
    ASSERT_TRUE(whole[k].valid) << k;
    ASSERT_TRUE(blocks[k].valid) << k;
    EXPECT_DOUBLE_EQ(blocks[k].lo, whole[k].lo) << k;
    EXPECT_DOUBLE_EQ(blocks[k].hi, whole[k].hi) << k;
  }
  // The jump: from x = 0.9 * 65535 / 300000 = 0.196605 (column 125) to 0.296608 (column 189); the
  // columns between hold the straight line up to the spike's mean.
  const double spike = 0.5 * (std::sin(65.536) + 3.0 + 0.5 * std::cos(0.0037 * 65536));
  EXPECT_NEAR(blocks[189].hi, spike, 1e-12);
  EXPECT_GT(blocks[160].hi, 0.5);
  EXPECT_LT(blocks[160].hi, spike);
}

TEST(Canvas, SeriesDrawsAnEnvelopePerColumn) {
  Canvas c = canvas(300, 200);
  const PlotArea a = PlotArea::make({0, 0, 300, 200}, 0, 1, -1, 1);
  std::vector<double> x, y;
  for (int i = 0; i <= 30000; ++i) {  // 100 samples per column, one period per column
    x.push_back(i / 30000.0);
    y.push_back(0.8 * std::sin(2 * 3.141592653589793 * 300 * x.back()));
  }
  c.series(a, x, y, {.color = kTrace, .width = 2});
  // Each column spans a whole period: its span reaches both peaks (160 of 200 rows).
  for (int col = 10; col < 290; col += 7) {
    int dark = 0;
    for (int row = 0; row < 200; ++row) dark += same(c.pixel(col, row), kTrace) ? 1 : 0;
    EXPECT_GE(dark, 150) << col;
  }
}

TEST(Canvas, TextIsDrawnAndMeasured) {
  Canvas c = canvas(400, 200);
  const Rect b = c.text(20, 50, "Hg 250 ns", 24, kInk);
  EXPECT_FALSE(b.empty());
  int dark = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 200; ++x) dark += c.pixel(x, y).r < 0.5f ? 1 : 0;
  EXPECT_GT(dark, 100);
  EXPECT_GT(c.measure("WWWW", 20).width, c.measure("iiii", 20).width);
  EXPECT_GT(c.measure("x", 20).ascent, 10);
  const Rect v = c.text(300, 100, "vertical text", 20, kInk, FontFace::kSans, HAlign::kCenter,
                        VAlign::kCenter, true);
  EXPECT_GT(v.height(), 2 * v.width());
  EXPECT_NEAR((v.y0 + v.y1) / 2.0, 100, 2);
}

TEST(Layout, SpreadLabelsKeepsOrderAndGap) {
  const std::vector<double> s = spread_labels({110, 100, 105}, 20, 0, 1000);
  EXPECT_DOUBLE_EQ(s[1], 85);
  EXPECT_DOUBLE_EQ(s[2], 105);
  EXPECT_DOUBLE_EQ(s[0], 125);
  const std::vector<double> far = spread_labels({10, 500}, 20, 0, 1000);
  EXPECT_DOUBLE_EQ(far[0], 10);
  EXPECT_DOUBLE_EQ(far[1], 500);
  const std::vector<double> edge = spread_labels({2, 3}, 20, 10, 1000);
  EXPECT_DOUBLE_EQ(edge[0], 10);
  EXPECT_DOUBLE_EQ(edge[1], 30);
}

TEST(ColorMap, ViridisAndInfernoAreTheirPublishedEnds) {
  const ColorMap& v = ColorMap::viridis();
  EXPECT_EQ(v.table().size(), 256u);
  // matplotlib: viridis[0] = (0.267, 0.005, 0.329), viridis[255] = (0.993, 0.906, 0.144).
  EXPECT_NEAR(v.at(0).r, 0.267, 0.015);
  EXPECT_NEAR(v.at(0).g, 0.005, 0.015);
  EXPECT_NEAR(v.at(0).b, 0.329, 0.015);
  EXPECT_NEAR(v.at(1).r, 0.993, 0.015);
  EXPECT_NEAR(v.at(1).g, 0.906, 0.015);
  EXPECT_NEAR(v.at(1).b, 0.144, 0.015);
  EXPECT_NEAR(v.at(0.5).g, 0.565, 0.015);  // viridis[128] = (0.128, 0.567, 0.551)
  const ColorMap& f = ColorMap::inferno();
  EXPECT_NEAR(f.at(0).r, 0.0015, 0.02);
  EXPECT_NEAR(f.at(1).b, 0.645, 0.02);
  // Perceptually ordered: lightness grows along both maps.
  for (const ColorMap* m : {&v, &f}) {
    double last = -1;
    for (int i = 0; i < 256; i += 5) {
      const Color c = m->table()[static_cast<size_t>(i)];
      const double l = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
      EXPECT_GT(l, last - 1e-3) << i;
      last = l;
    }
  }
}

TEST(ColorMap, LogScale) {
  const LogScale s{100};
  EXPECT_DOUBLE_EQ(s.norm(1), 0);
  EXPECT_DOUBLE_EQ(s.norm(10), 0.5);
  EXPECT_DOUBLE_EQ(s.norm(100), 1);
  EXPECT_DOUBLE_EQ(s.norm(1000), 1);
  EXPECT_DOUBLE_EQ(LogScale{1}.norm(1), 1);
}

TEST(Cells, FillCellsMapsCellZeroToTheLowerLeft) {
  Canvas c = canvas(60, 40);
  const PlotArea a = PlotArea::make({10, 10, 50, 30}, 0, 4, 0, 2);
  fill_cells(c, a, 4, 2, [](int ix, int iy) -> std::optional<Color> {
    if (ix == 0 && iy == 0) return kFail;
    if (ix == 3 && iy == 1) return kPass;
    return std::nullopt;
  });
  EXPECT_TRUE(same(c.pixel(10, 29), kFail));  // lower left
  EXPECT_TRUE(same(c.pixel(19, 20), kFail));
  EXPECT_TRUE(white(c.pixel(20, 29)));
  EXPECT_TRUE(same(c.pixel(49, 10), kPass));  // upper right
  EXPECT_TRUE(white(c.pixel(49, 20)));
}

// z = x - y over 10 x 10 cells: the zero contour is the diagonal x = y.
TEST(Contour, MarchingSquaresFollowsTheLevel) {
  const PlotArea a = PlotArea::make({0, 0, 100, 100}, 0, 10, 0, 10);
  std::vector<double> z;
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) z.push_back((i + 0.5) - (j + 0.5) + 0.25);
  const std::vector<ContourSegment> segs = contour_segments(a, z, 10, 10, 0.0);
  ASSERT_FALSE(segs.empty());
  for (const ContourSegment& g : segs) {
    EXPECT_NEAR(g.x0 - g.y0, -0.25, 1e-12);
    EXPECT_NEAR(g.x1 - g.y1, -0.25, 1e-12);
  }
  double len = 0;
  for (const ContourSegment& g : segs) len += std::hypot(g.x1 - g.x0, g.y1 - g.y0);
  EXPECT_NEAR(len, std::sqrt(2.0) * 9, 0.5);  // centre (0.5) to centre (9.5) along the diagonal
  Canvas c = canvas(100, 100);
  draw_contour(c, a, segs, {.color = kInk, .width = 2});
  EXPECT_LT(c.pixel(a.col(5.25), a.row(5.5)).r, 0.5f);
  EXPECT_TRUE(white(c.pixel(a.col(2), a.row(8))));
  EXPECT_TRUE(contour_segments(a, z, 10, 10, 100.0).empty());
}

TEST(Axes, TicksLabelsAndTitlesAroundThePlot) {
  Canvas c = canvas(800, 500);
  const PlotArea a = PlotArea::make({120, 40, 760, 400}, 0, 500e-9, -3, 3);
  const AxisTicks xt = make_ticks(a.x, si_scale(500e-9, "s"));
  const AxisTicks yt = make_ticks(a.y, {1, "V"}, 12);
  draw_grid(c, a, xt, yt);
  draw_axes(c, a, xt, yt, "time", "voltage");
  // Frame one pixel outside the area; labels below and left of it.
  EXPECT_TRUE(same(c.pixel(300, 39), kInk));
  EXPECT_TRUE(same(c.pixel(300, 400), kInk));
  int below = 0, left = 0;
  for (int y = 405; y < 500; ++y)
    for (int x = 0; x < 800; ++x) below += c.pixel(x, y).r < 0.5f ? 1 : 0;
  for (int y = 40; y < 400; ++y)
    for (int x = 0; x < 115; ++x) left += c.pixel(x, y).r < 0.5f ? 1 : 0;
  EXPECT_GT(below, 300);
  EXPECT_GT(left, 300);
  // A gridline at 0 V.
  EXPECT_TRUE(same(c.pixel(300, a.row(0)), kGrid));
}

TEST(Legend, SizeFitsItsLabels) {
  Canvas c = canvas(600, 300);
  const std::vector<LegendEntry> e{{"P", {.color = kSeriesP}},
                                   {"a much longer label", {.color = kSeriesN}},
                                   {"box", {.color = kPass}, true}};
  const Rect s = legend_size(c, e, 18);
  EXPECT_GT(s.width(), c.measure("a much longer label", 18).width);
  const Rect b = draw_legend(c, 100, 50, e, 18);
  EXPECT_EQ(b.width(), s.width());
  EXPECT_EQ(b.height(), s.height());
  int green = 0;
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) green += same(c.pixel(x, y), kPass) ? 1 : 0;
  EXPECT_GT(green, 200);  // the box swatch
}

TEST(Png, WritesThroughATempFileAndReadsBack) {
  const std::string dir = temp_dir("plot_png");
  Canvas c = canvas(64, 32);
  c.fill_rect({0, 0, 32, 32}, kFail);
  const std::string path = dir + "/out.png";
  Status s = c.write_png(path);
  ASSERT_TRUE(s.ok()) << s.message();
  for (const auto& e : std::filesystem::directory_iterator(dir))  // no temporary file left
    EXPECT_EQ(e.path().filename(), "out.png");
  const fixtures::Png p = read_png(path);
  ASSERT_EQ(p.width, 64);
  ASSERT_EQ(p.height, 32);
  EXPECT_TRUE(p.is(10, 10, 0xE00000));
  EXPECT_TRUE(p.is(40, 10, 0xFFFFFF));
}

// OpenImageIO reports success when the disk fills up under it (issue 15): the PNG is encoded in
// memory and written with a checked write, so a full disk is an error and leaves no file.
TEST(Png, FullDiskIsAnErrorAndLeavesNoFile) {
  const std::string dir = temp_dir("plot_png_full") + "/mnt";
  std::filesystem::create_directories(dir);
  if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=8k") != 0)
    GTEST_SKIP() << "mounting a small tmpfs needs root (CAP_SYS_ADMIN): " << std::strerror(errno);
  Canvas c = canvas(400, 300);
  unsigned lcg = 1;  // noise, so the PNG cannot compress below the disk's size
  for (int y = 0; y < 300; y += 2)
    for (int x = 0; x < 400; x += 2) {
      lcg = lcg * 1664525u + 1013904223u;
      c.fill_rect({x, y, x + 2, y + 2}, (lcg >> 28) & 1 ? kFail : kPass);
    }
  Status s = c.write_png(dir + "/eye.png");
  const bool left = std::filesystem::exists(dir + "/eye.png") || !std::filesystem::is_empty(dir);
  ::umount(dir.c_str());
  ASSERT_FALSE(s.ok()) << "an 8 KiB disk took the PNG";
  EXPECT_NE(s.message().find("eye.png: error: cannot write: No space left on device"),
            std::string::npos)
      << s.message();
  EXPECT_FALSE(left);
}

TEST(Png, ErrorNamesThePath) {
  Canvas c = canvas(8, 8);
  const std::string path = "/nonexistent-dir-isolink/x/eye.png";
  Status s = c.write_png(path);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
}

}  // namespace
}  // namespace isolink::reports
