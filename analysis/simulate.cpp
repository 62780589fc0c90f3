#include "analysis/simulate.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <map>
#include <mutex>
#include <span>

#include "analysis/link_run_wave.h"
#include "solver/circuit.h"

namespace isolink::analysis {

const char* engine_name(Engine e) {
  switch (e) {
    case Engine::Auto:
      return "auto";
    case Engine::Lti:
      return "lti";
    case Engine::PortModel:
      return "port";
    case Engine::Transient:
      return "transient";
  }
  return "auto";
}

const char* engine_summary(Engine e) {
  switch (e) {
    case Engine::Auto:
      return "the default: with diodes the port model where it passes its check, else "
             "transient; without, LTI where the circuit allows it and it is the cheaper engine, "
             "else transient";
    case Engine::Lti:
      return "exact superposition of edge responses; an error if the circuit does not allow it";
    case Engine::PortModel:
      return "circuits with diodes: the linear network as a checked reduced model seen from the "
             "diodes' ports, Newton on the ports alone; an error if it does not apply";
    case Engine::Transient:
      return "time stepping, any circuit";
  }
  return "";
}

StatusOr<Engine> parse_engine(const std::string& text) {
  std::string choices;
  for (Engine e : kEngines) {
    if (text == engine_name(e)) return e;
    choices += (choices.empty() ? "" : ", ") + std::string(engine_name(e));
  }
  return Status::Error("engine '" + text + "' is not one of " + choices);
}

// What the self-check (transient_check.h) did; `agreement`: its absolute allowance, in words.
std::string tightening_text(const TransientConvergence& c, const char* agreement) {
  return fmt::format(
      "checked by tightening: reltol {:g} -> {:g}{} in {} runs; the kept run is {:.3g} m from the "
      "run before it (V or A, the probe nearest its allowance){}",
      c.reltols.front(), c.reltols.back(),
      c.tmaxes.front() == c.tmaxes.back()
          ? ""
          : fmt::format(" and largest step {:g} -> {:g} s", c.tmaxes.front(), c.tmaxes.back()),
      c.reltols.size(), 1e3 * c.deviations.back(),
      c.agreed ? fmt::format(", within its allowance of {:.3g} m ({} or 0.1 % of the probe's "
                             "peak): converged to about that, as the error shrinks at least "
                             "twofold per round",
                             1e3 * c.allowed.back(), agreement)
               : fmt::format(", NOT within its allowance of {:.3g} m: the tightening stopped at "
                             "reltol {:g} or at the step limit; treat small differences with care",
                             1e3 * c.allowed.back(), c.reltols.back()));
}

std::string engine_accuracy(const SimulationResult& r) {
  if (r.engine == Engine::Lti && r.lti.method == "reduced model") {
    const double bound = ReducedModelOptions{}.edge_error_bound();
    return fmt::format(
        "reduced model within {:.1e} of the circuit's exact transfer (check {:.0e}, weighted by "
        "the edges' spectrum): each source edge's response within {:.2g} mV per volt of edge "
        "({:.2g} mV for 5 V); rows exact, linear interpolation between them within 1 mV",
        r.lti.model.error, ReducedModelOptions{}.tol, 1e3 * bound, 5e3 * bound);
  }
  if (r.engine == Engine::PortModel) {
    const PortModelOptions po;
    return fmt::format(
        "port model: the linear network's transfer (port impedances, sources to ports and "
        "probes) within {:.1e} of each pair's peak (check {:.0e}{}; an edge's response within "
        "{:.2g} of its amplitude times the pair's peak gain); the port currents linear over a "
        "step, the steps under the transient's truncation-error control and the currents' bend "
        "(trtol x reltol = {:.2g} of the largest port voltage's peak and of each charge's), rows "
        "inside a step as the probes' linear interpolation needs (the same of each probe's "
        "peak), charge conserved{}",
        r.port.model.error, r.port.model.tol,
        r.port.model.relaxed
            ? fmt::format(", relaxed from {:.0e}: the search could add no direction",
                          po.reduced.tol)
            : "",
        po.reduced.edge_error_bound(r.port.model.error), r.trtol * r.reltol,
        r.convergence && !r.convergence->deviations.empty()
            ? "; " + tightening_text(*r.convergence, "3 mV")
            : "");
  }
  if (r.engine == Engine::Lti && r.lti.method.empty())  // a waveform synthesized, not simulated
    return "that of the response it was synthesized from (" + r.engine_note + ")";
  if (r.engine == Engine::Lti) {
    const LtiOptions lo;
    return fmt::format(
        "march: local truncation error per unit time within {:g} of each state's peak step "
        "response + {:g} (a local bound, not a global one; 0.20 mV from the reduced model on a "
        "100 m link); linear interpolation between rows within 1 mV",
        lo.step_reltol, lo.step_abstol);
  }
  if (r.convergence && !r.convergence->deviations.empty())
    return "transient, " + tightening_text(*r.convergence, "5 mV");
  return fmt::format(
      "transient: local truncation error per step within trtol x reltol = {:.2g} of each "
      "unknown's peak (reltol {:g}); a local bound, not a global one: at reltol 1e-3 the links "
      "were 8.2 mV (15 m example) and 10-56 mV (8 of 14 links of 0-50 m) from a converged "
      "reference; --reltol tightens it",
      r.trtol * r.reltol, r.reltol);
}

namespace {

// An error at the .tran card when there is one (the run's length and step come from it).
Status run_error(const Netlist& netlist, const std::string& message) {
  return netlist.tran ? error_at(netlist.tran->loc, message) : Status::Error(message);
}

// The transient's least memory (one row per step, a step at most TMAX): refused over the limit.
Status check_transient_memory(const Netlist& netlist, const TransientOptions& opt,
                              double row_bytes) {
  const double rows = (opt.tstop - opt.tstart) / opt.effective_tmax() + 1;
  const double bytes = rows * row_bytes;
  if (bytes <= kMemoryLimitBytes) return Status::Ok();
  return run_error(
      netlist,
      fmt::format("the transient engine would keep at least {:.3g} rows (a run of {:g} s in steps "
                  "of at most {:g} s) of {} values: {:.3g} GB, over the 1 GB memory limit; raise "
                  "TSTEP (or TMAX), shorten the run or record fewer probes",
                  rows, opt.tstop - opt.tstart, opt.effective_tmax(),
                  static_cast<int>(row_bytes / 8), bytes / kMemoryLimitBytes));
}

// The sources' corners over the run, counted before either engine lists them (the transient's
// breakpoints, the LTI engine's ramps, a row at each corner in both): refused over the memory
// limit at the .tran card. PULSE(0 1 0 1n 1n 1u 2u) over 1000 s has 2e9 corners (it took 8 GB and
// ended in std::bad_alloc). The sources are bound to the run's TSTEP and TSTOP first (a PULSE's
// default period is TSTOP), as the engines bind them.
Status check_corner_memory(const Netlist& netlist, Circuit& circuit, const TransientOptions& opt,
                           double row_bytes) {
  double corners = 0, most = 0;
  std::string most_name;
  for (const auto& e : circuit.elements()) {
    e->bind_time(opt.tstep, opt.tstop);
    const SourceFunction* f = e->source_function();
    if (!f) continue;
    const double n = f->corner_count(opt.tstop);
    corners += n;
    if (n > most) most = n, most_name = e->name();
  }
  const double bytes = corners * (4 * row_bytes + kCornerListBytes);
  if (bytes <= kMemoryLimitBytes) return Status::Ok();
  return run_error(
      netlist,
      fmt::format("the sources have {:.3g} corners in the {:g} s run ({:.3g} of them {}'s), "
                  "and either engine keeps about 4 rows of {} values and {:g} bytes of corner "
                  "lists a corner: {:.3g} GB, over the 1 GB memory limit; shorten the run or give "
                  "the source fewer corners (a PULSE's NP, fewer PWL repeats)",
                  corners, opt.tstop, most, most_name, static_cast<int>(row_bytes / 8),
                  kCornerListBytes, bytes / kMemoryLimitBytes));
}

// The transient options: the .tran card, the netlist's .options (unknown ones a warning), the
// request's overrides; refused when there is nothing to simulate or the output grid is too fine.
Status run_options(const Netlist& netlist, const SimulationRequest& req, TransientOptions* opt,
                   SimulationResult& result) {
  if (netlist.tran) {
    opt->tstep = netlist.tran->tstep;
    opt->tstop = netlist.tran->tstop;
    opt->tstart = netlist.tran->tstart;
    opt->tmax = netlist.tran->tmax;
    opt->uic = netlist.tran->uic;
  }
  for (const auto& o : netlist.options) {
    bool known = true;
    if (Status s = opt->set_option(o.key, o.value, &known); !s.ok()) return s;
    if (!known)
      result.warnings.push_back(format_diagnostic(
          o.loc, "warning", "option '" + o.key + "' is not used by isolink; ignored"));
  }
  if (req.tstop) opt->tstop = *req.tstop;
  if (req.tstep) opt->tstep = *req.tstep;
  if (req.tmax) opt->tmax = *req.tmax;
  if (req.method) opt->method = *req.method;
  if (req.reltol) opt->reltol = *req.reltol;
  if (!netlist.tran && !req.tstop)
    return Status::Error("no .tran card in the netlist and no --tstop given: nothing to simulate");
  if (opt->tstep <= 0 && opt->tstop > 0) opt->tstep = opt->tstop / 1000;
  if (Status s = opt->validate(); !s.ok()) return s;
  if (req.grid_step > 0) {
    // Refused before any work: --step 1e-30 over 5 us asks for 5e24 rows (the LTI grid and the
    // transient's resampling would both allocate them).
    const double rows = (opt->tstop - opt->tstart) / req.grid_step + 1;
    if (!(rows <= static_cast<double>(kMaxGridRows)))
      return Status::Error(fmt::format(
          "--step {:g} over the {:.6g} s run asks for {:.3g} rows; the limit is {} rows (use a "
          "larger --step, or no --step for the engine's own time points)",
          req.grid_step, opt->tstop - opt->tstart, rows, kMaxGridRows));
  }
  return Status::Ok();
}

// The circuit of the netlist's cards (its warnings into result), and the .ic nodes into opt.
Status build_circuit(const Netlist& netlist, Circuit* circuit, TransientOptions* opt,
                     SimulationResult& result) {
  for (const Card& card : netlist.cards)
    if (Status s = circuit->add(card); !s.ok()) return s;
  if (Status s = circuit->finalize(); !s.ok()) return s;
  for (const auto& w : circuit->warnings()) result.warnings.push_back(w);
  for (const InitialVoltage& ic : netlist.initial_voltages) {
    const int node = circuit->find_node(ic.node);
    if (node <= 0)
      return error_at(ic.loc,
                      node == 0 ? "'.ic' on the ground node"
                                : "'.ic' names node '" + ic.node + "', which no element connects");
    opt->node_ic.emplace_back(node, ic.value);
  }
  return Status::Ok();
}

StatusOr<std::vector<Probe>> parse_probes(const Circuit& circuit, const SimulationRequest& req) {
  std::vector<Probe> probes;
  for (const auto& text : req.probes) {
    StatusOr<Probe> p = parse_probe(circuit, text);
    if (!p) return p.status();
    probes.push_back(*p);
  }
  if (probes.empty())
    return Status::Error("no --probe given: say what to record, e.g. --probe 'v(rxp,rxn)'");
  return probes;
}

// The rows of a --step grid within kMemoryLimitBytes (row_bytes: the time plus every probe).
Status check_grid_memory(const SimulationRequest& req, const TransientOptions& opt, size_t probes,
                         double row_bytes) {
  if (req.grid_step <= 0) return Status::Ok();
  const double bytes = ((opt.tstop - opt.tstart) / req.grid_step + 1) * row_bytes;
  if (!(bytes <= kMemoryLimitBytes))
    return Status::Error(
        fmt::format("--step {:g} over the {:.6g} s run with {} probes needs {:.3g} GB of rows, "
                    "over the 1 GB memory limit (use a larger --step or fewer probes)",
                    req.grid_step, opt.tstop - opt.tstart, probes, bytes / kMemoryLimitBytes));
  return Status::Ok();
}

// Bytes per step of the LTI march: it keeps each time-varying source's response at every probe.
double march_step_bytes(const Circuit& circuit, size_t probes) {
  long sources = 0;
  for (const auto& e : circuit.elements())
    if (const SourceFunction* f = e->source_function(); f && f->kind() != SourceFunction::Kind::Dc)
      ++sources;
  return 8.0 * static_cast<double>(1 + 2 * sources * static_cast<long>(probes));
}

// Why the LTI engine cannot run this circuit with these options (OK: it can).
Status lti_allowed(const Circuit& circuit, const TransientOptions& opt) {
  if (opt.uic)
    return Status::Error(
        ".tran uic starts from zero, not from the DC operating point: the LTI engine needs the "
        "operating point");
  if (!opt.node_ic.empty())
    return Status::Error(
        "'.ic' holds nodes for the DC point: the LTI engine starts from the circuit's own "
        "operating point");
  return check_lti(circuit);
}

// What the engines share: the circuit, its probes, the options and the memory per row.
struct EngineRun {
  Circuit& circuit;
  const std::vector<Probe>& probes;
  const SimulationRequest& req;
  TransientOptions& opt;
  double row_bytes = 0;
  std::chrono::steady_clock::time_point start;
};

// SimulationRequest::record_tol: the engine's windows of rows join `wave`, every row while it
// holds up to full_rows, thinned after that, each window with the last one's end (held back
// until then) as its first row and anchor.
class RecordThinner {
 public:
  // [t0, t1]: the record's span (its rate so far sizes the vectors: see grow).
  RecordThinner(const std::vector<Probe>& probes, double tol, size_t full_rows, double t0,
                double t1, Waveform& wave)
      : wave_(wave), full_rows_(full_rows), t0_(t0), t1_(t1) {
    for (const Probe& p : probes) tols_.push_back(p.label.rfind("i(", 0) == 0 ? 1e-3 * tol : tol);
  }
  // The time from which rows were thinned (infinity: none were).
  double thinned_from() const { return thinned_from_; }
  void add(const std::vector<double>& t, const std::vector<std::vector<double>>& v) {
    const size_t np = tols_.size();
    grow(t.size(), t.back());
    if (thinned_from_ == kNever && wave_.time.size() + time_.size() + t.size() <= full_rows_) {
      for (size_t i = 0; i < time_.size(); ++i) push(i);
      time_.clear();
      for (auto& c : cols_) c.clear();
      wave_.time.insert(wave_.time.end(), t.begin(), t.end() - 1);
      for (size_t p = 0; p < np; ++p)
        wave_.columns[p].insert(wave_.columns[p].end(), v[p].begin(), v[p].end() - 1);
      time_ = {t.back()};
      cols_.resize(np);
      for (size_t p = 0; p < np; ++p) cols_[p] = {v[p].back()};
      return;
    }
    if (thinned_from_ == kNever) thinned_from_ = time_.empty() ? t.front() : time_.front();
    time_.insert(time_.end(), t.begin(), t.end());
    cols_.resize(np);
    std::vector<std::span<const double>> spans;
    for (size_t p = 0; p < np; ++p) {
      cols_[p].insert(cols_[p].end(), v[p].begin(), v[p].end());
      spans.emplace_back(cols_[p]);
    }
    const std::vector<size_t> keep = thin_rows(time_, spans, tols_);
    for (size_t k = 0; k + 1 < keep.size(); ++k) push(keep[k]);  // the last: the window's end
    const size_t last = time_.size() - 1;
    time_ = {time_[last]};
    for (auto& c : cols_) c = {c[last]};
  }
  void finish() {
    if (!time_.empty()) push(0);
  }

