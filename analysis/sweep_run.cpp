#include "analysis/sweep_run.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include "base/csv.h"
#include "base/file_io.h"

namespace isolink::analysis::sweep {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The columns after the point's own: verdict .. fail_reason, [the noise columns], seconds, error,
// path.
const std::vector<std::string> kResultColumns = {
    "verdict",         "worst_metric",  "worst_margin_rel",
    "margin_vstart_V", "margin_vend_V", "margin_width_ns",
    "margin_edge_ns",  "decoded_ok",    "fail_reason",
    "seconds",         "error",         "path"};
constexpr size_t kBeforeNoise = 9;  // verdict .. fail_reason
const std::vector<std::string> kNoiseColumns = {"noise.verdict",
                                                "noise.immunity_min_db",
                                                "noise.down.immunity_min",
                                                "noise.down.immunity_min_db",
                                                "noise.down.freq_hz",
                                                "noise.up.immunity_min",
                                                "noise.up.immunity_min_db",
                                                "noise.up.freq_hz"};
// Scale of each kMetrics margin in the CSV (V, V, ns, ns).
constexpr std::array<double, 4> kCsvScale = {1.0, 1.0, 1e9, 1e9};
// The same for each kWorstMetrics margin (V, V, ns, ns, ns) and the units the columns name.
constexpr std::array<double, 5> kWorstCsvScale = {1.0, 1.0, 1e9, 1e9, 1e9};
constexpr std::array<const char*, 5> kWorstCsvUnit = {"V", "V", "ns", "ns", "ns"};
constexpr std::array<const char*, 2> kDirections = {"down", "up"};  // by link::Direction

// worst.verdict, worst.worst_metric, worst.margin_rel, worst.<dir>.<metric>_margin_<unit>.
std::vector<std::string> worst_columns() {
  std::vector<std::string> c = {"worst.verdict", "worst.worst_metric", "worst.margin_rel"};
  for (const char* d : kDirections)
    for (size_t m = 0; m < kWorstMetrics.size(); ++m)
      c.push_back(fmt::format("worst.{}.{}_margin_{}", d, kWorstMetrics[m], kWorstCsvUnit[m]));
  return c;
}
const std::vector<std::string> kWorstColumns = worst_columns();
const std::vector<std::string> kStressColumns = {
    "stress.verdict",  "stress.scenarios",   "stress.breaking",    "stress.max_pin_V",
    "stress.max_cm_V", "stress.max_diode_A", "stress.first_broken"};

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// One line per CSV record (results.csv is read back line by line on --resume).
std::string cell(const std::string& s) {
  std::string flat = s;
  for (char& c : flat)
    if (c == '\n' || c == '\r') c = ' ';
  return csv_field(flat);
}

std::string num(double v) {
  return std::isnan(v) ? "" : fmt::format("{:.6g}", v);
}

bool parse_double(const std::string& s, double* out) {
  if (s.empty()) {
    *out = kNaN;
    return true;
  }
  char* end = nullptr;
  *out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0';
}

std::string first_line(const std::string& s) {
  return s.substr(0, s.find('\n'));
}

// A count written by results_row ("" when the point has none).
bool parse_count(const std::string& s, int* out) {
  if (s.empty()) return (*out = 0, true);
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  *out = static_cast<int>(v);
  return end != s.c_str() && *end == '\0' && v >= 0 && v < (1L << 30);
}

// The stress.* fields from f[*k] on (results_row's order), into r->stress.
Status parse_stress_cells(const std::vector<std::string>& f, size_t* k, PointResult* r) {
  PointResult::Stress st;
  st.verdict = f[(*k)++];
  if (st.verdict != "pass" && st.verdict != "fail" && !st.verdict.empty())
    return Status::Error("stress.verdict is not pass, fail or empty: '" + st.verdict + "'");
  bool ok = parse_count(f[(*k)++], &st.scenarios);
  ok = parse_count(f[(*k)++], &st.breaking) && ok;
  ok = parse_double(f[(*k)++], &st.max_pin_v) && ok;
  ok = parse_double(f[(*k)++], &st.max_cm_v) && ok;
  ok = parse_double(f[(*k)++], &st.max_diode_a) && ok;
  st.first_broken = f[(*k)++];
  if (!ok) return Status::Error("bad stress column");
  r->stress = st;
  return Status::Ok();
}

}  // namespace

