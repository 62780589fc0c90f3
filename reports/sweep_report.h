// The files `isolink sweep` writes after its points, from the results the sweep computed
// (analysis/sweep_run.h): summary.json, and the charts (sweep_margin.png, sweep_heatmap.png,
// mc_histogram.png, drawn in sweep_plots.h) with report.html. results.csv is the sweep's own log,
// written by analysis/ as points finish (it is what --resume and MPI read back).
//
//   StatusOr<SweepOutcome> out = run_sweep(spec, parts, opt);
//   Status st = reports::write_sweep_report(spec, &*out, opt.out_dir, /*plots=*/true);
//
// Errors: a file that cannot be written (its path and why); nothing is thrown.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/sweep_run.h"
#include "base/status.h"
#include "reports/sweep_plots.h"

namespace isolink::reports {

// summary.json's `paths`: {"edges": N, "simulated": M, "first_simulated": {"point", "path"} or
// null}: how many points took the fast path, and the first (lowest index) that did not and why.
nlohmann::ordered_json sweep_path_counts(const std::vector<analysis::sweep::PointResult>& results);

// summary.json: the sweep (file, name, base, mode, axes, Monte Carlo), the counts and pass yield
// (errors count as not passing; null when nothing is done), the metric each point was worst in,
// the paths, the worst point (smallest worst_margin_rel), the yield per grid point (Monte Carlo),
// the pass/fail boundary along the first varying axis (its crossing interpolated to 4 significant
// digits, on a log scale for log axes; null for zip or no varying axis), and with the result
// families the noise, worst_case and stress counts and lowest points (stress: the most scenarios
// broken, then the highest pin peak). results: by point index, as
// results.csv holds them (a resumed or MPI sweep gives the same summary as a threaded one).
nlohmann::ordered_json sweep_summary_json(const analysis::sweep::SweepSpec& s,
                                          const std::vector<analysis::sweep::PointResult>& results);

// The plot data of a sweep: varying keys as axes, each point's worst relative margin and verdict.
SweepPlotData sweep_plot_data(const analysis::sweep::SweepSpec& s,
                              const std::vector<analysis::sweep::PointResult>& results);

// Writes the charts that apply (margin: one axis or more; heatmap: two or more in grid mode;
// histogram: Monte Carlo) and report.html (html_report.h) into dir and appends their file names
// to *files.
Status render_sweep_plots(const analysis::sweep::SweepSpec& s,
                          const std::vector<analysis::sweep::PointResult>& results,
                          const std::string& dir, std::vector<std::string>* files);

// Writes summary.json into dir (an existing folder) and, with plots, the charts and report.html
// (render_sweep_plots), from out->results; appends the names written to out->files. The charts
// need the image plug-in (reports/image_plugin.h), loaded on first use.
Status write_sweep_report(const analysis::sweep::SweepSpec& s, analysis::sweep::SweepOutcome* out,
                          const std::string& dir, bool plots);

}  // namespace isolink::reports