 private:
  static constexpr double kNever = std::numeric_limits<double>::infinity();
  // Room for `more` rows: when the vectors must grow, to the rows the record will hold at its
  // rate so far (5 % over) rather than twice what they hold, so that a long record's vectors
  // are about its size (doubling leaves up to half of them unused).
  void grow(size_t more, double t_now) {
    const size_t need = wave_.time.size() + more + 1;
    if (need <= wave_.time.capacity()) return;
    const double done = std::max(1e-30, (t_now - t0_) / (t1_ - t0_));
    const size_t at_rate =
        static_cast<size_t>(1.05 * static_cast<double>(need) / std::min(1.0, done));
    const size_t room = std::max(need + need / 8, std::min(at_rate, 2 * need));
    wave_.time.reserve(room);
    for (auto& c : wave_.columns) c.reserve(room);
  }
  void push(size_t i) {
    wave_.time.push_back(time_[i]);
    for (size_t p = 0; p < tols_.size(); ++p) wave_.columns[p].push_back(cols_[p][i]);
  }
  Waveform& wave_;
  const size_t full_rows_;
  const double t0_, t1_;
  double thinned_from_ = kNever;
  std::vector<double> tols_;
  std::vector<double> time_;               // the window's rows, after the held-back one
  std::vector<std::vector<double>> cols_;  // [probe][row]
};

// The LTI engine: *done when result holds its waveform; otherwise result.engine_note says why
// not (auto falls back to the transient). Errors: a forced `lti` that cannot run.
Status run_lti(const EngineRun& run, SimulationResult& result, bool* done) {
  const SimulationRequest& req = run.req;
  const TransientOptions& opt = run.opt;
  Status lti_ok = lti_allowed(run.circuit, opt);
  if (!lti_ok.ok() && req.engine == Engine::Lti) return lti_ok;
  if (lti_ok.ok()) {
    for (const auto& e : run.circuit.elements()) e->bind_time(opt.tstep, opt.tstop);
    LtiOptions lo;
    lo.horizon = opt.tstop;
    lo.method = req.lti_method;
    if (req.progress)
      lo.on_progress = [&](double tau) {
        req.progress("LTI responses", std::clamp(tau / opt.tstop, 0.0, 1.0));
      };
    // auto: a march longer than kAutoLtiMaxSteps costs more than the transient of any example
    // link (the longest takes 190k steps), so auto stops there and runs the transient.
    if (req.engine == Engine::Auto) {
      lo.max_steps = std::min(lo.max_steps, kAutoLtiMaxSteps);
      lo.settle_by = 0.25 * opt.tstop;
    }
    const double march_bytes = march_step_bytes(run.circuit, run.probes.size());
    lo.max_steps =
        std::min<long>(lo.max_steps, static_cast<long>(kMemoryLimitBytes / (2 * march_bytes)));
    StatusOr<LtiResponses> responses = LtiResponses::compute(run.circuit, run.probes, lo);
    // auto: a response march that cannot meet its error control falls back to the transient
    // engine (the cross-check) and says why; a forced `lti` reports the failure.
    if (!responses && req.engine == Engine::Lti) return responses.status();
    if (responses) {
      LtiResponses::GridOptions grid;
      grid.tstart = opt.tstart;
      grid.tstop = opt.tstop;
      grid.step = req.grid_step;
      grid.grid_probes = req.grid_probes;
      grid.threads = req.lti_threads;
      grid.max_rows =
          std::min<long>(grid.max_rows, static_cast<long>(kMemoryLimitBytes / (4 * run.row_bytes)));
      // auto: the LTI output only when it costs about what the transient would (a transient
      // step costs about an unknown's worth of work per unknown, as does a probe evaluation).
      if (req.engine == Engine::Auto && !responses->reduced())
        grid.max_evaluations =
            kAutoLtiBudget * static_cast<double>(responses->stats().steps) * result.unknowns;
      const bool thin = req.record_tol > 0 && responses->reduced() && grid.step == 0;
      Waveform kept;
      RecordThinner thinner(run.probes, req.record_tol, req.record_full_rows, grid.tstart,
                            grid.tstop, kept);
      if (thin) {
        grid.max_rows = LtiResponses::GridOptions{}.max_rows;  // per window: one at a time
        kept.names = responses->probe_labels();
        kept.columns.resize(kept.names.size());
        grid.on_rows = [&](const std::vector<double>& t,
                           const std::vector<std::vector<double>>& v) { thinner.add(t, v); };
      }
      result.wave = responses->waveform(responses->netlist_inputs(opt.tstop), grid, &result.grid);
      if (thin) {
        thinner.finish();
        result.wave = std::move(kept);
        if (thinner.thinned_from() < opt.tstop) {
          result.record_tol = req.record_tol;
          result.warnings.push_back(fmt::format(
              "note: the record keeps {} of the LTI engine's {} rows: from {:.6g} ms on, those "
              "that linear interpolation needs to stay within {:g} mV of every engine row "
              "(every row would take {:.0f} MB)",
              result.wave.time.size(), result.grid.rows, 1e3 * thinner.thinned_from(),
              1e3 * req.record_tol, static_cast<double>(result.grid.rows) * run.row_bytes / 1e6));
        }
      }
    }
    if (responses && result.grid.over_budget) {
      lti_ok = Status::Error(fmt::format(
          "the LTI output grid would take {:.3g} probe evaluations, more than the transient "
          "costs here ({} march steps x {} unknowns x {:g})",
          result.grid.evaluations, responses->stats().steps, result.unknowns, kAutoLtiBudget));
      result.grid = {};
    } else if (responses) {
      if (!result.grid.warning.empty())
        result.warnings.push_back("warning: " + result.grid.warning);
      result.lti = responses->stats();
      result.engine = Engine::Lti;
      result.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
      *done = true;
      return Status::Ok();
    } else {
      // Only auto gets here (a forced lti returned the error above), and auto's own limits
      // (settle_by, kAutoLtiMaxSteps) are the usual reason: say so, without reading the text.
      lti_ok = Status::Error(fmt::format(
          "the LTI response march stopped: {}; auto stops it where it would cost more than the "
          "transient (responses not settled by a quarter of the run, or over {} steps)",
          responses.status().message(), kAutoLtiMaxSteps));
    }
  }
  result.engine_note = lti_ok.message();
  return Status::Ok();
}

bool netlist_sets_reltol(const Netlist& netlist) {
  for (const NetlistOption& o : netlist.options)
    if (o.key == "reltol") return true;
  return false;
}

// The transient engine, within the memory limit (an error names the LTI engine's refusal too).
Status run_transient_engine(const Netlist& netlist, const EngineRun& run,
                            SimulationResult& result) {
  const SimulationRequest& req = run.req;
  TransientOptions& opt = run.opt;
  if (Status s = check_transient_memory(netlist, opt, run.row_bytes); !s.ok()) {
    if (result.engine_note.empty()) return s;
    return Status::Error(s.message() + "\n(the LTI engine was not used: " + result.engine_note +
                         ")");
  }
  if (req.progress)
    opt.on_progress = [&](double t) {
      req.progress("transient", std::clamp(t / opt.tstop, 0.0, 1.0));
    };
  if (!result.engine_note.empty())
    result.lti_attempt_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
  result.reltol = opt.reltol;
  result.trtol = opt.trtol;
  StatusOr<Waveform> wave = run_transient(run.circuit, opt, run.probes, &result.stats);
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
  if (!wave && opt.max_steps < TransientOptions{}.max_steps &&
      result.stats.accepted + result.stats.rejected >= opt.max_steps)
    return Status::Error(
        fmt::format("{} ({} steps: {} rows of {} values are what the 1 GB memory limit allows)",
                    wave.status().message(), opt.max_steps, opt.max_steps, run.probes.size() + 1));
  if (!wave) return wave.status();
  const bool netlist_reltol = netlist_sets_reltol(netlist);
  const bool auto_fell_back = req.engine == Engine::Auto && !result.engine_note.empty();
  const bool forced_at_defaults = req.engine == Engine::Transient && !netlist_reltol;
  if ((auto_fell_back || forced_at_defaults) && !req.reltol) {
    // auto fell back, or the transient was asked for without a tolerance of the user's: the run
    // checks its own convergence (transient_check.h), so the defaults are within its 5 mV.
    TransientConvergence conv;
    wave = converge_transient(run.circuit, opt, run.probes, std::move(*wave), &result.stats, &conv);
    result.reltol = conv.reltols.back();
    result.convergence = std::move(conv);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
  }
  result.wave = std::move(*wave);
  result.engine = Engine::Transient;
  return Status::Ok();
}

bool has_nonlinear(const Circuit& circuit) {
  for (const auto& e : circuit.elements())
    if (e->nonlinear_port_count() > 0) return true;
  return false;
}

// The port model engine (nonlinear circuits): *done when result holds its waveform; otherwise
// result.engine_note says why not (auto falls back to the transient). Errors: a forced `port`
// that cannot run.
Status run_port(const Netlist& netlist, const EngineRun& run, SimulationResult& result,
                bool* done) {
  const SimulationRequest& req = run.req;
  const TransientOptions& opt = run.opt;
  const bool forced = req.engine == Engine::PortModel;
  auto refuse = [&](const Status& why) {
    if (forced) return why;
    result.engine_note = "the port model did not apply: " + why.message();
    return Status::Ok();
  };
  if (opt.uic || !opt.node_ic.empty())
    return refuse(Status::Error(
        ".ic / .tran uic: the port model starts from the circuit's own DC operating point"));
  if (Status s = check_transient_memory(netlist, opt, run.row_bytes); !s.ok()) return refuse(s);
  const PortModelOptions po;
  StatusOr<PortModel> model =
      build_port_model(netlist.cards, run.circuit, run.probes, opt.tstop, po);
  if (!model) return refuse(model.status());
  TransientOptions port_opt = opt;
  const bool at_defaults = !req.reltol && !netlist_sets_reltol(netlist);
  if (at_defaults) port_opt.reltol = po.default_reltol;
  for (const auto& e : run.circuit.elements()) e->bind_time(opt.tstep, opt.tstop);
  StatusOr<Waveform> wave = Status::Ok();
  if (!at_defaults) {
    wave = run_port_model_bound(run.circuit, *model, port_opt, &result.port);
  } else {
    // No tolerance of the user's: the run checks its own convergence as the transient does
    // (transient_check.h), at the nonlinear bound of 3 mV, its first two runs at once. Each
    // run's statistics are kept by its reltol; the kept run's become the result's.
    std::mutex mutex;
    std::map<double, PortModelStats> stats;
    TransientConvergence conv;
    wave = converge_runs_two_at_once(
        port_opt,
        [&](const TransientOptions& o) -> StatusOr<Waveform> {
          PortModelStats st;
          StatusOr<Waveform> w = run_port_model_bound(run.circuit, *model, o, &st);
          const std::lock_guard<std::mutex> lock(mutex);
          if (w) stats[o.reltol] = st;
          return w;
        },
        TransientConvergence::kPortAgreementV, &conv, Tighten::Reltol);
    if (wave) {
      port_opt.reltol = conv.reltols.back();
      result.port = stats[port_opt.reltol];
      result.convergence = std::move(conv);
    }
  }
  if (!wave) return refuse(wave.status());
  result.wave = std::move(*wave);
  result.engine = Engine::PortModel;
  result.reltol = port_opt.reltol;
  result.trtol = opt.trtol;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run.start).count();
  *done = true;
  return Status::Ok();
}

// Fills `result` and moves it out (a copy would hold the record twice: 600 MB for 25 ms).
StatusOr<SimulationResult> simulate(const Netlist& netlist, const SimulationRequest& req,
                                    SimulationResult& result) {
  TransientOptions opt;
  if (Status s = run_options(netlist, req, &opt, result); !s.ok()) return s;
  Circuit circuit;
  if (Status s = build_circuit(netlist, &circuit, &opt, result); !s.ok()) return s;
  StatusOr<std::vector<Probe>> probes = parse_probes(circuit, req);
  if (!probes) return probes.status();
  // Memory (kMemoryLimitBytes): a row is the time plus every probe.
  const double row_bytes = 8.0 * static_cast<double>(1 + probes->size());
  if (Status s = check_grid_memory(req, opt, probes->size(), row_bytes); !s.ok()) return s;
  if (Status s = check_corner_memory(netlist, circuit, opt, row_bytes); !s.ok()) return s;
  opt.max_steps =
      std::min<long>(opt.max_steps, static_cast<long>(kMemoryLimitBytes / (2 * row_bytes)));
  result.nodes = circuit.node_count() - 1;
  result.unknowns = circuit.unknown_count();
  result.elements = static_cast<int>(circuit.elements().size());

  const EngineRun run{circuit, *probes, req, opt, row_bytes, std::chrono::steady_clock::now()};
  const bool nonlinear = has_nonlinear(circuit);
  if (req.engine == Engine::PortModel && !nonlinear)
    return Status::Error(
        "--engine port: the circuit has no nonlinear element (diode); use auto, lti or "
        "transient");
  if (nonlinear && (req.engine == Engine::Auto || req.engine == Engine::PortModel)) {
    bool done = false;
    if (Status s = run_port(netlist, run, result, &done); !s.ok()) return s;
    if (done) return std::move(result);
  }
  if (req.engine != Engine::Transient && (!nonlinear || req.engine == Engine::Lti)) {
    bool done = false;
    if (Status s = run_lti(run, result, &done); !s.ok()) return s;
    if (done) return std::move(result);
  }
  if (Status s = run_transient_engine(netlist, run, result); !s.ok()) return s;
  return std::move(result);
}

}  // namespace

StatusOr<SimulationResult> simulate_netlist(const Netlist& netlist, const SimulationRequest& req) {
  SimulationResult result;
  result.warnings = netlist.warnings;
  StatusOr<SimulationResult> r = simulate(netlist, req, result);
  if (r.ok() || result.warnings.empty()) return r;
  // Warnings first: a skipped card or a tied node may be why the run failed.
  std::string text;
  for (const std::string& w : result.warnings) text += w + "\n";
  return Status::Error(text + r.status().message());
}

}  // namespace isolink::analysis