std::vector<std::string> results_header(const SweepSpec& s) {
  std::vector<std::string> h{"point"};
  for (const std::string& c : s.point_columns()) h.push_back(c);
  h.insert(h.end(), kResultColumns.begin(), kResultColumns.begin() + kBeforeNoise);
  if (s.noise_outputs) h.insert(h.end(), kNoiseColumns.begin(), kNoiseColumns.end());
  if (s.worst_outputs) h.insert(h.end(), kWorstColumns.begin(), kWorstColumns.end());
  if (s.stress_outputs) h.insert(h.end(), kStressColumns.begin(), kStressColumns.end());
  h.insert(h.end(), kResultColumns.begin() + kBeforeNoise, kResultColumns.end());
  for (const std::string& c : pack_columns(s)) h.push_back(c);
  return h;
}

size_t RowShape::columns() const {
  return 1 + cells + kResultColumns.size() + (noise ? kNoiseColumns.size() : 0) +
         (worst ? kWorstColumns.size() : 0) + (stress ? kStressColumns.size() : 0) + extra;
}

RowShape row_shape(const SweepSpec& s) {
  return {.cells = s.point_columns().size(),
          .noise = s.noise_outputs,
          .worst = s.worst_outputs,
          .stress = s.stress_outputs,
          .extra = pack_columns(s).size()};
}

std::vector<std::string> pack_columns(const SweepSpec& s) {
  if (!s.pack) return {};
  std::vector<std::string> c{"weakest_hop", "failing_hops"};
  for (int k = 1; k <= s.pack_hops; ++k) c.push_back(fmt::format("hop_{}_margin_rel", k));
  return c;
}

PointResult score_pack(const PackResult& p) {
  PointResult r;
  if (p.weakest > 0) r = score_run(p.hops[static_cast<size_t>(p.weakest - 1)].run);
  r.verdict = p.pass ? "pass" : "fail";
  r.path = "simulated: a pack (every hop simulated)";
  r.decoded_ok.reset();
  r.reason.clear();
  std::string failing;
  for (const HopResult& h : p.hops) {
    const PointResult hr = score_run(h.run);
    if (hr.decoded_ok) r.decoded_ok = r.decoded_ok.value_or(true) && *hr.decoded_ok;
    if (h.pass) continue;
    r.reason += fmt::format("{}hop {}: {}", r.reason.empty() ? "" : "; ", h.index, hr.reason);
    failing += fmt::format("{}{}", failing.empty() ? "" : " ", h.index);
  }
  r.extra = {fmt::format("{}", p.weakest), failing};
  for (const HopResult& h : p.hops) r.extra.push_back(num(h.worst_rel));
  r.seconds = p.seconds;
  return r;
}

std::string results_row(const PointResult& r) {
  std::string line = fmt::format("{}", r.index);
  auto add = [&line](const std::string& f) { line += "," + cell(f); };
  for (const std::string& c : r.cells) add(c);
  add(r.verdict);
  add(r.worst_metric);
  add(num(r.worst_rel));
  for (size_t m = 0; m < kMetrics.size(); ++m) add(num(r.margin[m] * kCsvScale[m]));
  add(r.decoded_ok ? (*r.decoded_ok ? "true" : "false") : "");
  add(r.reason);
  if (r.noise) {
    const PointResult::Noise& n = *r.noise;
    add(n.verdict);
    add(num(n.immunity_min_db));
    for (size_t d = 0; d < 2; ++d) {
      add(num(n.immunity_min[d]));
      add(num(n.immunity_min_db_dir[d]));
      add(num(n.freq_hz[d]));
    }
  }
  if (r.worst) {
    const PointResult::Worst& w = *r.worst;
    add(w.verdict);
    add(w.worst_metric);
    add(num(w.margin_rel));
    for (size_t d = 0; d < 2; ++d)
      for (size_t m = 0; m < kWorstMetrics.size(); ++m)
        add(num(w.margin[d][m] * kWorstCsvScale[m]));
  }
  if (r.stress) {
    const PointResult::Stress& st = *r.stress;
    add(st.verdict);
    add(st.verdict.empty() ? "" : fmt::format("{}", st.scenarios));
    add(st.verdict.empty() ? "" : fmt::format("{}", st.breaking));
    add(num(st.max_pin_v));
    add(num(st.max_cm_v));
    add(num(st.max_diode_a));
    add(st.first_broken);
  }
  add(fmt::format("{:.2f}", r.seconds));
  add(r.error);
  add(r.path);
  for (const std::string& c : r.extra) add(c);
  return line + "\n";
}

