// wave.csv's rows (analysis/link_run_wave.h): the thinning against closed forms (a line, a
// parabola whose chord error is (b - a)^2 / 4), non-finite rows, and the merged axis of two
// directions.
#include "analysis/link_run_wave.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace isolink::analysis {
namespace {

// Linear interpolation of (t, v) between the kept rows, at row i.
double between_kept(const std::vector<double>& t, const std::vector<double>& v,
                    const std::vector<size_t>& keep, size_t i) {
  size_t k = 0;
  while (k + 1 < keep.size() && keep[k + 1] <= i) ++k;
  if (keep[k] == i || k + 1 == keep.size()) return v[keep[k]];
  const size_t a = keep[k], b = keep[k + 1];
  return v[a] + (t[i] - t[a]) / (t[b] - t[a]) * (v[b] - v[a]);
}

// The ladder's finest fitting tolerance by bisection: the answer of a scan from the finest, for
// every place the fitting rungs may start (none, the first, ..., the last), in at most
// ceil(log2(n + 1)) calls.
TEST(FinestFitting, FindsTheFirstFittingRungByBisection) {
  const std::vector<double> ladder{1e-3, 2e-3, 5e-3, 10e-3, 20e-3, 50e-3};
  for (size_t first = 0; first <= ladder.size(); ++first) {
    int calls = 0;
    const size_t k = finest_fitting(ladder, [&](double tol) {
      ++calls;
      return first < ladder.size() && tol >= ladder[first];
    });
    EXPECT_EQ(k, first);
    EXPECT_LE(calls, 3) << first;  // ceil(log2(7))
  }
  EXPECT_EQ(finest_fitting({}, [](double) { return true; }), 0u);
}

TEST(ThinRows, AStraightLineKeepsItsEnds) {
  std::vector<double> t, v;
  for (int i = 0; i <= 1000; ++i) t.push_back(i * 1e-9), v.push_back(0.5 + 3e6 * t.back());
  const std::vector<size_t> keep = thin_rows(t, {v}, 1e-6);
  EXPECT_EQ(keep, (std::vector<size_t>{0, 1000}));
}

// v = t^2 on [0, 1]: the chord over [a, b] is farthest from the parabola at its middle, by
// (b - a)^2 / 4. Within tol a chord spans at most 2 sqrt(tol): 0.02 for tol 1e-4, so at least 50
// chords, and the greedy choice on a 1e-4 grid loses at most one sample per chord.
TEST(ThinRows, AParabolaKeepsTheChordsItsCurvatureAllows) {
  std::vector<double> t, v;
  for (int i = 0; i <= 10000; ++i) t.push_back(i * 1e-4), v.push_back(t.back() * t.back());
  const double tol = 1e-4;
  const std::vector<size_t> keep = thin_rows(t, {v}, tol);
  EXPECT_GE(keep.size(), 51u);  // 50 chords at least: 51 rows
  EXPECT_LE(keep.size(), 53u);  // chords of 0.0199 or more: 51 of them, 52 rows, +1 for the end
  for (size_t i = 0; i < t.size(); ++i)
    ASSERT_LE(std::abs(between_kept(t, v, keep, i) - v[i]), tol * (1 + 1e-9)) << i;
  // The same parabola with a tighter second column: the kept rows satisfy both.
  std::vector<double> w(v.size());
  for (size_t i = 0; i < v.size(); ++i) w[i] = 4 * v[i];  // four times the curvature
  const std::vector<size_t> both = thin_rows(t, {v, w}, tol);
  EXPECT_GE(both.size(), 101u);  // chords at most 2 sqrt(tol / 4) = 0.01
  for (size_t i = 0; i < t.size(); ++i)
    ASSERT_LE(std::abs(between_kept(t, w, both, i) - w[i]), tol * (1 + 1e-9)) << i;
}

TEST(ThinRows, AStepKeepsBothSidesOfTheEdge) {
  // 0 V then 5 V from t = 10 on (a 1-sample edge): rows 0, 9, 10 and the last.
  std::vector<double> t, v;
  for (int i = 0; i < 20; ++i) t.push_back(i), v.push_back(i < 10 ? 0.0 : 5.0);
  EXPECT_EQ(thin_rows(t, {v}, 1e-3), (std::vector<size_t>{0, 9, 10, 19}));
}

TEST(ThinRows, NonFiniteRowsAreKeptWithTheirNeighbours) {
  std::vector<double> t{0, 1, 2, 3, 4, 5, 6}, v{0, 0, 0, std::nan(""), 0, 0, 0};
  const std::vector<size_t> keep = thin_rows(t, {v}, 1e-3);
  EXPECT_EQ(keep, (std::vector<size_t>{0, 2, 3, 4, 6}));
}

DirectionRun direction(link::Direction d, std::vector<double> t, std::vector<double> v) {
  DirectionRun r;
  r.link.direction = d;
  r.sim.wave.time = std::move(t);
  r.sim.wave.add_column("v(rxp,rxn)", std::move(v));
  return r;
}

TEST(RunWaveFile, TwoDirectionsShareTheUnionOfTheirRows) {
  LinkRun run;
  // down: a line (kept at its ends); up: a tent with its corner at 1.5.
  run.directions.push_back(direction(link::Direction::kDown, {0, 1, 2, 3}, {0, 1, 2, 3}));
  run.directions.push_back(direction(link::Direction::kUp, {0, 0.5, 1.5, 2.5, 3}, {0, 1, 3, 1, 0}));
  const Waveform w = run_wave_file(run, {.rows = WaveRows::Thinned, .tolerance = 1e-6}).wave;
  ASSERT_EQ(w.names, (std::vector<std::string>{"down v(rxp,rxn)", "up v(rxp,rxn)"}));
  EXPECT_EQ(w.time, (std::vector<double>{0, 1.5, 3}));  // down keeps 0, 3; up 0, 1.5, 3
  EXPECT_EQ(w.columns[0], (std::vector<double>{0, 1.5, 3}));
  EXPECT_EQ(w.columns[1], (std::vector<double>{0, 3, 0}));
  // Every engine row: all of both directions' times, each direction interpolated between its own.
  const Waveform all = run_wave_file(run, {.rows = WaveRows::Rows}).wave;
  EXPECT_EQ(all.time, (std::vector<double>{0, 0.5, 1, 1.5, 2, 2.5, 3}));
  EXPECT_EQ(all.columns[0], (std::vector<double>{0, 0.5, 1, 1.5, 2, 2.5, 3}));
  EXPECT_EQ(all.columns[1], (std::vector<double>{0, 1, 2, 3, 2, 1, 0}));
  // The uniform grid of before.
  const Waveform grid = run_wave_file(run, {.rows = WaveRows::Grid, .grid_step = 1.0}).wave;
  EXPECT_EQ(grid.time, (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(grid.columns[1], (std::vector<double>{0, 2, 2, 0}));
}

TEST(RunWaveFile, NamesParse) {
  for (WaveRows r : {WaveRows::Thinned, WaveRows::Rows, WaveRows::Grid})
    EXPECT_EQ(*parse_wave_rows(wave_rows_name(r)), r);
  EXPECT_NE(parse_wave_rows("every").status().message().find("none of thinned, rows, grid"),
            std::string::npos);
}

}  // namespace
}  // namespace isolink::analysis
