#include "reports/sweep_report.h"

#include <algorithm>

#include "base/file_io.h"
#include "reports/html_report.h"

namespace isolink::reports {

using SweepAxis = analysis::sweep::Axis;
using analysis::sweep::AxisValue;
using analysis::sweep::Mode;
using analysis::sweep::PointResult;
using analysis::sweep::SweepSpec;
using analysis::sweep::varying_axes;

SweepPlotData sweep_plot_data(const SweepSpec& s, const std::vector<PointResult>& results) {
  SweepPlotData d;
  d.title = s.name;
  d.source = s.path;
  d.samples = s.mc.samples;
  // Only the keys that vary are axes; the fixed ones are named in the charts' note.
  std::vector<size_t> vary = varying_axes(s);
  for (const SweepAxis& a : s.axes)
    if (a.values.size() == 1)
      d.note += (d.note.empty() ? "fixed: " : ", ") + a.key + " = " + a.values[0].label;
  // zip: the keys move together, so the first one is the x axis and the others ride along.
  if (s.mode == Mode::kZip && vary.size() > 1) {
    std::string with;
    for (size_t k = 1; k < vary.size(); ++k)
      with += (with.empty() ? "" : ", ") + s.axes[vary[k]].key;
    d.note += (d.note.empty() ? "" : "; ") + ("zip: " + with + " with " + s.axes[vary[0]].key);
    vary.resize(1);
  }
  for (size_t k : vary) {
    const SweepAxis& a = s.axes[k];
    SweepPlotAxis pa;
    pa.name = a.key;
    pa.unit = a.unit == config::Unit::kNone ? "" : config::unit_symbol(a.unit);
    pa.log = a.log;
    bool numeric = !a.variants;
    for (const AxisValue& v : a.values) {
      pa.labels.push_back(v.label);
      numeric = numeric && v.number.has_value();
    }
    if (numeric)
      for (const AxisValue& v : a.values) pa.values.push_back(*v.number);
    // Wide positive ranges read better on a log axis.
    if (numeric && !pa.values.empty()) {
      const auto [lo, hi] = std::minmax_element(pa.values.begin(), pa.values.end());
      if (*lo > 0 && *hi / *lo >= 20) pa.log = true;
    }
    d.axes.push_back(std::move(pa));
  }
  for (const PointResult& r : results) {
    SweepPlotPoint p;
    const std::vector<size_t> idx = s.grid_indices(r.index / s.samples());
    for (size_t k : vary) p.axis.push_back(idx[k]);
    p.margin = r.worst_rel;
    p.verdict = r.verdict;
    p.reason = r.reason;
    d.points.push_back(std::move(p));
  }
  return d;
}

Status render_sweep_plots(const SweepSpec& s, const std::vector<PointResult>& results,
                          const std::string& dir, std::vector<std::string>* files) {
  const SweepPlotData d = sweep_plot_data(s, results);
  if (!d.axes.empty()) {
    if (Status st = render_margin_png(d, dir + "/sweep_margin.png"); !st.ok()) return st;
    files->push_back("sweep_margin.png");
  }
  if (d.axes.size() >= 2 && s.mode == Mode::kGrid) {
    if (Status st = render_heatmap_png(d, dir + "/sweep_heatmap.png"); !st.ok()) return st;
    files->push_back("sweep_heatmap.png");
  }
  if (s.mc.samples > 0) {
    if (Status st = render_mc_histogram_png(d, dir + "/mc_histogram.png"); !st.ok()) return st;
    files->push_back("mc_histogram.png");
  }
  if (Status st = write_file_atomic(dir + "/report.html", sweep_report_html(s, results)); !st.ok())
    return st;
  files->push_back("report.html");
  return Status::Ok();
}

}  // namespace isolink::reports