StatusOr<PointResult> parse_results_row(std::string_view line, const RowShape& shape) {
  const std::vector<std::string> f = split_csv_line(line);
  if (f.size() != shape.columns())
    return Status::Error(fmt::format("{} fields, expected {}", f.size(), shape.columns()));
  PointResult r;
  char* end = nullptr;
  const unsigned long long idx = std::strtoull(f[0].c_str(), &end, 10);
  if (f[0].empty() || *end != '\0') return Status::Error("point is not a number: '" + f[0] + "'");
  r.index = static_cast<size_t>(idx);
  size_t k = 1;
  for (size_t i = 0; i < shape.cells; ++i) r.cells.push_back(f[k++]);
  r.verdict = f[k++];
  if (r.verdict != "pass" && r.verdict != "fail" && r.verdict != "error")
    return Status::Error("verdict is not pass, fail or error: '" + r.verdict + "'");
  r.worst_metric = f[k++];
  if (!parse_double(f[k++], &r.worst_rel)) return Status::Error("bad worst_margin_rel");
  for (size_t m = 0; m < kMetrics.size(); ++m) {
    double v = 0;
    if (!parse_double(f[k++], &v)) return Status::Error("bad margin");
    r.margin[m] = v / kCsvScale[m];
  }
  const std::string& d = f[k++];
  if (d == "true") r.decoded_ok = true;
  if (d == "false") r.decoded_ok = false;
  r.reason = f[k++];
  if (shape.noise) {
    PointResult::Noise n;
    n.verdict = f[k++];
    if (n.verdict != "pass" && n.verdict != "fail" && !n.verdict.empty())
      return Status::Error("noise.verdict is not pass, fail or empty: '" + n.verdict + "'");
    bool ok = parse_double(f[k++], &n.immunity_min_db);
    for (size_t dir = 0; dir < 2; ++dir) {
      ok = parse_double(f[k++], &n.immunity_min[dir]) && ok;
      ok = parse_double(f[k++], &n.immunity_min_db_dir[dir]) && ok;
      ok = parse_double(f[k++], &n.freq_hz[dir]) && ok;
    }
    if (!ok) return Status::Error("bad noise column");
    r.noise = n;
  }
  if (shape.worst) {
    PointResult::Worst w;
    w.verdict = f[k++];
    if (w.verdict != "pass" && w.verdict != "fail" && !w.verdict.empty())
      return Status::Error("worst.verdict is not pass, fail or empty: '" + w.verdict + "'");
    w.worst_metric = f[k++];
    if (!w.worst_metric.empty() &&
        std::find_if(kWorstMetrics.begin(), kWorstMetrics.end(),
                     [&](const char* m) { return w.worst_metric == m; }) == kWorstMetrics.end())
      return Status::Error("worst.worst_metric is not a worst-case metric: '" + w.worst_metric +
                           "'");
    bool ok = parse_double(f[k++], &w.margin_rel);
    for (size_t dir = 0; dir < 2; ++dir)
      for (size_t m = 0; m < kWorstMetrics.size(); ++m) {
        double v = 0;
        ok = parse_double(f[k++], &v) && ok;
        w.margin[dir][m] = v / kWorstCsvScale[m];
      }
    if (!ok) return Status::Error("bad worst column");
    r.worst = w;
  }
  if (shape.stress) {
    if (Status st = parse_stress_cells(f, &k, &r); !st.ok()) return st;
  }
  if (!parse_double(f[k++], &r.seconds)) return Status::Error("bad seconds");
  if (std::isnan(r.seconds)) r.seconds = 0;
  r.error = f[k++];
  r.path = f[k++];
  r.extra.assign(f.begin() + static_cast<long>(k), f.end());
  return r;
}

PointResult round_trip(const PointResult& r, const RowShape& shape) {
  std::string row = results_row(r);
  row.pop_back();
  StatusOr<PointResult> p = parse_results_row(row, shape);
  return p ? *p : r;
}

