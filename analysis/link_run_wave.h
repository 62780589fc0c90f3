// The waveform file of a run (wave.csv): which rows it holds, and how close they stay to the
// engine's own rows.
//
//   WaveFile f = run_wave_file(run, {});         // thinned: the default of `isolink run`
//   Status s = write_waveform_csv(f.wave, dir + "/wave.csv");
//   md += wave_file_note(f);                     // what it holds, within what
//
// Rows. The engines give each direction its own rows: the LTI engine a grid refined where the
// response bends (linear interpolation between its rows within 1 mV of the engine's waveform,
// solver/lti.h GridOptions), the transient one row per accepted step. A 1 ns grid over 20 ms of
// traffic is 20 million rows (1.2 GB of CSV); the engine's rows are fewer, and the rows that
// linear interpolation cannot do without fewer still:
// - Thinned (the default): per direction, the fewest of the engine's rows (greedily, from the
//   first row on) such that linear interpolation between the kept rows reproduces every engine row
//   within a tolerance on every probe: the finest of kWaveTolerances whose file stays within
//   kWaveFileBytes (estimated), else the coarsest. Kept rows are the engine's exact values; the
//   tolerance used is returned (report.json and report.md state it).
// - Rows: every engine row.
// - Grid: every probe resampled onto a uniform step (the spec's sim.tstep), as before issue 45.
// Several directions share one time axis: the union of their rows, each direction's columns
// interpolated linearly between its own kept rows at the other's times (so within the same bound).
//
// Contract: pure functions (no I/O); units SI. Memory: the output only (the kept rows times the
// columns), plus one index vector per direction.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "base/status.h"
#include "base/waveform.h"

namespace isolink::analysis {

enum class WaveRows { Thinned, Rows, Grid };
// "thinned", "rows", "grid" (the CLI's --wave and Python's wave= take these names).
const char* wave_rows_name(WaveRows r);
StatusOr<WaveRows> parse_wave_rows(const std::string& text);

// V, finest first: how far linear interpolation between the thinned rows may be from any engine
// row. 1 mV is the LTI engine's own rule between its rows; a ripple of a few mV on every pulse
// (a 2 m cable's reflections) takes a row every 1-2 ns at 1 mV and every 2-3 ns at 20 mV.
inline constexpr double kWaveTolerances[] = {1e-3, 2e-3, 5e-3, 10e-3, 20e-3, 50e-3};
// The size wave.csv is kept under when a tolerance allows (estimated: 14 bytes of time and 11 per
// value a row).
inline constexpr double kWaveFileBytes = 90e6;
double wave_file_bytes(size_t rows, size_t columns);

struct WaveFileOptions {
  WaveRows rows = WaveRows::Thinned;
  double grid_step = 1e-9;  // Grid: s (the spec's sim.tstep)
  // Thinned: one tolerance (V) instead of the ladder (0: the ladder).
  double tolerance = 0;
};

struct WaveFile {
  Waveform wave;
  WaveRows rows = WaveRows::Thinned;
  // Thinned: the tolerance used (V), against the engine's rows (the run's own record thinning,
  // record_tol, included); 0 otherwise
  double tolerance = 0;
  double record_tol = 0;     // V: the runs' records were thinned within this (0: every row)
  size_t engine_rows = 0;    // rows of the engines, all directions together
  bool over_budget = false;  // Thinned: even the coarsest tolerance leaves it over kWaveFileBytes
};

// The indices of the rows of (time, columns) to keep: the first and the last row, and greedily the
// farthest row after each kept one such that the straight line between the two passes within
// `tolerance` of every row between them, on every column. One pass (each column keeps the range of
// slopes still possible from the last kept row), so the cost is rows x columns. Non-finite values
// are kept as rows of their own.
std::vector<size_t> thin_rows(std::span<const double> time,
                              const std::vector<std::span<const double>>& columns,
                              double tolerance);
// How many rows thin_rows keeps (nothing kept in memory).
size_t thin_rows_count(std::span<const double> time,
                       const std::vector<std::span<const double>>& columns, double tolerance);
// The index of the finest tolerance of `ladder` (ascending) that fits(tol) accepts, or
// ladder.size() when none does. By bisection, since a coarser tolerance never keeps more rows:
// a long record's rows are counted about log2 of the ladder's length times, not once per rung.
size_t finest_fitting(std::span<const double> ladder, const std::function<bool(double)>& fits);
// The same with a tolerance per column.
std::vector<size_t> thin_rows(std::span<const double> time,
                              const std::vector<std::span<const double>>& columns,
                              std::span<const double> tolerances);

// Every direction's probes (columns "down v(rxp,rxn)", ...) on one axis, by the rule above. A
// direction that is a copy of another (same_as) is still written (the file's columns do not
// depend on the link's symmetry).
WaveFile run_wave_file(const LinkRun& run, const WaveFileOptions& opt);
// One sentence for report.md and the terminal: what wave.csv holds and within what.
std::string wave_file_note(const WaveFile& f);

}  // namespace isolink::analysis
