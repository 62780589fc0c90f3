// The isolink Python module (pybind11): a front end beside cli/, over the same library calls.
//
//   import isolink
//   r = isolink.run({"name": "a", "cable": {"length": 12}})   # report.json's content + waveforms
//   w = isolink.worst("netlists/examples/cap_2m.yaml")         # `isolink worst --json`
//   m = isolink.check(t, v, rules="bq7961x")                   # `isolink check --json`
//
// Every result is the JSON the CLI writes for the same input, built by the same functions
// (reports::run_report_json, reports::worst_json, reports::noise_json, reports::pack_report_json,
// eye::to_json, the sweep's results.csv rows), turned into dicts and lists: a name means the same
// thing in both front ends and the two cannot drift. Errors raise isolink.Error (a ValueError)
// whose text is the CLI's message. No analysis happens here: each function reads its input the
// way its CLI command does, releases the GIL and makes that command's library call.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <stdlib.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/compare.h"
#include "analysis/link_run.h"
#include "analysis/noise.h"
#include "analysis/pack.h"
#include "analysis/pack_spec.h"
#include "analysis/simulate.h"
#include "analysis/stress.h"
#include "analysis/sweep_run.h"
#include "analysis/sweep_spec.h"
#include "analysis/worst.h"
#include "base/csv.h"
#include "base/hex.h"
#include "base/status.h"
#include "config/yaml_reader.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "python/convert.h"
#include "python/docstrings.h"
#include "reports/compare_report.h"
#include "reports/noise_report.h"
#include "reports/pack_report.h"
#include "reports/run_report.h"
#include "reports/stress_report.h"
#include "reports/sweep_report.h"
#include "reports/worst_report.h"