PointResult score_run(const LinkRun& run) {
  PointResult r;
  r.verdict = run.pass ? "pass" : "fail";
  r.seconds = run.seconds;
  std::array<std::optional<eye::Judged>, 4> worst;
  bool any_data = false, decoded = true;
  std::vector<std::string> reasons;
  auto reason = [&reasons](const std::string& why) {
    if (std::find(reasons.begin(), reasons.end(), why) == reasons.end()) reasons.push_back(why);
  };
  for (const DirectionRun& d : run.directions) {
    for (const std::optional<eye::CheckResult>* c : {&d.data, &d.tones}) {
      if (!c->has_value()) continue;
      const eye::CheckResult& cr = **c;
      if (!cr.pass) {
        if (cr.pulses.empty()) reason("no signal");
        for (const eye::PulseMetrics& p : cr.pulses)
          for (const std::string& f : p.fails) reason(f.substr(0, f.find(':')));
        for (const eye::FrameResult& f : cr.frames)
          if (f.fails()) reason("decode: " + f.fault);
        if (!cr.expect_match) reason("bytes differ");
      }
      for (const eye::WorstMargin& w : (*c)->worst) {
        if (!w.j.judged()) continue;
        for (size_t m = 0; m < kMetrics.size(); ++m)
          if (w.metric == kMetrics[m] && (!worst[m] || w.j.margin < worst[m]->margin))
            worst[m] = w.j;
      }
    }
    if (d.data) {
      any_data = true;
      bool frames_ok = !d.data->frames.empty() && d.data->expect_match;
      for (const eye::FrameResult& f : d.data->frames) frames_ok = frames_ok && !f.fails();
      decoded = decoded && frames_ok;
    }
  }
  if (any_data) r.decoded_ok = decoded;
  for (const std::string& why : reasons) r.reason += (r.reason.empty() ? "" : "; ") + why;
  for (size_t m = 0; m < kMetrics.size(); ++m) {
    if (!worst[m]) continue;
    r.margin[m] = worst[m]->margin;
    const double lim = std::abs(worst[m]->limit);
    const double rel = lim > 0 ? worst[m]->margin / lim : kNaN;
    if (!std::isnan(rel) && (std::isnan(r.worst_rel) || rel < r.worst_rel)) {
      r.worst_rel = rel;
      r.worst_metric = kMetrics[m];
    }
  }
  if (r.worst_metric.empty()) {
    r.worst_metric = "none";
    if (!run.pass) r.worst_rel = -1.0;
  }
  return r;
}

PointResult::Noise noise_cells(const NoiseResult& r) {
  PointResult::Noise n;
  n.verdict = r.pass ? "pass" : "fail";
  n.immunity_min_db = noise_immunity_min_db(r);
  for (const NoiseDirection& d : r.directions) {
    const size_t k = d.direction == link::Direction::kDown ? 0 : 1;
    const VerdictImmunity v = verdict_immunity(d, r.spec);
    n.immunity_min[k] = v.value;
    n.immunity_min_db_dir[k] = 20 * std::log10(std::max(v.value / r.spec.level, 1e-20));
    n.freq_hz[k] = v.freq_hz;
  }
  return n;
}

PointResult::Worst worst_cells(const WorstResult& r) {
  PointResult::Worst w;
  w.verdict = r.pass ? "pass" : "fail";
  for (const DirectionWorst& d : r.directions) {
    const size_t k = d.direction == link::Direction::kDown ? 0 : 1;
    for (size_t m = 0; m < kWorstMetrics.size(); ++m) {
      const WorstMetric* wm = d.metric(kWorstMetrics[m]);
      if (!wm || !std::isfinite(wm->margin)) continue;
      w.margin[k][m] = wm->margin;
      // The smallest margin / |limit|, as score_run's worst_margin_rel.
      const double lim = std::abs(wm->limit);
      const double rel = lim > 0 ? wm->margin / lim : kNaN;
      if (std::isfinite(rel) && (std::isnan(w.margin_rel) || rel < w.margin_rel)) {
        w.margin_rel = rel;
        w.worst_metric = kWorstMetrics[m];
      }
    }
  }
  return w;
}

