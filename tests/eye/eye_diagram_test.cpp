#include "eye/eye_diagram.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "synth.h"

namespace isolink::eye {
namespace {

constexpr double ns = 1e-9;

Rules rules(const char* name = "bq7961x") {
  StatusOr<Rules> r = load_rules(name);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return *r;
}

// 100 x 100 cells over 0..100 ns and -1..1 V: one cell is 1 ns x 20 mV.
EyeGrid square_grid() {
  EyeGrid g;
  g.t_lo = 0;
  g.t_hi = 100 * ns;
  g.v_lo = -1;
  g.v_hi = 1;
  g.period = 100 * ns;
  g.nx = 100;
  g.ny = 100;
  return g;
}

TEST(EyeGrid, ForRulesSpansQuarterBeforeToTwoAndAQuarterPeriodsAfter) {
  const EyeGrid d = EyeGrid::for_rules(rules(), 1000, 500, -3, 3);
  EXPECT_DOUBLE_EQ(d.period, 250 * ns);
  EXPECT_DOUBLE_EQ(d.t_lo, -62.5 * ns);
  EXPECT_DOUBLE_EQ(d.t_hi, 562.5 * ns);
  EXPECT_DOUBLE_EQ(d.dt_per_px(), 0.625 * ns);
  EXPECT_DOUBLE_EQ(d.dv_per_px(), 0.012);
  const EyeGrid t = EyeGrid::for_rules(rules("tone"), 1000, 500, -3, 3);
  EXPECT_DOUBLE_EQ(t.period, 1e-6);
  EXPECT_DOUBLE_EQ(t.t_lo, -0.25e-6);
  EXPECT_DOUBLE_EQ(t.t_hi, 2.25e-6);
}

TEST(EyeHistogram, MappingPutsValuesInTheirCells) {
  EyeHistogram h(square_grid());
  EXPECT_EQ(h.column_of(0), 0);
  EXPECT_EQ(h.column_of(99.5 * ns), 99);
  EXPECT_EQ(h.column_of(-0.5 * ns), -1);
  EXPECT_EQ(h.row_of(-1), 0);
  EXPECT_EQ(h.row_of(0), 50);
  EXPECT_EQ(h.row_of(0.999), 99);
  EXPECT_EQ(h.row_of(1.0), 100);  // the top edge is outside
}

// A diagonal across the grid is 100 px long in x and in y: 100 steps, one per diagonal cell.
TEST(EyeHistogram, DiagonalHitsEachDiagonalCellOnce) {
  EyeHistogram h(square_grid());
  const std::vector<double> t{0, 100 * ns}, v{-1, 1};
  h.add_window(t, v, 0);
  EXPECT_EQ(h.windows(), 1u);
  EXPECT_EQ(h.total(), 100u);
  EXPECT_EQ(h.outside(), 0u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(h.count(i, i), 1u) << i;
  EXPECT_EQ(h.max_count(), 1u);
}

// The same line sampled at 37 irregular points gives the same counts: the step phase carries
// across samples, so the solver's time step does not weigh the density.
TEST(EyeHistogram, CountsDoNotDependOnTheSampling) {
  EyeHistogram a(square_grid()), b(square_grid());
  const std::vector<double> t2{0, 100 * ns}, v2{-1, 1};
  a.add_window(t2, v2, 0);
  std::vector<double> t{0}, v{-1};
  double x = 0;
  for (int i = 1; i < 37; ++i) {
    x += (1.0 + (i * 7919 % 13)) * ns / 2.7;  // uneven steps
    if (x >= 100 * ns) break;
    t.push_back(x);
    v.push_back(-1 + 2 * x / (100 * ns));
  }
  t.push_back(100 * ns);
  v.push_back(1);
  b.add_window(t, v, 0);
  EXPECT_EQ(a.total(), b.total());
  EXPECT_EQ(a.counts(), b.counts());
}

// Flat 45 ns, edge -1 -> +1 V in 10 ns, flat 45 ns: 45 + 100 + 45 steps, every row of the edge
// hit (no holes on a steep edge) and every column hit once on the flats.
TEST(EyeHistogram, SteepEdgeHasNoHoles) {
  EyeHistogram h(square_grid());
  const std::vector<double> t{0, 45 * ns, 55 * ns, 100 * ns}, v{-0.99, -0.99, 0.99, 0.99};
  h.add_window(t, v, 0);
  // dy of the edge is 1.98 V = 99 rows; the flats are 45 columns each.
  EXPECT_EQ(h.total(), 45u + 99u + 45u);
  for (int row = h.row_of(-0.99); row <= h.row_of(0.98); ++row) {
    uint32_t in_row = 0;
    for (int col = 0; col < 100; ++col) in_row += h.count(col, row);
    EXPECT_GE(in_row, 1u) << "row " << row;
  }
  for (int col = 0; col < 100; ++col) {
    uint32_t in_col = 0;
    for (int row = 0; row < 100; ++row) in_col += h.count(col, row);
    EXPECT_GE(in_col, 1u) << "column " << col;
  }
}

TEST(EyeHistogram, FlatLevelLandsInOneRow) {
  EyeHistogram h(square_grid());
  std::vector<double> t, v;
  for (int i = 0; i <= 400; ++i) {  // 0..400 ns, a window in the middle
    t.push_back(i * ns);
    v.push_back(0.5);
  }
  h.add_window(t, v, 150 * ns);
  const int row = h.row_of(0.5);
  EXPECT_EQ(row, 75);
  EXPECT_EQ(h.total(), 100u);
  for (int col = 0; col < 100; ++col) {
    EXPECT_EQ(h.count(col, row), 1u) << col;
    for (int r = 0; r < 100; ++r)
      if (r != row) {
        ASSERT_EQ(h.count(col, r), 0u) << col << "," << r;
      }
  }
}

TEST(EyeHistogram, LevelsOutsideTheRangeAreCountedApart) {
  EyeHistogram h(square_grid());
  const std::vector<double> t{0, 100 * ns}, v{1.5, 1.5};
  h.add_window(t, v, 0);
  EXPECT_EQ(h.total(), 0u);
  EXPECT_EQ(h.outside(), 100u);
}

TEST(EyeHistogram, WindowsAreClippedToTheRecord) {
  EyeHistogram h(square_grid());
  const std::vector<double> t{0, 50 * ns}, v{0, 0};
  h.add_window(t, v, 0);  // the record ends half way through the window
  EXPECT_EQ(h.total(), 50u);
  h.add_window(t, v, 60 * ns);  // starts after the record: nothing
  EXPECT_EQ(h.windows(), 1u);
}

TEST(FoldOrigins, EveryPeriodOfEveryFrameFromThePreamble) {
  const Rules r = rules();
  Waveform w = synth::ideal_frames({0x80, 0x5A}, FrameFormat{});
  StatusOr<CheckResult> c = check_waveform(w, r);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE(c->pass);
  ASSERT_EQ(c->frames.size(), 2u);
  const std::vector<double> o = fold_origins(*c, r.pulse_time);
  // 26 half bits per frame: origins at the preamble crossing a and every T up to the postamble.
  ASSERT_EQ(o.size(), 52u);
  EXPECT_DOUBLE_EQ(o[0], c->frames[0].start);
  EXPECT_NEAR(o[0], 1e-6 + 6 * ns, 0.01 * ns);
  EXPECT_NEAR(o[25] - o[0], 25 * 250 * ns, 1e-15);
  EXPECT_DOUBLE_EQ(o[26], c->frames[1].start);
}

TEST(EyeHistogram, AccumulateFoldsFramesWithoutGaps) {
  const Rules r = rules();
  Waveform w = synth::ideal_frames({0x80, 0x5A, 0xC3}, FrameFormat{});
  StatusOr<CheckResult> c = check_waveform(w, r);
  ASSERT_TRUE(c.ok());
  EyeHistogram h(EyeGrid::for_rules(r, 500, 300, -3, 3));
  const size_t n = h.accumulate(w.time, w.columns[0], *c);
  EXPECT_EQ(n, 78u);
  EXPECT_EQ(h.windows(), 78u);
  EXPECT_EQ(h.outside(), 0u);
  // Every column of every window is crossed once at least: no empty column.
  for (int col = 0; col < 500; ++col) {
    uint64_t in_col = 0;
    for (int row = 0; row < 300; ++row) in_col += h.count(col, row);
    EXPECT_GE(in_col, 78u) << "column " << col;
  }
  // At t = 0 every window sits on an edge crossing +1.2 V or -1.2 V, or inside a double pulse:
  // the edges (0.2 V/ns) pass 0.9..1.5 V within the columns next to t = 0.
  const int c0 = h.column_of(0.0);
  uint32_t near_pos = 0, near_neg = 0;
  for (int col = c0 - 1; col <= c0 + 1; ++col) {
    for (int row = h.row_of(0.9); row <= h.row_of(1.5); ++row) near_pos += h.count(col, row);
    for (int row = h.row_of(-1.5); row <= h.row_of(-0.9); ++row) near_neg += h.count(col, row);
  }
  EXPECT_GT(near_pos, 0u);
  EXPECT_GT(near_neg, 0u);
  // The flat tops at +/-2 V are the densest rows.
  uint64_t top = 0, mid = 0;
  for (int col = 0; col < 500; ++col) {
    top += h.count(col, h.row_of(2.0));
    mid += h.count(col, h.row_of(0.6));
  }
  EXPECT_GT(top, 10 * mid);
}

TEST(EyeHistogram, SampleStepBarelyChangesTheTotal) {
  const Rules r = rules();
  Waveform w1 = synth::ideal_frames({0xA5}, FrameFormat{}, 2e-6, 1 * ns);
  Waveform w4 = synth::ideal_frames({0xA5}, FrameFormat{}, 2e-6, 0.25 * ns);
  StatusOr<CheckResult> c1 = check_waveform(w1, r), c4 = check_waveform(w4, r);
  ASSERT_TRUE(c1.ok() && c4.ok());
  EyeHistogram h1(EyeGrid::for_rules(r, 400, 200, -3, 3));
  EyeHistogram h4(EyeGrid::for_rules(r, 400, 200, -3, 3));
  h1.accumulate(w1.time, w1.columns[0], *c1);
  h4.accumulate(w4.time, w4.columns[0], *c4);
  ASSERT_EQ(h1.windows(), h4.windows());
  const double diff = std::abs(static_cast<double>(h1.total()) - static_cast<double>(h4.total()));
  EXPECT_LE(diff, 2.0 * static_cast<double>(h1.windows()));  // a step or two per window
}

}  // namespace
}  // namespace isolink::eye
