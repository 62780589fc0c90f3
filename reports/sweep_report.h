// The charts of `isolink sweep` (sweep_margin.png, sweep_heatmap.png, mc_histogram.png) from a
// sweep's results: the bridge from analysis/sweep_run.h to the drawing in sweep_plots.h.
//
//   SweepOptions opt;
//   opt.render_plots = reports::render_sweep_plots;   // analysis/ calls it after summary.json
#pragma once

#include <string>
#include <vector>

#include "analysis/sweep_run.h"
#include "reports/sweep_plots.h"

namespace isolink::reports {

// The plot data of a sweep: varying keys as axes, each point's worst relative margin and verdict.
SweepPlotData sweep_plot_data(const analysis::sweep::SweepSpec& s,
                              const std::vector<analysis::sweep::PointResult>& results);

// Writes the charts that apply (margin: one axis or more; heatmap: two or more in grid mode;
// histogram: Monte Carlo) and report.html (html_report.h) into dir and appends their file names
// to *files.
Status render_sweep_plots(const analysis::sweep::SweepSpec& s,
                          const std::vector<analysis::sweep::PointResult>& results,
                          const std::string& dir, std::vector<std::string>* files);

}  // namespace isolink::reports