namespace isolink::python {
namespace {

struct ErrorTag {};  // names isolink.Error's type; no C++ exception is translated to it
using Strings = std::vector<std::string>;

// The readers, from a file or a dict's text (convert.h SpecArg); called without the GIL.
StatusOr<link::LinkSpec> read_link(const SpecArg& a) {
  return a.is_file() ? link::read_link_spec_file(a.path)
                     : link::read_link_spec_text(a.text, a.name);
}
StatusOr<config::YamlDoc> read_doc(const SpecArg& a) {
  return a.is_file() ? config::YamlDoc::load_file(a.path)
                     : config::YamlDoc::from_text(a.text, a.name);
}

// direction= as the CLI's --direction: overrides the spec's stimulus.direction.
void check_direction(const std::optional<std::string>& d) {
  if (d && *d != "down" && *d != "up" && *d != "both")
    raise(Status::Error("direction: error: '" + *d + "' is none of down, up, both"));
}
void set_direction(link::LinkSpec& spec, const std::optional<std::string>& d) {
  if (d == "down") spec.stimulus.directions = {link::Direction::kDown};
  if (d == "up") spec.stimulus.directions = {link::Direction::kUp};
  if (d == "both") spec.stimulus.directions = {link::Direction::kDown, link::Direction::kUp};
}

// A link analysis's inputs and result (run_on_link).
template <class Result>
struct OnLink {
  link::LinkSpec spec;
  Result result;
};

// Reads the link spec (direction= applied) and the part library, then runs `analyse` on them,
// all without the GIL (the work holds no Python object); raises the first error, the analysis's
// with the spec's place.
template <class Result>
OnLink<Result> run_on_link(
    const SpecArg& arg, const Strings& parts_dirs, const std::optional<std::string>& direction,
    const std::function<StatusOr<Result>(const link::LinkSpec&, const link::PartLibrary&)>&
        analyse) {
  StatusOr<link::LinkSpec> spec = Status::Error("not read");
  StatusOr<link::PartLibrary> parts = Status::Error("not read");
  StatusOr<Result> r = Status::Error("not run");
  {
    py::gil_scoped_release nogil;
    spec = read_link(arg);
    if (spec) set_direction(*spec, direction);
    if (spec) parts = link::PartLibrary::load(parts_dirs);
    if (spec && parts) r = analyse(*spec, *parts);
  }
  if (!spec) raise(spec.status());
  if (!parts) raise(parts.status());
  if (!r) raise(r.status().with_context(arg.where()));
  return {std::move(*spec), std::move(*r)};
}

Strings sim_warnings(const analysis::LinkRun& run) {
  Strings w;
  for (const analysis::DirectionRun& d : run.directions)
    w.insert(w.end(), d.sim.warnings.begin(), d.sim.warnings.end());
  return w;
}

// isolink.run: `isolink run SPEC [--no-worst]`'s report.json, with waveforms and bools.
py::dict run(const py::object& spec_obj, const std::optional<std::string>& direction,
             const std::string& engine, bool worst, const std::string& wave,
             const Strings& parts_dirs) {
  check_direction(direction);
  const SpecArg arg = spec_arg(spec_obj, "spec");
  analysis::RunOptions ro;
  ro.engine = take(analysis::parse_engine(engine));
  // wave="rows": every engine row (as `isolink run --wave rows`); "thinned": the run's record.
  if (wave == "rows")
    ro.record_tol = 0;
  else if (wave != "thinned")
    raise(Status::Error("wave: error: '" + wave + "' is none of thinned, rows"));
  bool pack = false;
  StatusOr<link::LinkSpec> spec = Status::Error("not read");
  StatusOr<link::PartLibrary> parts = Status::Error("not read");
  StatusOr<analysis::LinkRun> lr = Status::Error("not run");
  std::optional<StatusOr<analysis::WorstResult>> wr;
  {
    py::gil_scoped_release nogil;  // the work holds no Python object
    StatusOr<config::YamlDoc> doc = read_doc(arg);
    pack = doc && analysis::is_pack_spec(*doc);
    if (!pack) spec = read_link(arg);
    if (spec) set_direction(*spec, direction);
    if (spec) parts = link::PartLibrary::load(parts_dirs);
    if (spec && parts) lr = analysis::run_link(*spec, *parts, ro);
    if (lr && worst && link::nonlinear_parts(*spec).empty())
      wr = analysis::worst_case(*spec, *parts);
  }
  if (pack)
    raise(Status::Error(arg.where() + ": error: a pack spec (hops:); isolink.run takes a link "
                                      "spec (run a pack with isolink.pack)"));
  if (!spec) raise(spec.status());
  if (!parts) raise(parts.status());
  if (!lr) raise(lr.status().with_context(arg.where()));
  if (wr && !*wr) raise(wr->status().with_context(arg.where() + ", worst case"));
  nlohmann::ordered_json j = reports::run_report_json(*spec, *lr);
  if (wr) j["worst_case"] = reports::worst_json(**wr);  // as cmd_run.cpp
  if (worst && !wr)  // a nonlinear link: no superposition (as cmd_run.cpp)
    j["worst_case"] = {{"computed", false},
                       {"why", link::linear_only(*spec, "the worst case over all legal traffic")}};
  py::dict out = to_python(j);
  out["pass"] = lr->pass;
  py::list dirs = out["directions"];
  for (size_t i = 0; i < lr->directions.size(); ++i) {
    py::dict dj = dirs[i];
    dj["pass"] = lr->directions[i].pass;
    dj["wave"] = wave_dict(lr->directions[i].sim.wave);
  }
  warn_once(sim_warnings(*lr));
  return out;
}

// isolink.worst: `isolink worst SPEC --json`.
py::object worst(const py::object& spec_obj, const std::optional<std::string>& direction,
                 const std::string& edge_engine, const Strings& parts_dirs) {
  check_direction(direction);
  if (edge_engine != "auto" && edge_engine != "transient")
    raise(Status::Error("edge_engine: error: '" + edge_engine + "' is none of auto, transient"));
  const SpecArg arg = spec_arg(spec_obj, "spec");
  analysis::WorstOptions opt;
  if (edge_engine == "transient") opt.edge_engine = analysis::WorstOptions::EdgeEngine::Transient;
  const OnLink<analysis::WorstResult> w = run_on_link<analysis::WorstResult>(
      arg, parts_dirs, direction, [&](const link::LinkSpec& spec, const link::PartLibrary& parts) {
        return analysis::worst_case(spec, parts, opt);
      });
  return to_python(reports::worst_json(w.result));
}

// isolink.noise: `isolink noise SPEC --json`.
py::object noise(const py::object& spec_obj, const Strings& parts_dirs) {
  const SpecArg arg = spec_arg(spec_obj, "spec");
  const OnLink<analysis::NoiseRun> nr = run_on_link<analysis::NoiseRun>(
      arg, parts_dirs, std::nullopt,
      [](const link::LinkSpec& spec, const link::PartLibrary& parts) {
        return analysis::run_noise(spec, parts);
      });
  py::object out = to_python(reports::noise_json(nr.result.noise));
  warn_once(sim_warnings(nr.result.run));
  return out;
}

// isolink.stress: `isolink stress SPEC --json`.
py::object stress(const py::object& spec_obj, const Strings& only, const Strings& parts_dirs) {
  const SpecArg arg = spec_arg(spec_obj, "spec");
  analysis::StressOptions so;
  so.only = only;
  const OnLink<analysis::StressResult> r = run_on_link<analysis::StressResult>(
      arg, parts_dirs, std::nullopt,
      [&](const link::LinkSpec& spec, const link::PartLibrary& parts) {
        return analysis::run_stress(spec, parts, so);
      });
  return to_python(reports::stress_json(r.spec.name, r.result));
}

// isolink.sim: `isolink sim NETLIST --probe ...`'s columns as numpy arrays.
py::dict sim(const py::object& netlist, const Strings& probes, const std::string& engine,
             const py::object& step, const py::object& tstop, const py::object& tmax,
             const std::optional<std::string>& method, const std::optional<double>& reltol) {
  if (probes.empty()) raise(Status::Error("probes: error: give at least one probe, e.g. 'v(out)'"));
  analysis::SimulationRequest req;
  req.probes = probes;
  req.engine = take(analysis::parse_engine(engine));
  const std::optional<double> dt = time_arg(step, "step");
  req.grid_step = dt.value_or(0.0);
  req.tstop = time_arg(tstop, "tstop");
  req.tmax = time_arg(tmax, "tmax");
  if (method && *method != "trap" && *method != "gear")
    raise(Status::Error("method: error: '" + *method + "' is none of trap, gear"));
  if (method)
    req.method = *method == "trap" ? IntegrationMethod::Trapezoidal : IntegrationMethod::Gear2;
  if (reltol && !(*reltol >= 1e-9 && *reltol <= 0.1))
    raise(Status::Error(fmt::format("reltol: error: {:g} is outside 1e-9 to 0.1", *reltol)));
  req.reltol = reltol;
  // A str with a line break is the netlist's text; anything else names a file.
  std::string text;
  if (py::isinstance<py::str>(netlist)) text = netlist.cast<std::string>();
  const bool is_text = text.find('\n') != std::string::npos;
  if (py::isinstance<py::dict>(netlist))
    raise(Status::Error("netlist: error: expected a path or the netlist's text, got a dict"));
  const std::string path = is_text ? "" : spec_arg(netlist, "netlist").path;
  StatusOr<Netlist> n = Status::Error("not read");
  StatusOr<analysis::SimulationResult> r = Status::Error("not run");
  {
    py::gil_scoped_release nogil;
    n = is_text ? read_spice_text(text, "<netlist>") : read_spice_file(path);
    if (n) r = analysis::simulate_netlist(*n, req);
  }
  if (!n) raise(n.status());
  if (!r) {
    const std::string& m = r.status().message();  // as cmd_sim.cpp
    raise(Status::Error(m.find(": error: ") == std::string::npos ? "sim: error: " + m : m));
  }
  warn_once(r->warnings);
  // With a step, the LTI engine already wrote that grid; the transient's steps are resampled onto
  // it (as cmd_sim.cpp; simulate_netlist refused a grid of too many rows).
  return wave_dict(dt && r->engine != analysis::Engine::Lti ? r->wave.resampled(*dt) : r->wave);
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
py::list sweep(const py::object& sweep_obj, const std::optional<std::string>& out, int jobs,
               const std::string& engine, const Strings& parts_dirs) {
  if (jobs < 0)
    raise(Status::Error("jobs: error: " + std::to_string(jobs) + " is below 0 (0: all cores)"));
  const SpecArg arg = spec_arg(sweep_obj, "sweep");
  analysis::sweep::SweepOptions opt;
  opt.point.run.engine = take(analysis::parse_engine(engine));
  opt.jobs = jobs;
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
    StatusOr<analysis::sweep::SweepSpec> sp =
        arg.is_file() ? analysis::sweep::read_sweep_file(arg.path)
                      : analysis::sweep::read_sweep_text(arg.text, arg.name);
    StatusOr<link::PartLibrary> p =
        sp ? link::PartLibrary::load(parts_dirs) : StatusOr<link::PartLibrary>(sp.status());
    if (p)
      r = analysis::sweep::run_sweep(*sp, *p, opt);
    else
      r = p.status();
    // summary.json beside results.csv; the charts are the CLI's.
    if (r)
      if (Status st = reports::write_sweep_report(*sp, &*r, opt.out_dir, false); !st.ok()) r = st;
    if (sp) s = std::move(*sp);
    if (!tmp.empty()) {
      std::error_code ec;
      std::filesystem::remove_all(tmp, ec);
    }
  }
  if (!r) raise(r.status());
  const Strings header = analysis::sweep::results_header(s);
  py::list rows;
  for (const analysis::sweep::PointResult& pr : r->results) {
    std::string line = analysis::sweep::results_row(pr);
    if (!line.empty() && line.back() == '\n') line.pop_back();
    const Strings fields = split_csv_line(line);
    py::dict row;
    for (size_t k = 0; k < header.size() && k < fields.size(); ++k)
      row[py::str(header[k])] = cell(header[k], fields[k]);
    rows.append(std::move(row));
  }
  return rows;
}

// isolink.pack: `isolink pack`'s report.json.
py::object pack(const py::object& pack_obj, int jobs, bool worst, const Strings& parts_dirs) {
  if (jobs < 0)
    raise(Status::Error("jobs: error: " + std::to_string(jobs) + " is below 0 (0: all cores)"));
  const SpecArg arg = spec_arg(pack_obj, "pack_spec");
  analysis::PackOptions opt;
  opt.jobs = jobs;
  if (worst) opt.worst = analysis::WorstOptions{};
  StatusOr<analysis::PackSpec> spec = Status::Error("not read");
  StatusOr<link::PartLibrary> parts = Status::Error("not read");
  StatusOr<analysis::PackResult> r = Status::Error("not run");
  {
    py::gil_scoped_release nogil;
    spec = arg.is_file() ? analysis::read_pack_spec_file(arg.path)
                         : analysis::read_pack_spec_text(arg.text, arg.name);
    if (spec) parts = link::PartLibrary::load(parts_dirs);
    if (spec && parts) r = analysis::run_pack(*spec, *parts, opt);
  }
  if (!spec) raise(spec.status());
  if (!parts) raise(parts.status());
  if (!r) raise(r.status().with_context(arg.where()));
  py::object out = to_python(reports::pack_report_json(*spec, *r));
  Strings w;
  for (const analysis::HopResult& h : r->hops) {
    const Strings hw = sim_warnings(h.run);
    w.insert(w.end(), hw.begin(), hw.end());
  }
  warn_once(w);
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
// isolink.compare: `isolink compare --json`'s object for a capture (one file, or P and N files)
// and a link spec; errors (bad input) raise isolink.Error.
py::dict compare(const std::vector<std::string>& capture, const std::string& spec,
                 const std::string& direction, const std::vector<std::string>& fit,
                 const py::dict& bounds_obj, const std::string& frames, const std::string& p,
                 const std::string& n, const std::string& diff,
                 const std::vector<std::string>& parts_dirs) {
  if (direction != "down" && direction != "up")
    raise(Status::Error("direction: '" + direction + "' is none of down, up"));
  std::map<std::string, std::pair<double, double>> bounds;
  for (const auto& [key, range] : bounds_obj) {
    const auto pair = range.cast<std::pair<double, double>>();
    bounds[key.cast<std::string>()] = pair;
  }
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
  return to_python(reports::compare_json(*r));
}

py::object load_spec(const py::object& spec_obj) {
  const SpecArg arg = spec_arg(spec_obj, "spec");
  StatusOr<link::LinkSpec> spec = Status::Error("not read");
  {
    py::gil_scoped_release nogil;
    spec = read_link(arg);
  }
  return to_python(reports::link_spec_json(take(std::move(spec))));
}

}  // namespace
}  // namespace isolink::python

PYBIND11_MODULE(isolink, m) {
  using namespace isolink::python;
  namespace doc = isolink::python::doc;
  m.doc() = doc::kModule;
  static py::exception<ErrorTag> error(m, "Error", PyExc_ValueError);
  set_error_type(error.ptr());
  const auto no_parts = std::vector<std::string>{};
  m.def("run", &run, py::arg("spec"), py::kw_only(), py::arg("direction") = py::none(),
        py::arg("engine") = "auto", py::arg("worst") = false, py::arg("wave") = "thinned",
        py::arg("parts") = no_parts, doc::kRun);
  m.def("worst", &worst, py::arg("spec"), py::kw_only(), py::arg("direction") = py::none(),
        py::arg("edge_engine") = "auto", py::arg("parts") = no_parts, doc::kWorst);
  m.def("noise", &noise, py::arg("spec"), py::kw_only(), py::arg("parts") = no_parts, doc::kNoise);
  m.def("stress", &stress, py::arg("spec"), py::kw_only(), py::arg("only") = no_parts,
        py::arg("parts") = no_parts, doc::kStress);
  m.def("sim", &sim, py::arg("netlist"), py::arg("probes"), py::kw_only(),
        py::arg("engine") = "auto", py::arg("step") = py::none(), py::arg("tstop") = py::none(),
        py::arg("tmax") = py::none(), py::arg("method") = py::none(),
        py::arg("reltol") = py::none(), doc::kSim);
  m.def("compare", &compare, py::arg("capture"), py::arg("spec"), py::kw_only(),
        py::arg("direction") = "down", py::arg("fit") = std::vector<std::string>{},
        py::arg("bounds") = py::dict(), py::arg("frames") = "", py::arg("p") = "",
        py::arg("n") = "", py::arg("diff") = "", py::arg("parts") = std::vector<std::string>{},
        "Compare a scope capture with the link spec's simulation of the same traffic, as "
        "`isolink compare --json`.\n\n"
        "Args:\n"
        "    capture: a list of file paths: one capture, or the P and N files.\n"
        "    spec: the link spec's path (YAML).\n"
        "    direction: 'down' or 'up', the receiver that was probed.\n"
        "    fit: link-spec keys to fit, dotted as in sweeps ('rx.isolation.cap').\n"
        "    bounds: {key: (low, high)} in SI units (default 0.2x-5x the design value).\n"
        "    frames: traffic when nothing decodes (a stimulus script, as --frames).\n"
        "    p, n, diff: the capture's column names, as check's --p/--n/--diff.\n"
        "    parts: extra part-library folders.\n\n"
        "Returns:\n"
        "    dict: verdict, direction, offset_s, residual {rms_v, max_v}, fit {key: {value, "
        "initial, low, high, stderr}}, residual_after_fit, findings [...], in SI units.");
  m.def("sweep", &sweep, py::arg("sweep"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("jobs") = 0, py::arg("engine") = "auto", py::arg("parts") = no_parts, doc::kSweep);
  m.def("pack", &pack, py::arg("pack_spec"), py::kw_only(), py::arg("jobs") = 0,
        py::arg("worst") = true, py::arg("parts") = no_parts, doc::kPack);
  m.def("check", &check, py::arg("t"), py::arg("v"), py::kw_only(), py::arg("rules") = "bq7961x",
        py::arg("expect") = py::none(), doc::kCheck);
  m.def("load_spec", &load_spec, py::arg("spec"), doc::kLoadSpec);
}
