#include "reports/sweep_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "base/file_io.h"
#include "reports/html_report.h"

namespace isolink::reports {

using SweepAxis = analysis::sweep::Axis;
using analysis::sweep::AxisValue;
using analysis::sweep::Mode;
using analysis::sweep::PointResult;
using analysis::sweep::SweepSpec;
using analysis::sweep::Tolerance;
using analysis::sweep::varying_axes;

nlohmann::ordered_json sweep_path_counts(const std::vector<PointResult>& results) {
  size_t edges = 0, simulated = 0;
  nlohmann::ordered_json first = nullptr;  // the first simulated point (by index) and why
  for (const PointResult& r : results) {
    if (r.path == "edges") ++edges;
    if (r.path.rfind("simulated", 0) != 0) continue;
    ++simulated;
    if (first.is_null() || r.index < first["point"].get<size_t>())
      first = {{"point", r.index}, {"path", r.path}};
  }
  return {{"edges", edges}, {"simulated", simulated}, {"first_simulated", first}};
}

namespace {

using nlohmann::ordered_json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

ordered_json num_json(double v) {
  return std::isnan(v) ? ordered_json(nullptr) : ordered_json(v);
}

// A point named in summary.json: its index and its point_columns() cells.
ordered_json point_json(const SweepSpec& s, const PointResult& r) {
  ordered_json w{{"point", r.index}};
  const std::vector<std::string> cols = s.point_columns();
  for (size_t i = 0; i < cols.size() && i < r.cells.size(); ++i) w[cols[i]] = r.cells[i];
  return w;
}

// A grid point's verdict and margin over its Monte Carlo samples (pass only when all pass).
struct GridCell {
  bool any = false;
  std::string verdict;  // pass | fail | error
  double margin = kNaN;
};

std::vector<GridCell> grid_cells(const SweepSpec& s, const std::vector<PointResult>& results) {
  std::vector<GridCell> cells(s.grid_size());
  for (const PointResult& r : results) {
    GridCell& c = cells[r.index / s.samples()];
    if (!c.any) {
      c.any = true;
      c.verdict = r.verdict;
    } else if (r.verdict == "error" || (r.verdict == "fail" && c.verdict == "pass")) {
      c.verdict = r.verdict;
    }
    if (!std::isnan(r.worst_rel) && (std::isnan(c.margin) || r.worst_rel < c.margin))
      c.margin = r.worst_rel;
  }
  return cells;
}

// Row-major grid index of a value index per axis.
size_t grid_index(const SweepSpec& s, const std::vector<size_t>& idx) {
  size_t g = 0;
  for (size_t k = 0; k < s.axes.size(); ++k) g = g * s.axes[k].values.size() + idx[k];
  return g;
}

ordered_json boundary_json(const SweepSpec& s, const std::vector<PointResult>& results) {
  const std::vector<size_t> vary = varying_axes(s);
  if (vary.empty() || s.mode == Mode::kZip) return nullptr;
  const size_t ax = vary[0];
  const SweepAxis& x = s.axes[ax];
  const std::vector<GridCell> cells = grid_cells(s, results);
  // The first varying key's value order: ascending for numbers, as listed otherwise.
  std::vector<size_t> order(x.values.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  bool numeric = true;
  for (const AxisValue& v : x.values) numeric = numeric && v.number.has_value();
  if (numeric)
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return *x.values[a].number < *x.values[b].number; });
  // One line per combination of the other varying keys.
  size_t others = 1;
  for (size_t k = 1; k < vary.size(); ++k) others *= s.axes[vary[k]].values.size();
  ordered_json along = ordered_json::array();
  for (size_t o = 0; o < others; ++o) {
    std::vector<size_t> idx(s.axes.size(), 0);
    ordered_json at = ordered_json::object();
    for (size_t k = vary.size(), rest = o; k-- > 1;) {
      const SweepAxis& a = s.axes[vary[k]];
      idx[vary[k]] = rest % a.values.size();
      rest /= a.values.size();
    }
    for (size_t k = 1; k < vary.size(); ++k)
      at[s.axes[vary[k]].key] = s.axes[vary[k]].values[idx[vary[k]]].label;
    auto grid_of = [&](size_t i) {
      idx[ax] = i;
      return grid_index(s, idx);
    };
    ordered_json transitions = ordered_json::array();
    ordered_json pass_values = ordered_json::array();
    const GridCell* prev = nullptr;
    size_t prev_i = 0;
    for (size_t i : order) {
      const GridCell& c = cells[grid_of(i)];
      if (!c.any) continue;
      if (c.verdict == "pass") pass_values.push_back(x.values[i].label);
      if (prev && prev->verdict != c.verdict) {
        ordered_json t{{"from", x.values[prev_i].label},
                       {"from_verdict", prev->verdict},
                       {"to", x.values[i].label},
                       {"to_verdict", c.verdict}};
        double crossing = kNaN;
        if (numeric && !std::isnan(prev->margin) && !std::isnan(c.margin) &&
            (prev->margin >= 0) != (c.margin >= 0)) {
          double x0 = *x.values[prev_i].number, x1 = *x.values[i].number;
          const double f = prev->margin / (prev->margin - c.margin);
          if (x.log && x0 > 0 && x1 > 0)
            crossing = std::exp(std::log(x0) + f * (std::log(x1) - std::log(x0)));
          else
            crossing = x0 + f * (x1 - x0);
        }
        // 4 significant digits: an interpolation between two points is no more exact than that.
        t["margin_crossing"] =
            num_json(std::isnan(crossing) ? kNaN : std::stod(fmt::format("{:.4g}", crossing)));
        transitions.push_back(t);
      }
      prev = &c;
      prev_i = i;
    }
    ordered_json line{{"at", at}};
    line["pass"] = pass_values;
    line["transitions"] = transitions;
    along.push_back(line);
  }
  return ordered_json{{"axis", x.key}, {"along", along}};
}

}  // namespace