PointResult::Stress stress_cells(const StressResult& r) {
  PointResult::Stress st;
  st.scenarios = static_cast<int>(r.scenarios.size());
  auto grow = [](double& to, double v) {
    if (std::isfinite(v) && (std::isnan(to) || std::abs(v) > to)) to = std::abs(v);
  };
  for (const StressScenario& s : r.scenarios) {
    for (const auto& [node, p] : s.peak_pin_v) grow(st.max_pin_v, std::max(-p.min, p.max));
    grow(st.max_cm_v, s.peak_cm_v);
    for (const DiodePeak& d : s.diodes) grow(st.max_diode_a, d.peak_a);
    if (s.broken.empty()) continue;
    if (st.breaking++ == 0) st.first_broken = s.id + ": " + s.broken.front();
  }
  st.verdict = st.breaking == 0 ? "pass" : "fail";
  return st;
}

namespace {

// Why a point must be simulated rather than synthesized from its edge responses, or empty.
std::string fast_path_refused(const link::LinkSpec& spec, const PointOptions& opt, double dt) {
  if (opt.simulate) return "--simulate";
  if (opt.run.engine == Engine::Transient) return "--engine transient";
  if (!link::nonlinear_parts(spec).empty()) return "nonlinear link (superposition does not hold)";
  // Waveform files at sim.tstep: the synthesis grid (dt) resampled, exact on a multiple of it.
  const double k = spec.sim.tstep / dt;
  if (!opt.waves_dir.empty() && (k < 1 - 1e-9 || std::abs(k - std::round(k)) > 1e-6))
    return fmt::format(
        "waveform files at sim.tstep {:g} ns (not a multiple of the {:g} ns grid "
        "of the edge response)",
        spec.sim.tstep * 1e9, dt * 1e9);
  return "";
}

// The options of a point's edge responses: the run's expansion, the probes its noise analysis
// and waveform files read, the sweep's start points.
WorstOptions point_worst_options(const SweepSpec& s, const PointOptions& opt) {
  WorstOptions wopt;
  wopt.expand = opt.run.expand;
  if (s.noise_outputs || !opt.waves_dir.empty())  // they read the pins (and the files the driver)
    wopt.more_probes.assign(run_probes().begin() + 1, run_probes().end());
  wopt.reduced_start_points_by_direction = opt.start_points;
  return wopt;
}

}  // namespace

std::map<link::Direction, std::vector<double>> sweep_start_points(const SweepSpec& s,
                                                                  const link::PartLibrary& parts,
                                                                  const PointOptions& opt) {
  std::map<link::Direction, std::vector<double>> out;
  PointOutcome po = make_point(s, 0);
  if (!po.status.ok() || po.point.pack) return out;
  WorstOptions fine = point_worst_options(s, opt);
  fine.dt /= kSynthesisOversample;
  if (!fast_path_refused(po.point.spec, opt, fine.dt).empty()) return out;
  // One edge response per distinct circuit (a symmetric link's second direction takes the
  // first's points, as run_link reuses its response), computed in parallel in the caller's
  // task arena: on the asymmetric bridge-to-stack sweep they were 0.2 s of one core while the
  // other waited, 2 % of a 64-point sweep.
  std::map<std::string, link::Direction> done;  // link::circuit_key -> the direction computed
  std::vector<std::pair<link::Direction, link::Direction>> copies;  // (direction, same as)
  std::vector<link::Direction> fresh_directions;
  for (link::Direction d : po.point.spec.stimulus.directions) {
    StatusOr<link::ExpandedLink> ex = link::expand_link(po.point.spec, parts, d, opt.run.expand);
    if (!ex) continue;
    const auto [same, fresh] = done.emplace(link::circuit_key(*ex), d);
    if (fresh)
      fresh_directions.push_back(d);
    else if (same->second != d)
      copies.emplace_back(d, same->second);
  }
  std::vector<std::vector<double>> points(fresh_directions.size());
  tbb::parallel_for(size_t{0}, fresh_directions.size(), [&](size_t i) {
    StatusOr<EdgeResponse> e = edge_response(po.point.spec, parts, fresh_directions[i], fine);
    if (e) points[i] = e->expansion_points;
  });
  for (size_t i = 0; i < fresh_directions.size(); ++i)
    if (!points[i].empty()) out[fresh_directions[i]] = points[i];
  for (const auto& [d, same] : copies)
    if (out.count(same)) out[d] = out[same];
  return out;
}

