#include "analysis/link_run.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <limits>
#include <optional>
#include <span>

namespace isolink::analysis {

namespace {

// Samples of column 0 kept (keep = true) or dropped by time windows [a, b).
void filter(const Waveform& w, const std::vector<std::pair<double, double>>& windows, bool inside,
            std::vector<double>& t, std::vector<double>& v) {
  t.clear(), v.clear();
  const std::vector<double>& col = w.columns[0];
  if (windows.empty()) {  // data without tones: every sample kept, none for the tone check
    if (!inside) t = w.time, v = col;
    return;
  }
  // One pass: the windows sorted by start, and the latest end among those started so far (they
  // may overlap), so the cost is samples + windows, not their product.
  std::vector<std::pair<double, double>> sorted = windows;
  std::sort(sorted.begin(), sorted.end());
  size_t k = 0;
  double reach = -std::numeric_limits<double>::infinity();  // end of the windows started
  for (size_t i = 0; i < w.time.size(); ++i) {
    while (k < sorted.size() && sorted[k].first <= w.time[i])
      reach = std::max(reach, sorted[k++].second);
    const bool in = w.time[i] < reach;
    if (in == inside) t.push_back(w.time[i]), v.push_back(col[i]);
  }
}

}  // namespace

const std::vector<std::string>& run_probes() {
  static const std::vector<std::string> probes{"v(rxp,rxn)", "v(rxp)", "v(rxn)", "v(txp,txn)"};
  return probes;
}

StatusOr<DirectionRun> run_direction(link::ExpandedLink link, const RunOptions& opt) {
  DirectionRun dr;
  dr.link = std::move(link);
  SimulationRequest req;
  req.probes = run_probes();
  req.reltol = opt.reltol;
  req.engine = opt.engine;
  req.record_tol = opt.record_tol;
  req.lti_threads = opt.threads;
  req.record_full_rows = opt.record_full_rows;
  // The LTI grid follows the receiver probes; v(txp,txn) is the ideal PWL drive, whose corners
  // a uniform grid could only meet within 1 mV at a few ps (it is only plotted).
  req.grid_probes = {true, true, true, false};
  if (opt.progress)
    req.progress = [&](const char* phase, double fraction) {
      opt.progress(fmt::format("{} {}", link::direction_name(dr.link.direction), phase), fraction);
    };
  StatusOr<SimulationResult> sim = simulate_netlist(dr.link.netlist, req);
  if (!sim) return sim.status().with_context(dr.link.description);
  dr.sim = std::move(*sim);
  if (Status s = score_direction(dr); !s.ok()) return s;
  return dr;
}

StatusOr<DirectionRun> run_direction_synthesized(link::ExpandedLink link, const EdgeResponse& e) {
  DirectionRun dr;
  dr.link = std::move(link);
  const auto start = std::chrono::steady_clock::now();
  const double t_end = dr.link.netlist.tran ? dr.link.netlist.tran->tstop : 0.0;
  StatusOr<Waveform> w = synthesize_drive(e, dr.link.drive, t_end);
  if (!w) return w.status().with_context(dr.link.description);
  dr.sim.wave = std::move(*w);
  dr.sim.engine = Engine::Lti;
  dr.sim.engine_note = "synthesized from the edge response: " + e.engine;
  dr.sim.seconds =
      e.seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (Status s = score_direction(dr); !s.ok()) return s;
  return dr;
}

Status score_direction(DirectionRun& dr) {
  StatusOr<eye::Rules> rules = eye::load_rules(dr.link.rules);
  if (!rules) return rules.status();
  dr.rules = *rules;

  // Tone windows: from each tone's first edge to 4.5 us after its last (tblank + margin).
  std::vector<std::pair<double, double>> tone_windows;
  bool any_data = false;
  for (const traffic::DriveFrame& f : dr.link.drive.frames) {
    if (f.kind == traffic::FrameKind::kTone)
      tone_windows.push_back({f.start - 0.5e-6, f.end + 4.5e-6});
    else
      any_data = true;
  }
  std::vector<double> t, v;
  dr.pass = true;
  if (any_data) {
    // Without tones the data check reads the waveform itself (a long record is not copied).
    if (!tone_windows.empty()) filter(dr.sim.wave, tone_windows, false, t, v);
    const std::span<const double> dt = tone_windows.empty() ? dr.sim.wave.time : t;
    const std::span<const double> dv = tone_windows.empty() ? dr.sim.wave.columns[0] : v;
    eye::CheckOptions co;
    co.expect = dr.link.expected;
    StatusOr<eye::CheckResult> r = eye::check_samples(dt, dv, dr.rules, co);
    if (!r) return r.status().with_context(dr.link.description + ", data check");
    dr.data = std::move(*r);
    dr.pass = dr.pass && dr.data->pass;
  }
  if (!tone_windows.empty()) {
    StatusOr<eye::Rules> tone_rules = eye::load_rules("tone");
    if (!tone_rules) return tone_rules.status();
    dr.tone_rules = *tone_rules;
    filter(dr.sim.wave, tone_windows, true, t, v);
    StatusOr<eye::CheckResult> r = eye::check_samples(t, v, dr.tone_rules, {});
    if (!r) return r.status().with_context(dr.link.description + ", tone check");
    dr.tones = std::move(*r);
    dr.pass = dr.pass && dr.tones->pass;
  }
  return Status::Ok();
}

namespace {

// The directions of spec.stimulus.directions, each expanded and run by `one`; a direction with the
// same circuit key as one before (link::circuit_key) gets a copy of that result (same_as) and
// `copied(index of the original)` instead.
StatusOr<LinkRun> run_each_direction(
    const link::LinkSpec& spec, const link::PartLibrary& parts, const RunOptions& opt,
    const std::function<StatusOr<DirectionRun>(link::ExpandedLink, link::Direction)>& one,
    const std::function<void(size_t)>& copied) {
  LinkRun run;
  const auto start = std::chrono::steady_clock::now();
  run.pass = true;
  std::vector<std::string> keys;  // link::circuit_key per direction done
  for (link::Direction d : spec.stimulus.directions) {
    StatusOr<link::ExpandedLink> ex = link::expand_link(spec, parts, d, opt.expand);
    if (!ex) return ex.status();
    keys.push_back(link::circuit_key(*ex));
    const size_t same =
        static_cast<size_t>(std::find(keys.begin(), keys.end() - 1, keys.back()) - keys.begin());
    StatusOr<DirectionRun> dr = Status::Error("not run");
    if (same + 1 < keys.size()) {
      dr = run.directions[same];
      dr->same_as = link::direction_name(dr->link.direction);
      dr->link = std::move(*ex);
      dr->sim.seconds = 0;  // nothing computed for it
      copied(same);
    } else {
      dr = one(std::move(*ex), d);
      if (!dr) return dr.status();
    }
    run.pass = run.pass && dr->pass;
    run.directions.push_back(std::move(*dr));
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace

StatusOr<LinkRun> run_link(const link::LinkSpec& spec, const link::PartLibrary& parts,
                           const RunOptions& opt) {
  return run_each_direction(
      spec, parts, opt,
      [&](link::ExpandedLink ex, link::Direction) { return run_direction(std::move(ex), opt); },
      [](size_t) {});
}

namespace {

// Why the drive cannot be superposed on a grid of step dt: its first level change off the grid,
// or empty.
std::string off_grid_why(const traffic::Drive& drive, double dt) {
  for (const traffic::DriveSegment& g : drive.segments) {
    traffic::Drive one;
    one.segments = {g};
    if (!on_grid(one, dt))
      return fmt::format(
          "the drive changes level at {:.7g} us (off the {:g} ns grid of the edge response)",
          g.start * 1e6, dt * 1e9);
  }
  return "";
}

}  // namespace

StatusOr<LinkRun> run_link_from_edges(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                      const RunOptions& opt, const WorstOptions& wopt,
                                      std::vector<EdgeResponse>* edges) {
  WorstOptions fine = wopt;  // the synthesis grid
  fine.dt = wopt.dt / kSynthesisOversample;
  std::vector<std::optional<EdgeResponse>> per;  // per direction run so far, on wopt's grid
  StatusOr<LinkRun> run = run_each_direction(
      spec, parts, opt,
      [&](link::ExpandedLink ex, link::Direction d) -> StatusOr<DirectionRun> {
        per.emplace_back();
        std::string why = off_grid_why(ex.drive, fine.dt);
        if (why.empty()) {
          StatusOr<EdgeResponse> e = edge_response(spec, parts, d, fine);
          if (e) {
            StatusOr<DirectionRun> dr = run_direction_synthesized(std::move(ex), *e);
            if (edges) per.back() = coarsened(*e, kSynthesisOversample, wopt);
            return dr;
          }
          why = "edge response: " + e.status().message();
        }
        StatusOr<DirectionRun> dr = run_direction(std::move(ex), opt);
        if (dr) dr->simulated_why = std::move(why);
        return dr;
      },
      [&](size_t same) { per.push_back(per[same]); });
  if (!edges) return run;
  edges->clear();
  if (!run) return run;
  for (std::optional<EdgeResponse>& e : per) {
    if (!e) {
      edges->clear();
      break;
    }
    edges->push_back(std::move(*e));
  }
  return run;
}

std::string simulated_note(const LinkRun& run) {
  std::string note;
  for (const DirectionRun& d : run.directions)
    if (!d.simulated_why.empty() && d.same_as.empty())
      note +=
          fmt::format("{}{}: {}", note.empty() ? "" : "; ", link::direction_name(d.link.direction),
                      d.simulated_why.substr(0, d.simulated_why.find('\n')));
  return note;
}

std::vector<int> same_circuits(const LinkRun& run) {
  std::vector<int> same(run.directions.size(), -1);
  for (size_t d = 0; d < run.directions.size(); ++d) {
    if (run.directions[d].same_as.empty()) continue;
    for (size_t k = 0; k < d && same[d] < 0; ++k)
      if (run.directions[k].same_as.empty() &&
          link::direction_name(run.directions[k].link.direction) == run.directions[d].same_as)
        same[d] = static_cast<int>(k);
  }
  return same;
}

Waveform run_waveforms(const LinkRun& run, double dt) {
  Waveform out;
  std::vector<Waveform> parts;
  double t_end = 1e300;
  for (const DirectionRun& d : run.directions) {
    parts.push_back(d.sim.wave.resampled(dt));
    t_end = std::min(t_end, parts.back().time.empty() ? 0.0 : parts.back().time.back());
  }
  if (parts.empty()) return out;
  size_t n = 0;
  while (n < parts[0].time.size() && parts[0].time[n] <= t_end) ++n;
  out.time.assign(parts[0].time.begin(), parts[0].time.begin() + n);
  for (size_t k = 0; k < parts.size(); ++k) {
    const char* dir = link::direction_name(run.directions[k].link.direction);
    for (size_t c = 0; c < parts[k].columns.size(); ++c) {
      std::vector<double> col(parts[k].columns[c].begin(), parts[k].columns[c].begin() + n);
      out.add_column(fmt::format("{} {}", dir, parts[k].names[c]), std::move(col));
    }
  }
  return out;
}

}  // namespace isolink::analysis