nlohmann::ordered_json sweep_summary_json(const SweepSpec& s,
                                          const std::vector<PointResult>& results) {
  ordered_json j;
  j["sweep"] = s.path;
  j["name"] = s.name;
  j["base"] = s.base_inline ? ordered_json("(inline)") : ordered_json(s.base_path);
  j["mode"] = s.mode == Mode::kZip ? "zip" : "grid";
  ordered_json axes = ordered_json::array();
  for (const SweepAxis& a : s.axes) {
    ordered_json values = ordered_json::array();
    for (const AxisValue& v : a.values) values.push_back(v.label);
    axes.push_back({{"key", a.key}, {"values", values}});
  }
  j["axes"] = axes;
  if (s.mc.samples > 0) {
    ordered_json tol = ordered_json::array();
    for (const Tolerance& t : s.mc.tolerances) tol.push_back(t.key);
    j["monte_carlo"] = {{"samples", s.mc.samples}, {"seed", s.mc.seed}, {"tolerances", tol}};
  } else {
    j["monte_carlo"] = nullptr;
  }
  size_t pass = 0, fail = 0, error = 0;
  const PointResult* worst = nullptr;
  std::map<std::string, size_t> worst_metrics;
  for (const PointResult& r : results) {
    pass += r.verdict == "pass";
    fail += r.verdict == "fail";
    error += r.verdict == "error";
    if (r.verdict != "error") ++worst_metrics[r.worst_metric];
    if (!std::isnan(r.worst_rel) && (!worst || r.worst_rel < worst->worst_rel)) worst = &r;
  }
  const size_t done = pass + fail + error;
  j["points"] = s.size();
  j["done"] = done;
  j["pass"] = pass;
  j["fail"] = fail;
  j["error"] = error;
  // Errors count as not passing: a point that cannot be simulated is not a pass.
  j["pass_yield"] = done ? ordered_json(static_cast<double>(pass) / done) : ordered_json(nullptr);
  j["worst_metric_counts"] = worst_metrics;
  j["paths"] = sweep_path_counts(results);
  if (worst) {
    ordered_json w = point_json(s, *worst);
    w["verdict"] = worst->verdict;
    w["worst_metric"] = worst->worst_metric;
    w["worst_margin_rel"] = worst->worst_rel;
    j["worst"] = w;
  } else {
    j["worst"] = nullptr;
  }
  if (s.mc.samples > 0 && !s.axes.empty()) {
    // Yield per grid point.
    std::vector<size_t> gp(s.grid_size(), 0), gn(s.grid_size(), 0);
    for (const PointResult& r : results) {
      const size_t g = r.index / s.samples();
      ++gn[g];
      gp[g] += r.verdict == "pass";
    }
    ordered_json by = ordered_json::array();
    for (size_t g = 0; g < s.grid_size(); ++g) {
      ordered_json e;
      const std::vector<size_t> idx = s.grid_indices(g);
      for (size_t k = 0; k < s.axes.size(); ++k) e[s.axes[k].key] = s.axes[k].values[idx[k]].label;
      e["done"] = gn[g];
      e["pass_yield"] =
          gn[g] ? ordered_json(static_cast<double>(gp[g]) / gn[g]) : ordered_json(nullptr);
      by.push_back(e);
    }
    j["yield_by_grid_point"] = by;
  }
  j["boundary"] = boundary_json(s, results);
  // A result family's verdict counts and its point with the smallest figure (the noise immunity
  // in dB, the worst case's relative margin).
  auto family = [&](auto has, auto verdict, auto figure, auto extra) {
    size_t npass = 0, nfail = 0;
    const PointResult* low = nullptr;
    for (const PointResult& r : results) {
      if (!has(r)) continue;
      npass += verdict(r) == "pass";
      nfail += verdict(r) == "fail";
      if (!std::isnan(figure(r)) && (!low || figure(r) < figure(*low))) low = &r;
    }
    ordered_json n{{"pass", npass}, {"fail", nfail}};
    if (low) {
      ordered_json w = point_json(s, *low);
      extra(*low, w);
      n["worst"] = w;
    } else {
      n["worst"] = nullptr;
    }
    return n;
  };
  if (s.noise_outputs)
    j["noise"] = family([](const PointResult& r) { return r.noise.has_value(); },
                        [](const PointResult& r) { return r.noise->verdict; },
                        [](const PointResult& r) { return r.noise->immunity_min_db; },
                        [](const PointResult& r, ordered_json& w) {
                          w["immunity_min_db"] = r.noise->immunity_min_db;
                        });
  // "worst" is taken by the spec traffic's worst point.
  if (s.worst_outputs)
    j["worst_case"] = family([](const PointResult& r) { return r.worst.has_value(); },
                             [](const PointResult& r) { return r.worst->verdict; },
                             [](const PointResult& r) { return r.worst->margin_rel; },
                             [](const PointResult& r, ordered_json& w) {
                               w["verdict"] = r.worst->verdict;
                               w["worst_metric"] = r.worst->worst_metric;
                               w["margin_rel"] = r.worst->margin_rel;
                             });
  // Its worst point: the most scenarios broken, then the highest pin peak (x / (1 + x) < 1).
  if (s.stress_outputs)
    j["stress"] = family([](const PointResult& r) { return r.stress.has_value(); },
                         [](const PointResult& r) { return r.stress->verdict; },
                         [](const PointResult& r) {
                           const PointResult::Stress& st = *r.stress;
                           if (st.verdict.empty()) return std::numeric_limits<double>::quiet_NaN();
                           const double pin = std::isfinite(st.max_pin_v) ? st.max_pin_v : 0.0;
                           return -(st.breaking + pin / (1 + pin));
                         },
                         [](const PointResult& r, ordered_json& w) {
                           w["breaking"] = r.stress->breaking;
                           w["scenarios"] = r.stress->scenarios;
                           w["max_pin_V"] = r.stress->max_pin_v;
                           w["first_broken"] = r.stress->first_broken;
                         });
  return j;
}

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

Status write_sweep_report(const SweepSpec& s, analysis::sweep::SweepOutcome* out,
                          const std::string& dir, bool plots) {
  const nlohmann::ordered_json j = sweep_summary_json(s, out->results);
  if (Status st = write_file_atomic(dir + "/summary.json", j.dump(2) + "\n"); !st.ok()) return st;
  out->files.push_back("summary.json");
  return plots ? render_sweep_plots(s, out->results, dir, &out->files) : Status::Ok();
}

}  // namespace isolink::reports