PointResult run_point(const SweepSpec& s, const link::PartLibrary& parts, size_t index,
                      const PointOptions& opt) {
  const double t0 = now_seconds();
  PointResult r;
  r.index = index;
  auto fail = [&](const std::string& message) {
    r.verdict = "error";
    r.worst_metric.clear();
    r.worst_rel = kNaN;
    r.margin.fill(kNaN);
    r.decoded_ok.reset();
    r.reason.clear();
    r.error = first_line(message);
    r.path.clear();
    r.noise.reset();
    if (s.noise_outputs) r.noise.emplace();
    r.worst.reset();
    if (s.worst_outputs) r.worst.emplace();
    r.stress.reset();
    if (s.stress_outputs) r.stress.emplace();
    r.extra.clear();
    r.seconds = now_seconds() - t0;
    return r;
  };
  try {
    PointOutcome po = make_point(s, index);
    r.cells = po.point.cells;
    if (!po.status.ok()) return fail(po.status.message());
    if (po.point.pack) {
      PackOptions popt;
      popt.run = opt.run;
      StatusOr<PackResult> pr = run_pack(*po.point.pack, parts, popt);
      if (!pr) return fail(pr.status().message());
      std::vector<std::string> cells = std::move(r.cells);
      r = score_pack(*pr);
      r.index = index;
      r.cells = std::move(cells);
      for (size_t k = 0; k < pr->hops.size() && !opt.waves_dir.empty(); ++k) {
        const HopResult& h = pr->hops[k];
        const Waveform w = run_waveforms(h.run, po.point.pack->hops[k].spec.sim.tstep);
        const std::string path =
            fmt::format("{}/point_{:05}_hop_{:02}.csv", opt.waves_dir, index, h.index);
        if (Status st = write_waveform_csv(w, path); !st.ok()) return fail(st.message());
      }
      r.seconds = now_seconds() - t0;
      return r;
    }
    // The fast path (analysis/README.md "The sweep's fast path"): each direction's edge
    // response gives the spec traffic's waveform and serves the worst case.
    const WorstOptions wopt = point_worst_options(s, opt);
    const std::string simulate_why =
        fast_path_refused(po.point.spec, opt, wopt.dt / kSynthesisOversample);
    std::vector<EdgeResponse> edges;
    StatusOr<LinkRun> run = simulate_why.empty()
                                ? run_link_from_edges(po.point.spec, parts, opt.run, wopt,
                                                      s.worst_outputs ? &edges : nullptr)
                                : run_link(po.point.spec, parts, opt.run);
    if (!run) return fail(run.status().message());
    std::vector<std::string> cells = std::move(r.cells);
    r = score_run(*run);
    r.index = index;
    r.cells = std::move(cells);
    const std::string note = simulate_why.empty() ? simulated_note(*run) : simulate_why;
    r.path = note.empty() ? "edges" : "simulated: " + note;
    if (s.noise_outputs) {
      StatusOr<NoiseResult> noise = analyze_noise_of_run(po.point.spec, parts, *run);
      if (!noise) return fail("noise: " + noise.status().message());
      r.noise = noise_cells(*noise);
    }
    if (s.worst_outputs) {
      // The default options, as `isolink run` and `isolink worst` use, on the run's expansion.
      StatusOr<WorstResult> w =
          worst_case(po.point.spec, parts, wopt, std::move(edges), same_circuits(*run));
      if (!w) return fail("worst: " + w.status().message());
      r.worst = worst_cells(*w);
    }
    if (s.stress_outputs) {
      StatusOr<StressResult> st = run_stress(po.point.spec, parts, StressOptions{});
      if (!st) return fail("stress: " + st.status().message());
      r.stress = stress_cells(*st);
    }
    if (!opt.waves_dir.empty()) {
      const Waveform w = run_waveforms(*run, po.point.spec.sim.tstep);
      const std::string path = fmt::format("{}/point_{:05}.csv", opt.waves_dir, index);
      if (Status st = write_waveform_csv(w, path); !st.ok()) return fail(st.message());
    }
  } catch (const std::exception& e) {
    return fail(std::string("internal error: ") + e.what());
  }
  r.seconds = now_seconds() - t0;
  return r;
}

// --- results.csv -----------------------------------------------------------------------------

