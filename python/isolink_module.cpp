// The isolink Python module (pybind11): a front end beside cli/, over the same library calls.
//
//   import isolink
//   r = isolink.run("netlists/examples/same_pcb.yaml")   # report.json's content, plus waveforms
//   r["verdict"], r["directions"][0]["check"]["summary"]["worst"], r["directions"][0]["wave"]
//   m = isolink.check(t, v, rules="bq7961x")             # `isolink check --json`'s object
//   rows = isolink.sweep("sweep.yaml")                   # results.csv's rows, as dicts
//
// Every result is the JSON the CLI writes for the same input (report.json, check --json,
// results.csv), turned into dicts and lists, so a name means the same thing in both front ends.
// Errors raise isolink.Error (a ValueError) whose text is the CLI's message, file:line:col
// included. No analysis happens here: each function is the library call its CLI command makes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <stdlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/compare.h"
#include "analysis/link_run.h"
#include "analysis/pack_spec.h"
#include "analysis/simulate.h"
#include "analysis/sweep_run.h"
#include "analysis/sweep_spec.h"
#include "base/csv.h"
#include "base/hex.h"
#include "base/status.h"
#include "config/yaml_reader.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "reports/run_report.h"

namespace py = pybind11;

namespace isolink::python {
namespace {

PyObject* g_error = nullptr;  // isolink.Error
struct ErrorTag {};           // names isolink.Error's type; no C++ exception is translated to it

[[noreturn]] void raise(const Status& s) {
  PyErr_SetString(g_error, s.message().c_str());
  throw py::error_already_set();
}
template <typename T>
T take(StatusOr<T> v) {
  if (!v) raise(v.status());
  return std::move(*v);
}

py::object to_python(const nlohmann::ordered_json& j) {
  switch (j.type()) {
    case nlohmann::ordered_json::value_t::null:
      return py::none();
    case nlohmann::ordered_json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::ordered_json::value_t::number_integer:
      return py::int_(j.get<int64_t>());
    case nlohmann::ordered_json::value_t::number_unsigned:
      return py::int_(j.get<uint64_t>());
    case nlohmann::ordered_json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::ordered_json::value_t::string:
      return py::str(j.get_ref<const std::string&>());
    case nlohmann::ordered_json::value_t::array: {
      py::list l;
      for (const auto& e : j) l.append(to_python(e));
      return l;
    }
    case nlohmann::ordered_json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return d;
    }
    default:
      return py::none();  // binary / discarded: never produced by isolink's writers
  }
}

py::array_t<double> to_numpy(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

// {"time": array, "<probe>": array, ...}: one direction's waveform on the engine's own grid.
py::dict wave_dict(const Waveform& w) {
  py::dict d;
  d["time"] = to_numpy(w.time);
  for (size_t k = 0; k < w.names.size(); ++k) d[py::str(w.names[k])] = to_numpy(w.columns[k]);
  return d;
}

StatusOr<analysis::Engine> engine_option(const std::string& engine) {
  return analysis::parse_engine(engine);
}

// Solver warnings (floating nodes, ...), each once, as Python warnings: what the CLI prints on
// stderr.
void warn(const std::vector<std::string>& seen) {
  for (const std::string& w : seen)
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) < 0) throw py::error_already_set();
}

// isolink.run: `isolink run SPEC --no-worst`'s report.json as a dict, each direction with its
// waveforms ("wave") as numpy arrays and its verdict as a bool ("pass").
py::dict run(const std::string& path, const std::optional<std::string>& direction,
             const std::string& engine, const std::vector<std::string>& parts_dirs) {
  if (direction && *direction != "down" && *direction != "up" && *direction != "both")
    raise(Status::Error("direction: '" + *direction + "' is none of down, up, both"));
  analysis::RunOptions ro;
  ro.engine = take(engine_option(engine));
  bool pack = false;
  StatusOr<link::LinkSpec> spec = Status::Error("not read");
  StatusOr<link::PartLibrary> parts = Status::Error("not read");
  StatusOr<analysis::LinkRun> lr = Status::Error("not run");
  {
    py::gil_scoped_release nogil;  // the work holds no Python object
    StatusOr<config::YamlDoc> doc = config::YamlDoc::load_file(path);
    pack = doc && analysis::is_pack_spec(*doc);
    if (!pack) spec = link::read_link_spec_file(path);
    if (spec && direction == "down") spec->stimulus.directions = {link::Direction::kDown};
    if (spec && direction == "up") spec->stimulus.directions = {link::Direction::kUp};
    if (spec && direction == "both")
      spec->stimulus.directions = {link::Direction::kDown, link::Direction::kUp};
    if (spec) parts = link::PartLibrary::load(parts_dirs);
    if (spec && parts) lr = analysis::run_link(*spec, *parts, ro);
  }
  if (pack)
    raise(Status::Error(path + ": error: a pack spec (hops:); isolink.run takes a link spec "
                               "(run a pack with `isolink pack`)"));
  if (!spec) raise(spec.status());
  if (!parts) raise(parts.status());
  if (!lr) raise(lr.status().with_context(path));
  py::dict out = to_python(reports::run_report_json(*spec, *lr));
  out["pass"] = lr->pass;
  py::list dirs = out["directions"];
  std::vector<std::string> warned;
  for (size_t i = 0; i < lr->directions.size(); ++i) {
    const analysis::DirectionRun& d = lr->directions[i];
    py::dict dj = dirs[i];
    dj["pass"] = d.pass;
    dj["wave"] = wave_dict(d.sim.wave);
    for (const std::string& w : d.sim.warnings)
      if (std::find(warned.begin(), warned.end(), w) == warned.end()) warned.push_back(w);
  }
  warn(warned);
  return out;
}