StatusOr<std::unique_ptr<ResultLog>> ResultLog::open(const SweepSpec& s, const SweepOptions& opt) {
  std::unique_ptr<ResultLog> log(new ResultLog());
  log->spec_ = &s;
  log->line_ = std::make_unique<ProgressLine>(
      ProgressLine::Options{.label = "sweep", .enabled = !opt.quiet, .pipe_interval = 5.0});
  log->total_ = s.size();
  log->have_.assign(log->total_, false);
  log->shape_ = row_shape(s);
  const std::vector<std::string> header = results_header(s);
  log->path_ = opt.out_dir + "/results.csv";
  std::string header_line;
  for (const std::string& h : header) header_line += (header_line.empty() ? "" : ",") + cell(h);
  header_line += "\n";

  std::string keep = header_line;
  if (opt.resume) {
    std::ifstream in(log->path_, std::ios::binary);
    if (in) {
      std::stringstream ss;
      ss << in.rdbuf();
      const std::string text = ss.str();
      size_t pos = 0, line_no = 0;
      while (pos < text.size()) {
        const size_t nl = text.find('\n', pos);
        if (nl == std::string::npos) break;  // a row cut short by a crash: run that point again
        const std::string line = text.substr(pos, nl - pos);
        pos = nl + 1;
        ++line_no;
        if (line_no == 1) {
          if (line + "\n" != header_line && line + "\r\n" != header_line)
            return Status::Error(fmt::format(
                "{}:1: error: --resume: the columns differ from this sweep's ({}); was it written "
                "by another sweep file?",
                log->path_, header_line.substr(0, header_line.size() - 1)));
          continue;
        }
        if (line.empty()) continue;
        StatusOr<PointResult> r = parse_results_row(line, log->shape_);
        if (!r)
          return Status::Error(fmt::format("{}:{}: error: --resume: cannot read the row: {}",
                                           log->path_, line_no, r.status().message()));
        if (r->index >= log->total_ || log->have_[r->index]) continue;
        // The row must describe the same point (the sweep file may have been edited since).
        const std::vector<std::string> cells = make_point(s, r->index).point.cells;
        if (cells != r->cells) {
          std::string want, have;
          for (const std::string& c : cells) want += (want.empty() ? "" : ",") + c;
          for (const std::string& c : r->cells) have += (have.empty() ? "" : ",") + c;
          return Status::Error(fmt::format(
              "{}:{}: error: --resume: point {} is {} in this sweep but {} in the file; was the "
              "sweep file changed? (start again without --resume)",
              log->path_, line_no, r->index, want, have));
        }
        log->have_[r->index] = true;
        log->results_.push_back(*r);
        keep += line + "\n";
        if (r->verdict == "pass") ++log->pass_;
        if (r->verdict == "fail") ++log->fail_;
        if (r->verdict == "error") ++log->error_;
      }
    }
  }
  log->skipped_ = log->results_.size();
  log->todo_count_ = log->total_ - log->skipped_;
  // The kept rows (or just the header) through a temporary file, then appended to.
  if (Status st = write_file_atomic(log->path_, keep); !st.ok()) return st;
  log->file_ = std::fopen(log->path_.c_str(), "ab");
  if (!log->file_)
    return Status::Error(fmt::format("{}: error: cannot open for appending", log->path_));
  return log;
}

ResultLog::~ResultLog() {
  if (file_) std::fclose(file_);
}

std::vector<size_t> ResultLog::todo() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<size_t> t;
  for (size_t i = 0; i < total_; ++i)
    if (!have_[i]) t.push_back(i);
  return t;
}

void ResultLog::add(const PointResult& in) {
  PointResult padded = in;
  padded.cells.resize(shape_.cells);  // a point that failed before its cells were known
  if (shape_.noise && !padded.noise) padded.noise.emplace();
  if (!shape_.noise) padded.noise.reset();
  if (shape_.worst && !padded.worst) padded.worst.emplace();
  if (!shape_.worst) padded.worst.reset();
  if (shape_.stress && !padded.stress) padded.stress.emplace();
  if (!shape_.stress) padded.stress.reset();
  padded.extra.resize(shape_.extra);  // an error's: empty
  const PointResult r = round_trip(padded, shape_);
  const std::string row = results_row(r);
  std::lock_guard<std::mutex> lock(mu_);
  if (r.index >= total_ || have_[r.index] || !write_error_.ok()) return;
  // Checked: a row the disk did not take is not counted, and the sweep stops (status()).
  if (std::fputs(row.c_str(), file_) < 0 || std::fflush(file_) != 0) {
    const int err = errno;
    write_error_ = Status::Error(fmt::format(
        "{}: error: cannot append the row of point {}: {}; {} of {} points are recorded: free "
        "some space and run again with --resume",
        path_, r.index, std::error_code(err, std::generic_category()).message(),
        skipped_ + done_now_, total_));
    return;
  }
  have_[r.index] = true;
  results_.push_back(r);
  ++done_now_;
  if (r.verdict == "pass") ++pass_;
  if (r.verdict == "fail") ++fail_;
  if (r.verdict == "error") ++error_;
  progress(r);
}