// isolink.check: `isolink check --json`'s object for samples t (s, increasing) and v (V).
py::dict check(const py::array_t<double, py::array::c_style | py::array::forcecast>& t,
               const py::array_t<double, py::array::c_style | py::array::forcecast>& v,
               const std::string& rules_name, const std::optional<std::string>& expect) {
  if (t.ndim() != 1 || v.ndim() != 1)
    raise(Status::Error("t and v must be one-dimensional arrays, got " + std::to_string(t.ndim()) +
                        " and " + std::to_string(v.ndim()) + " dimensions"));
  eye::Rules rules = take(eye::load_rules(rules_name));
  eye::CheckOptions opt;
  if (expect) {
    StatusOr<std::vector<uint8_t>> e = parse_hex_bytes(*expect);
    if (!e) raise(Status::Error("expect: error: " + e.status().message()));
    opt.expect = *e;
  }
  StatusOr<eye::CheckResult> r = Status::Error("not run");
  {
    py::gil_scoped_release nogil;
    r = eye::check_samples({t.data(), static_cast<size_t>(t.size())},
                           {v.data(), static_cast<size_t>(v.size())}, rules, opt);
  }
  if (!r) raise(Status::Error("error: " + r.status().message()));
  py::dict out = to_python(eye::to_json(*r));
  out["pass"] = r->pass;
  return out;
}

// isolink.load_spec: the link spec with every default filled in (report.json's "spec").
py::dict load_spec(const std::string& path) {
  return to_python(reports::link_spec_json(take(link::read_link_spec_file(path))));
}

// isolink.compare: `isolink compare --json`'s object for a capture (one file, or P and N files)
// and a link spec; errors (bad input) raise isolink.Error.
py::dict compare(const std::vector<std::string>& capture, const std::string& spec,
                 const std::string& direction, const std::vector<std::string>& fit,
                 const std::map<std::string, std::pair<double, double>>& bounds,
                 const std::string& frames, const std::string& p, const std::string& n,
                 const std::string& diff, const std::vector<std::string>& parts_dirs) {
  if (direction != "down" && direction != "up")
    raise(Status::Error("direction: '" + direction + "' is none of down, up"));
  analysis::CompareInput in{.files = capture, .spec_path = spec};
  in.cols.p = p;
  in.cols.n = n;
  in.cols.diff = diff;
  analysis::CompareOptions opt;
  opt.direction = direction == "up" ? link::Direction::kUp : link::Direction::kDown;
  opt.fit = fit;
  opt.bounds = bounds;
  opt.frames = frames;
  StatusOr<analysis::CompareResult> r = Status::Error("not run");
  {
    py::gil_scoped_release nogil;
    StatusOr<link::PartLibrary> parts = link::PartLibrary::load(parts_dirs);
    r = parts ? analysis::compare_capture(in, *parts, opt)
              : StatusOr<analysis::CompareResult>(parts.status());
  }
  if (!r) raise(r.status());
  return to_python(analysis::compare_json(*r));
}

// A results.csv cell as Python: "" -> None, true/false -> bool, a number -> float (the point
// index -> int), anything else (a variant's name, a reason) -> str.
py::object cell(const std::string& name, const std::string& text) {
  if (text.empty()) return py::none();
  if (text == "true" || text == "false") return py::bool_(text == "true");
  double x = 0;
  const char* end = text.data() + text.size();
  // Decimal numbers only (no hex); "nan" or "inf" would be a variant's name.
  if (auto [p, ec] = std::from_chars(text.data(), end, x);
      ec == std::errc() && p == end && std::isfinite(x)) {
    if (name == "point" || name == "sample") return py::int_(static_cast<int64_t>(x));
    return py::float_(x);
  }
  return py::str(text);
}