void ResultLog::progress(const PointResult& r) {
  if (r.verdict == "error" && line_->active())
    line_->note(fmt::format("sweep: point {}: error: {}", r.index, r.error));
  const bool last = done_now_ == todo_count_;
  const double elapsed = line_->elapsed();
  const double rate = elapsed > 0 ? done_now_ / elapsed * 60.0 : 0.0;
  const double left = done_now_ > 0 ? elapsed / done_now_ * (todo_count_ - done_now_) : kNaN;
  const std::string line = fmt::format(
      "{}/{} points ({} pass, {} fail, {} error), {:.1f} points/min, {}", skipped_ + done_now_,
      total_, pass_, fail_, error_, rate,
      last ? "done in " + duration_text(elapsed) : "about " + duration_text(left) + " left");
  if (last)
    line_->done(line);
  else
    line_->show(line);
}

std::vector<PointResult> ResultLog::results() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<PointResult> out = results_;
  std::sort(out.begin(), out.end(),
            [](const PointResult& a, const PointResult& b) { return a.index < b.index; });
  return out;
}

std::vector<size_t> varying_axes(const SweepSpec& s) {
  std::vector<size_t> v;
  for (size_t k = 0; k < s.axes.size(); ++k)
    if (s.axes[k].values.size() > 1) v.push_back(k);
  return v;
}

void finish_sweep(const SweepSpec& s, std::vector<PointResult> results, SweepOutcome* out) {
  out->points = s.size();
  out->pass = out->fail = out->error = 0;
  for (const PointResult& r : results) {
    out->pass += r.verdict == "pass";
    out->fail += r.verdict == "fail";
    out->error += r.verdict == "error";
  }
  out->files.push_back("results.csv");
  out->results = std::move(results);
}

StatusOr<SweepOutcome> run_sweep(const SweepSpec& s, const link::PartLibrary& parts,
                                 const SweepOptions& opt_in) {
  const double t0 = now_seconds();
  SweepOptions opt = opt_in;
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (ec)
    return Status::Error(
        fmt::format("{}: error: cannot create the folder: {}", opt.out_dir, ec.message()));
  if (opt.keep_waves) {
    opt.point.waves_dir = opt.out_dir + "/waves";
    std::filesystem::create_directories(opt.point.waves_dir, ec);
    if (ec)
      return Status::Error(fmt::format("{}: error: cannot create the folder: {}",
                                       opt.point.waves_dir, ec.message()));
  }
  StatusOr<std::unique_ptr<ResultLog>> log = ResultLog::open(s, opt);
  if (!log) return log.status();
  ResultLog& L = **log;
  const std::vector<size_t> todo = L.todo();
  const int threads = opt.jobs > 0 ? opt.jobs : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.initialize();  // loads oneTBB's allocator and thread-pool libraries
  if (!todo.empty() && opt.point.start_points.empty())  // on the sweep's threads
    arena.execute([&] { opt.point.start_points = sweep_start_points(s, parts, opt.point); });
  if (opt.on_pool_ready) opt.on_pool_ready();
  arena.execute([&] {
    // One task per point (grain 1): points take seconds, so scheduling costs nothing, and a
    // thread only ever holds the point it is running.
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, todo.size(), 1),
        [&](const tbb::blocked_range<size_t>& range) {
          for (size_t i = range.begin(); i != range.end(); ++i)
            if (L.status().ok()) L.add(run_point(s, parts, todo[i], opt.point));
        },
        tbb::simple_partitioner());
  });
  if (Status st = L.status(); !st.ok()) return st;
  SweepOutcome out;
  out.skipped = L.skipped();
  finish_sweep(s, L.results(), &out);
  out.seconds = now_seconds() - t0;
  return out;
}

}  // namespace isolink::analysis::sweep