// isolink.sweep: every point's row of results.csv (the same names, units and numbers), as dicts
// in point order. results.csv and summary.json go to `out` (a temporary folder, removed
// afterwards, when None).
py::list sweep(const std::string& path, const std::optional<std::string>& out, int jobs,
               const std::string& engine, const std::vector<std::string>& parts_dirs) {
  if (jobs < 0)
    raise(Status::Error("jobs: " + std::to_string(jobs) + " is below 0 (0: all cores)"));
  analysis::sweep::SweepOptions opt;
  opt.point.run.engine = take(engine_option(engine));
  opt.jobs = jobs;
  opt.plots = false;  // analysis/ draws nothing; charts are the CLI's (reports/)
  opt.quiet = true;
  std::string tmp;
  if (out) {
    opt.out_dir = *out;
  } else {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "isolink-sweep-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
      raise(Status::Error(pattern + ": error: cannot create a temporary folder"));
    tmp = opt.out_dir = pattern;
  }
  analysis::sweep::SweepSpec s;
  StatusOr<analysis::sweep::SweepOutcome> r = Status::Error("not run");
  {
    py::gil_scoped_release nogil;
    StatusOr<analysis::sweep::SweepSpec> sp = analysis::sweep::read_sweep_file(path);
    StatusOr<link::PartLibrary> p =
        sp ? link::PartLibrary::load(parts_dirs) : StatusOr<link::PartLibrary>(sp.status());
    if (p)
      r = analysis::sweep::run_sweep(*sp, *p, opt);
    else
      r = p.status();
    if (sp) s = std::move(*sp);
    if (!tmp.empty()) {
      std::error_code ec;
      std::filesystem::remove_all(tmp, ec);
    }
  }
  if (!r) raise(r.status());
  const std::vector<std::string> header = analysis::sweep::results_header(s);
  py::list rows;
  for (const analysis::sweep::PointResult& pr : r->results) {
    std::string line = analysis::sweep::results_row(pr);
    if (!line.empty() && line.back() == '\n') line.pop_back();
    const std::vector<std::string> fields = split_csv_line(line);
    py::dict row;
    for (size_t k = 0; k < header.size() && k < fields.size(); ++k)
      row[py::str(header[k])] = cell(header[k], fields[k]);
    rows.append(std::move(row));
  }
  return rows;
}

}  // namespace
}  // namespace isolink::python

PYBIND11_MODULE(isolink, m) {
  using namespace isolink::python;
  m.doc() =
      "isolink: signal integrity of BMS daisy-chain links (run, check, compare, load_spec, sweep). "
      "Results are the JSON the isolink CLI writes, as dicts; errors raise isolink.Error with "
      "the CLI's file:line:col message.";
  static py::exception<ErrorTag> error(m, "Error", PyExc_ValueError);
  g_error = error.ptr();
  m.def("run", &run, py::arg("spec"), py::kw_only(), py::arg("direction") = py::none(),
        py::arg("engine") = "auto", py::arg("parts") = std::vector<std::string>{},
        "Simulate a link spec (YAML) with its traffic and score each receiver, as `isolink run "
        "SPEC --no-worst`: report.json's content as a dict, with 'pass' (bool) at the top and in "
        "each direction, and each direction's waveforms under 'wave' ({'time': array, "
        "'v(rxp,rxn)': array, ...}, seconds and volts).");
  m.def("check", &check, py::arg("t"), py::arg("v"), py::kw_only(), py::arg("rules") = "bq7961x",
        py::arg("expect") = py::none(),
        "Score samples v (V) at times t (s, increasing) against a rule set (bq7961x, bq79600, "
        "tone or a YAML rule file), as `isolink check --json`: its object as a dict, with "
        "'pass' (bool). expect: the bytes expected, in hex ('80 00 02 15').");
  m.def("compare", &compare, py::arg("capture"), py::arg("spec"), py::kw_only(),
        py::arg("direction") = "down", py::arg("fit") = std::vector<std::string>{},
        py::arg("bounds") = std::map<std::string, std::pair<double, double>>{},
        py::arg("frames") = "", py::arg("p") = "", py::arg("n") = "", py::arg("diff") = "",
        py::arg("parts") = std::vector<std::string>{},
        "Compare a scope capture (a list: one file, or the P and N files) with the link spec's "
        "simulation of the same traffic, as `isolink compare --json`: its object as a dict "
        "(verdict, offset_s, residual, fit, residual_after_fit, findings, ...). fit: keys as in "
        "sweeps; bounds: {key: (low, high)} in SI units.");
  m.def("load_spec", &load_spec, py::arg("spec"),
        "Read a link spec: every key with its default filled in, as report.json's 'spec'.");
  m.def("sweep", &sweep, py::arg("sweep"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("jobs") = 0, py::arg("engine") = "auto",
        py::arg("parts") = std::vector<std::string>{},
        "Run a sweep file on all cores (jobs: threads, 0 = all) as `isolink sweep --no-plots`: "
        "one dict per point, in point order, with results.csv's columns and numbers (margins in "
        "V and ns). results.csv and summary.json are written to out (a temporary folder when "
        "None, removed afterwards).");
}
