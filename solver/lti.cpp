#include "solver/lti.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>

#include "solver/lti_internal.h"
#include "solver/mna_system.h"

namespace isolink {

using lti_internal::coarsest_grid_step;
using lti_internal::phi;
using lti_internal::Rows;

Status LtiOptions::validate() const {
  auto bad = [](const char* field, double v, const char* rule) {
    return Status::Error(fmt::format("LTI option {} = {:g}: {}", field, v, rule));
  };
  if (!(horizon > 0) || !std::isfinite(horizon)) return bad("horizon", horizon, "must be positive");
  if (!(step_reltol > 0 && step_reltol < 1))
    return bad("step_reltol", step_reltol, "must be in (0, 1)");
  if (!(step_abstol > 0)) return bad("step_abstol", step_abstol, "must be positive");
  if (!(settle_tol > 0)) return bad("settle_tol", settle_tol, "must be positive");
  if (!(first_step >= 0)) return bad("first_step", first_step, "must not be negative");
  if (!(max_step >= 0)) return bad("max_step", max_step, "must not be negative");
  if (max_steps <= 0) return bad("max_steps", static_cast<double>(max_steps), "must be positive");
  if (!(settle_by >= 0)) return bad("settle_by", settle_by, "must not be negative");
  return Status::Ok();
}

SourceInput pwl_input(const std::vector<double>& t, const std::vector<double>& v) {
  SourceInput in;
  if (t.empty()) return in;
  in.initial = v[0];
  double previous = 0.0;
  for (size_t i = 0; i + 1 < t.size(); ++i) {
    const double slope = (v[i + 1] - v[i]) / (t[i + 1] - t[i]);
    if (slope != previous) in.ramps.push_back({t[i], slope - previous});
    previous = slope;
  }
  if (previous != 0.0) in.ramps.push_back({t.back(), -previous});
  return in;
}

Status check_lti(const Circuit& circuit) {
  for (const auto& e : circuit.elements()) {
    if (!e->linear_time_invariant()) {
      const std::string why = "element '" + e->name() +
                              "' is not linear and time-invariant: the LTI engine cannot "
                              "simulate it (use --engine transient)";
      // Elements built in code (a link spec's TVS, the pins' clamps) have no netlist location.
      return e->loc().valid() ? error_at(e->loc(), why) : Status::Error(why);
    }
    const SourceFunction* f = e->source_function();
    if (f && !f->piecewise_linear())
      return error_at(e->loc(), "source '" + e->name() +
                                    "' is not a continuous piecewise-linear function (SIN, EXP, "
                                    "or a PWL whose r= repeat jumps): the LTI engine takes DC, "
                                    "PULSE and PWL sources (use --engine transient)");
  }
  if (!circuit.dc_open_branches().empty())
    return Status::Error(
        "an inductor closes a loop of voltage sources and inductors and is opened for the DC "
        "point: the LTI engine needs a DC operating point of the circuit as it is (use --engine "
        "transient)");
  return Status::Ok();
}

namespace {

// The shortest linear piece with a slope of any source's waveform up to tstop (its fastest
// edge), 0 when none moves.
double shortest_edge(const std::vector<const SourceFunction*>& sources, double tstop) {
  double shortest = 0.0;
  for (const SourceFunction* f : sources) {
    const std::vector<Ramp> ramps = f->ramps(tstop);
    double slope = 0.0, steepest = 0.0;
    for (size_t j = 0; j < ramps.size(); ++j) {
      slope += ramps[j].slope;
      steepest = std::max(steepest, std::fabs(slope));
      const double end = j + 1 < ramps.size() ? ramps[j + 1].t : tstop;
      const double piece = end - ramps[j].t;
      if (std::fabs(slope) > 1e-9 * steepest && piece > 0 && (shortest == 0 || piece < shortest))
        shortest = piece;
    }
  }
  return shortest;
}

}  // namespace

StatusOr<LtiResponses> LtiResponses::compute(const Circuit& circuit,
                                             const std::vector<Probe>& probes,
                                             const LtiOptions& opt) {
  if (Status s = opt.validate(); !s.ok()) return s;
  if (Status s = check_lti(circuit); !s.ok()) return s;
  LtiResponses r;
  for (const Probe& p : probes) {
    r.labels_.push_back(p.label);
    r.is_current_.push_back(p.label.rfind("i(", 0) == 0);
  }
  MnaSystem sys;
  if (Status s = sys.build(circuit); !s.ok()) return s;
  const std::vector<std::vector<double>> unit = r.collect_sources(circuit, sys.n);
  if (opt.tie_sources) r.find_ties(opt.horizon);
  std::vector<std::vector<double>> dc_solutions;  // per source: G^-1 e_k
  if (Status s = r.solve_dc(circuit, sys, probes, unit, dc_solutions); !s.ok()) return s;
  if (opt.method != LtiOptions::Method::March && !r.sources_.empty()) {
    StatusOr<bool> reduced = r.try_reduced_model(circuit, probes, unit, dc_solutions, opt);
    if (!reduced) return reduced.status();
    if (*reduced) return r;
  }
  if (Status s = r.march(circuit, sys, probes, unit, opt); !s.ok()) return s;
  return r;
}

std::vector<std::vector<double>> LtiResponses::collect_sources(const Circuit& circuit, int n) {
  std::vector<std::vector<double>> unit;  // per source: its unit excitation (n + 1)
  for (const auto& e : circuit.elements()) {
    const SourceFunction* f = e->source_function();
    if (!f || f->kind() == SourceFunction::Kind::Dc) continue;
    sources_.push_back({e->name(), f, f->value(0.0)});
    unit.emplace_back(n + 1, 0.0);
    e->stamp_unit(unit.back().data());
    unit.back()[0] = 0.0;
  }
  return unit;
}

namespace {

// Whether every slope change of `a` is b times `leader`'s at the same time (within 1e-12 of the
// largest); two empty lists do.
bool moves_as(const std::vector<Ramp>& a, const std::vector<Ramp>& leader, double b) {
  if (a.size() != leader.size()) return false;
  double largest = 0.0;
  for (const Ramp& r : a) largest = std::max(largest, std::fabs(r.slope));
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].t != leader[i].t || !(std::fabs(a[i].slope - b * leader[i].slope) <= 1e-12 * largest))
      return false;
  return true;
}

}  // namespace

void LtiResponses::find_ties(double tstop) {
  std::vector<std::vector<Ramp>> ramps;
  for (const Source& s : sources_) ramps.push_back(s.function->ramps(tstop));
  for (size_t k = 0; k < sources_.size(); ++k)
    for (size_t j = 0; j < k; ++j) {
      if (sources_[j].tied_to >= 0 || ramps[k].empty() || ramps[j].empty()) continue;
      if (ramps[j].front().slope == 0) continue;
      const double b = ramps[k].front().slope / ramps[j].front().slope;
      if (b == 0 || !std::isfinite(b) || !moves_as(ramps[k], ramps[j], b)) continue;
      sources_[k].tied_to = static_cast<int>(j);
      sources_[k].tie_factor = b;
      break;
    }
}

bool LtiResponses::follows_ties(const std::vector<SourceInput>& inputs) const {
  static const std::vector<Ramp> kNone;
  for (size_t k = 0; k < sources_.size() && k < inputs.size(); ++k) {
    const size_t j = static_cast<size_t>(sources_[k].tied_to);
    if (sources_[k].tied_to < 0) continue;
    if (!moves_as(inputs[k].ramps, j < inputs.size() ? inputs[j].ramps : kNone,
                  sources_[k].tie_factor))
      return false;
  }
  return true;
}

// The operating point of the netlist's sources at t = 0, and each source's DC gain.
Status LtiResponses::solve_dc(const Circuit& circuit, const MnaSystem& sys,
                              const std::vector<Probe>& probes,
                              const std::vector<std::vector<double>>& unit,
                              std::vector<std::vector<double>>& dc_solutions) {
  KluSolver dc_klu;
  if (Status s = sys.factor_dc(circuit, dc_klu); !s.ok())
    return s.with_context("DC operating point");
  std::vector<double> x(sys.n + 1);
  sys.rhs(0.0, x);
  if (Status s = dc_klu.solve(x.data() + 1); !s.ok()) return s;
  x[0] = 0.0;
  for (const Probe& p : probes) y_dc_.push_back(p.value(x.data()));
  for (size_t k = 0; k < unit.size(); ++k) {
    x = unit[k];
    if (Status s = dc_klu.solve(x.data() + 1); !s.ok()) return s;
    x[0] = 0.0;
    gain_.emplace_back();
    for (const Probe& p : probes) gain_[k].push_back(p.value(x.data()));
    dc_solutions.push_back(x);
  }
  stats_.factorizations = 1;
  return Status::Ok();
}

StatusOr<bool> LtiResponses::try_reduced_model(const Circuit& circuit,
                                               const std::vector<Probe>& probes,
                                               const std::vector<std::vector<double>>& unit,
                                               const std::vector<std::vector<double>>& dc_solutions,
                                               const LtiOptions& opt) {
  ReducedModelOptions ro = opt.reduced;
  ro.horizon = opt.horizon;
  std::vector<const SourceFunction*> functions;
  for (const Source& src : sources_) functions.push_back(src.function);
  ro.edge_time = opt.edge_time > 0 ? opt.edge_time : shortest_edge(functions, opt.horizon);
  // One model input per source that is not tied (LtiOptions::tie_sources), its excitation and
  // DC solution summed with its tied sources' (scaled): the model is linear in both.
  std::vector<std::vector<double>> in_unit, in_dc;
  std::vector<int> input_of(sources_.size(), -1);  // per source: its model input, -1 if tied
  for (size_t k = 0; k < sources_.size(); ++k) {
    const int j = sources_[k].tied_to;
    if (j < 0) {
      input_of[k] = static_cast<int>(in_unit.size());
      in_unit.push_back(unit[k]);
      in_dc.push_back(dc_solutions[k]);
      continue;
    }
    const double b = sources_[k].tie_factor;
    const size_t i = static_cast<size_t>(input_of[static_cast<size_t>(j)]);
    for (size_t u = 0; u < unit[k].size(); ++u) {
      in_unit[i][u] += b * unit[k][u];
      in_dc[i][u] += b * dc_solutions[k][u];
    }
  }
  const auto started = std::chrono::steady_clock::now();
  StatusOr<ReducedModel> model = reduce_circuit(circuit, in_unit, in_dc, probes, ro);
  if (model && in_unit.size() != sources_.size()) {
    // Back to one row per source: a tied source's are 0 (its leader's carry it).
    ReducedModel& m = *model;
    std::vector<std::vector<std::complex<double>>> input(sources_.size());
    std::vector<std::vector<double>> direct(sources_.size());
    for (size_t k = 0; k < sources_.size(); ++k) {
      if (input_of[k] >= 0) {
        input[k] = m.input[static_cast<size_t>(input_of[k])];
        direct[k] = m.direct[static_cast<size_t>(input_of[k])];
      } else {
        input[k].assign(m.poles.size(), 0.0);
        direct[k].assign(probes.size(), 0.0);
      }
    }
    m.input = std::move(input);
    m.direct = std::move(direct);
  }
  stats_.model_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (model) {
    stats_.method = "reduced model";
    stats_.model = model->stats;
    stats_.factorizations += model->stats.factorizations;
    stats_.settled_at = opt.horizon;
    model_ = std::move(*model);
    tau_.push_back(0.0);
    return true;
  }
  if (opt.method == LtiOptions::Method::Reduced) return model.status();
  stats_.note = model.status().message();
  return false;
}

int LtiResponses::find_source(const std::string& name) const {
  for (size_t k = 0; k < sources_.size(); ++k)
    if (sources_[k].name == name) return static_cast<int>(k);
  return -1;
}

std::vector<SourceInput> LtiResponses::netlist_inputs(double tstop) const {
  std::vector<SourceInput> in;
  for (const Source& s : sources_) in.push_back({s.initial, s.function->ramps(tstop)});
  return in;
}

double LtiResponses::hermite(size_t k, size_t p, size_t i, double tau) const {
  const double h = tau_[i + 1] - tau_[i];
  const double u = (tau - tau_[i]) / h, u2 = u * u, u3 = u2 * u;
  const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2,
               h11 = u3 - u2;
  const auto &R = r_[k][p], &S = s_[k][p];
  return h00 * R[i] + h10 * h * S[i] + h01 * R[i + 1] + h11 * h * S[i + 1];
}

double LtiResponses::ramp_response(size_t k, size_t p, double tau) const {
  if (tau <= 0) return 0.0;
  if (model_) {
    std::complex<double> y = 0.0;
    for (size_t i = 0; i < model_->poles.size(); ++i)
      y += model_->output[p][i] * model_->input[k][i] * phi(model_->poles[i] * tau).phi2;
    return model_->direct[k][p] * tau + tau * tau * y.real();
  }
  const double end = tau_.back();
  if (tau >= end) return r_[k][p].back() + end_slope_[k][p] * (tau - end);
  size_t i = std::upper_bound(tau_.begin(), tau_.end(), tau) - tau_.begin() - 1;
  return hermite(k, p, i, tau);
}

double LtiResponses::step_response(size_t k, size_t p, double tau) const {
  if (tau <= 0) return 0.0;
  if (model_) {
    std::complex<double> y = 0.0;
    for (size_t i = 0; i < model_->poles.size(); ++i)
      y += model_->output[p][i] * model_->input[k][i] * phi(model_->poles[i] * tau).phi1;
    return model_->direct[k][p] + tau * y.real();
  }
  const double end = tau_.back();
  if (tau >= end) return end_slope_[k][p];
  size_t i = std::upper_bound(tau_.begin(), tau_.end(), tau) - tau_.begin() - 1;
  // Derivative of the Hermite interpolant.
  const double h = tau_[i + 1] - tau_[i];
  const double u = (tau - tau_[i]) / h, u2 = u * u;
  const auto &R = r_[k][p], &S = s_[k][p];
  return ((6 * u2 - 6 * u) * R[i] + (6 * u - 6 * u2) * R[i + 1]) / h + (3 * u2 - 4 * u + 1) * S[i] +
         (3 * u2 - 2 * u) * S[i + 1];
}

double LtiResponses::value(size_t p, double t, const std::vector<SourceInput>& inputs) const {
  if (model_ && !follows_ties(inputs)) return std::numeric_limits<double>::quiet_NaN();
  double y = y_dc_[p];
  for (size_t k = 0; k < sources_.size() && k < inputs.size(); ++k) {
    y += (inputs[k].initial - sources_[k].initial) * gain_[k][p];
    for (const Ramp& ramp : inputs[k].ramps) {
      if (ramp.t >= t) break;
      y += ramp.slope * ramp_response(k, p, t - ramp.t);
    }
  }
  return y;
}

void LtiResponses::superpose(const std::vector<SourceInput>& inputs, double t0, double dt,
                             long count, std::vector<std::vector<double>>& out) const {
  const size_t np = labels_.size();
  const double end = tau_.back();
  const size_t last = tau_.size() - 1;
  // Beyond the march's end each ramp adds slope * (R_end + S_end (t - t_j - end)): an affine
  // function of t, added through difference arrays a (constant) and b (times t).
  std::vector<std::vector<double>> da(np, std::vector<double>(count + 1, 0.0)), db = da;
  std::vector<double> basis(4);
  for (size_t k = 0; k < sources_.size() && k < inputs.size(); ++k) {
    for (const Ramp& ramp : inputs[k].ramps) {
      // First row strictly after the corner.
      long i = static_cast<long>(std::floor((ramp.t - t0) / dt)) + 1;
      if (i < 0) i = 0;
      while (i > 0 && t0 + static_cast<double>(i - 1) * dt > ramp.t) --i;
      while (i < count && t0 + static_cast<double>(i) * dt <= ramp.t) ++i;
      size_t m = 0;  // march interval
      for (; i < count; ++i) {
        const double tau = t0 + static_cast<double>(i) * dt - ramp.t;
        if (tau >= end) break;
        while (m + 1 < last && tau_[m + 1] <= tau) ++m;
        const double h = tau_[m + 1] - tau_[m];
        const double u = (tau - tau_[m]) / h, u2 = u * u, u3 = u2 * u;
        const double h00 = 2 * u3 - 3 * u2 + 1, h10 = (u3 - 2 * u2 + u) * h, h01 = -2 * u3 + 3 * u2,
                     h11 = (u3 - u2) * h;
        for (size_t p = 0; p < np; ++p) {
          const auto &R = r_[k][p], &S = s_[k][p];
          out[p][i] += ramp.slope * (h00 * R[m] + h10 * S[m] + h01 * R[m + 1] + h11 * S[m + 1]);
        }
      }
      if (i < count)
        for (size_t p = 0; p < np; ++p) {
          const double rend = r_[k][p][last], send = end_slope_[k][p];
          // slope * (rend + send * (t - ramp.t - end)), t = t0 + i dt
          da[p][i] += ramp.slope * (rend - send * (ramp.t + end - t0));
          db[p][i] += ramp.slope * send;
        }
    }
  }
  for (size_t p = 0; p < np; ++p) {
    double a = 0.0, b = 0.0;
    for (long i = 0; i < count; ++i) {
      a += da[p][i], b += db[p][i];
      out[p][i] += a + b * static_cast<double>(i) * dt;
    }
  }
}

std::vector<std::vector<double>> LtiResponses::values(const std::vector<SourceInput>& inputs,
                                                      const std::vector<double>& times) const {
  const size_t np = labels_.size();
  const std::vector<double> base = base_values(inputs);
  std::vector<std::vector<double>> out;
  out.reserve(np);
  for (size_t p = 0; p < np; ++p) {
    out.emplace_back(times.size(), model_ ? base[p] : 0.0);
    if (!model_)
      for (size_t j = 0; j < times.size(); ++j) out[p][j] = value(p, times[j], inputs);
  }
  if (model_) {
    const double dt = times.size() >= 2 ? times[1] - times[0] : 0.0;
    modal_add(inputs, times, dt, out);
  }
  return out;
}

std::vector<double> LtiResponses::base_values(const std::vector<SourceInput>& inputs) const {
  std::vector<double> base(labels_.size());
  for (size_t p = 0; p < base.size(); ++p) {
    base[p] = y_dc_[p];
    for (size_t k = 0; k < sources_.size() && k < inputs.size(); ++k)
      base[p] += (inputs[k].initial - sources_[k].initial) * gain_[k][p];
  }
  return base;
}

// waveform() on the march's responses: GridOptions' rule by uniform halving, the corners as rows
// of their own.
class MarchGrid {
 public:
  MarchGrid(const LtiResponses& r, const std::vector<SourceInput>& inputs,
            const LtiResponses::GridOptions& grid, const std::vector<double>& base,
            LtiResponses::GridInfo& gi);
  Waveform build();

 private:
  // Probe p at time t in O(ramps inside the march window): the ramps older than the march's
  // end respond affinely, summed from prefix sums of slope and slope * time.
  double value_at(size_t p, double t) const;
  Rows rows_at(double t0, double dt, long count) const {
    Rows v(np_, std::vector<double>(count, 0.0));
    for (size_t p = 0; p < np_; ++p) std::fill(v[p].begin(), v[p].end(), base_[p]);
    r_.superpose(inputs_, t0, dt, count, v);
    return v;
  }
  // Counts the probe evaluations of a level at `step`; true when over max_evaluations.
  bool over_budget(double step) {
    const double evaluations = static_cast<double>(np_) * reach_ / step;
    gi_.evaluations += evaluations;
    if (grid_.max_evaluations > 0 && evaluations > grid_.max_evaluations) gi_.over_budget = true;
    return gi_.over_budget;
  }
  // The level's worst interpolation error at the cells' midpoints, over the grid probes.
  double level_error(const Rows& rows, const Rows& mids, double dt, long count) const;
  // Halves the grid until the rule holds (or max_rows stops it, with a warning); false when the
  // evaluation budget stops it.
  bool refine(Rows& rows, double& dt, long& count);
  Waveform assemble(const Rows& rows, double dt, long count) const;

  const LtiResponses& r_;
  const std::vector<SourceInput>& inputs_;
  const LtiResponses::GridOptions& grid_;
  const std::vector<double>& base_;
  LtiResponses::GridInfo& gi_;
  const size_t np_;
  const double end_;             // s, the march's end
  std::vector<double> corners_;  // source corners strictly inside the span, sorted, unique
  std::vector<std::vector<double>> sum_s_, sum_st_;  // [k][j]: prefix sums of slope, slope * t
  double reach_ = 0.0;  // s, the rows each ramp is evaluated on (inside its march window), summed
};

MarchGrid::MarchGrid(const LtiResponses& r, const std::vector<SourceInput>& inputs,
                     const LtiResponses::GridOptions& grid, const std::vector<double>& base,
                     LtiResponses::GridInfo& gi)
    : r_(r),
      inputs_(inputs),
      grid_(grid),
      base_(base),
      gi_(gi),
      np_(r.labels_.size()),
      end_(r.tau_.back()) {
  // Source corners strictly inside the span: rows of their own, so that a probe on a driven node
  // is exact between rows too (not with a given step: the caller asked for that grid).
  for (const SourceInput& in : inputs)
    for (const Ramp& ramp : in.ramps)
      if (grid.step <= 0 && ramp.t > grid.tstart && ramp.t < grid.tstop) corners_.push_back(ramp.t);
  std::sort(corners_.begin(), corners_.end());
  corners_.erase(std::unique(corners_.begin(), corners_.end()), corners_.end());
  sum_s_.resize(inputs.size());
  sum_st_.resize(inputs.size());
  for (size_t k = 0; k < inputs.size(); ++k) {
    sum_s_[k].assign(inputs[k].ramps.size() + 1, 0.0);
    sum_st_[k].assign(inputs[k].ramps.size() + 1, 0.0);
    for (size_t j = 0; j < inputs[k].ramps.size(); ++j) {
      sum_s_[k][j + 1] = sum_s_[k][j] + inputs[k].ramps[j].slope;
      sum_st_[k][j + 1] = sum_st_[k][j] + inputs[k].ramps[j].slope * inputs[k].ramps[j].t;
    }
  }
  // The superposition's cost at a step: each ramp is evaluated on the rows inside its march window
  // (beyond it the response is affine and costs nothing per row).
  for (const SourceInput& in : inputs)
    for (const Ramp& ramp : in.ramps)
      if (ramp.t < grid.tstop) reach_ += std::min(grid.tstop - std::max(ramp.t, grid.tstart), end_);
}

double MarchGrid::value_at(size_t p, double t) const {
  double y = base_[p];
  for (size_t k = 0; k < r_.sources_.size() && k < inputs_.size(); ++k) {
    const auto& ramps = inputs_[k].ramps;
    auto before = [&](double x) {  // ramps with t_j < x
      return static_cast<size_t>(std::lower_bound(ramps.begin(), ramps.end(), x,
                                                  [](const Ramp& r, double v) { return r.t < v; }) -
                                 ramps.begin());
    };
    const size_t hi = before(t), lo = std::min(hi, before(t - end_));
    const double rend = r_.r_[k][p].back(), send = r_.end_slope_[k][p];
    y += (rend - send * end_) * sum_s_[k][lo] + send * (t * sum_s_[k][lo] - sum_st_[k][lo]);
    for (size_t j = lo; j < hi; ++j) y += ramps[j].slope * r_.ramp_response(k, p, t - ramps[j].t);
  }
  return y;
}

double MarchGrid::level_error(const Rows& rows, const Rows& mids, double dt, long count) const {
  double worst = 0.0;
  // Cells holding a source corner are skipped: the corner becomes a row of its own below.
  std::vector<char> has_corner(count, 0);
  for (double c : corners_) {
    const long i = static_cast<long>(std::floor((c - grid_.tstart) / dt));
    if (i >= 0 && i < count) has_corner[i] = 1;
  }
  for (size_t p = 0; p < np_; ++p) {
    if (!grid_.grid_probes.empty() && (p >= grid_.grid_probes.size() || !grid_.grid_probes[p]))
      continue;
    const double scale = r_.is_current_[p] ? 1e3 : 1.0;  // 1 mV -> 1 uA
    for (long i = 0; i + 1 < count; ++i)
      if (!has_corner[i])
        worst =
            std::max(worst, scale * std::fabs(mids[p][i] - 0.5 * (rows[p][i] + rows[p][i + 1])));
    // A cell holding corners is tested piece by piece between them (the corners are rows of
    // their own): a fast response just after a corner is as visible as anywhere else.
    for (size_t c = 0; c < corners_.size();) {
      const long i = static_cast<long>(std::floor((corners_[c] - grid_.tstart) / dt));
      if (i < 0 || i + 1 >= count) {
        ++c;
        continue;
      }
      double a = grid_.tstart + static_cast<double>(i) * dt, ya = rows[p][i];
      for (; c < corners_.size() && corners_[c] < a + dt; ++c) {
        const double yc = value_at(p, corners_[c]);
        const double ym = value_at(p, 0.5 * (a + corners_[c]));
        worst = std::max(worst, scale * std::fabs(ym - 0.5 * (ya + yc)));
        a = corners_[c], ya = yc;
      }
      const double b = grid_.tstart + static_cast<double>(i + 1) * dt;
      const double ym = value_at(p, 0.5 * (a + b));
      worst = std::max(worst, scale * std::fabs(ym - 0.5 * (ya + rows[p][i + 1])));
    }
  }
  return worst;
}

bool MarchGrid::refine(Rows& rows, double& dt, long& count) {
  while (true) {
    if (over_budget(dt)) return false;
    const Rows mids = rows_at(grid_.tstart + 0.5 * dt, dt, count - 1);
    const double worst = level_error(rows, mids, dt, count);
    if (worst <= 0.5 * grid_.interp_tol) return true;
    // Budgeted: a smooth response's interpolation error falls as dt^2, so the step that meets
    // the tolerance is about dt sqrt(tol / worst); when even that level would be over budget,
    // stop now instead of computing the levels on the way (a kink needs finer still).
    if (grid_.max_evaluations > 0) {
      const double final_dt = dt * std::sqrt(0.5 * grid_.interp_tol / worst);
      const double predicted = static_cast<double>(np_) * reach_ / final_dt;
      if (predicted > grid_.max_evaluations) {
        gi_.evaluations += predicted;
        gi_.over_budget = true;
        return false;
      }
    }
    if (2 * count - 1 > grid_.max_rows) {
      gi_.warning = fmt::format(
          "LTI output grid stopped at {} rows (step {:g} s): linear interpolation between rows "
          "may be off by up to {:.3g} mV, over the {:g} mV target",
          count, dt, 2e3 * worst, 1e3 * grid_.interp_tol);
      return true;
    }
    // Interleave: the midpoints are the finer grid's odd rows.
    for (size_t p = 0; p < np_; ++p) {
      std::vector<double> fine(2 * count - 1);
      for (long i = 0; i < count; ++i) fine[2 * i] = rows[p][i];
      for (long i = 0; i + 1 < count; ++i) fine[2 * i + 1] = mids[p][i];
      rows[p].swap(fine);
    }
    count = 2 * count - 1;
    dt *= 0.5;
  }
}

Waveform MarchGrid::assemble(const Rows& rows, double dt, long count) const {
  Waveform w;
  Rows cols(np_);
  const double tiny = dt * 1e-6;
  size_t c = 0;
  for (long i = 0; i < count; ++i) {
    const double t = grid_.tstart + static_cast<double>(i) * dt;
    for (; c < corners_.size() && corners_[c] < t; ++c) {
      if (corners_[c] <= t - tiny && (w.time.empty() || corners_[c] >= w.time.back() + tiny)) {
        w.time.push_back(corners_[c]);
        for (size_t p = 0; p < np_; ++p) cols[p].push_back(value_at(p, corners_[c]));
      }
    }
    if (!w.time.empty() && t <= w.time.back()) continue;
    w.time.push_back(t);
    for (size_t p = 0; p < np_; ++p) cols[p].push_back(rows[p][i]);
  }
  for (size_t p = 0; p < np_; ++p) w.add_column(r_.labels_[p], std::move(cols[p]));
  gi_.rows = static_cast<long>(w.time.size());
  gi_.step = dt;
  return w;
}

Waveform MarchGrid::build() {
  const double span = grid_.tstop - grid_.tstart;
  double dt = grid_.step;
  Rows rows;
  long count = 0;
  if (dt > 0) {
    count = static_cast<long>(std::floor(span / dt * (1 + 1e-12))) + 1;
    if (over_budget(dt)) return Waveform{};
    rows = rows_at(grid_.tstart, dt, count);
  } else {
    dt = span;
    while (dt > coarsest_grid_step(span)) dt *= 0.5;
    count = static_cast<long>(std::llround(span / dt)) + 1;
    if (over_budget(dt)) return Waveform{};
    rows = rows_at(grid_.tstart, dt, count);
    if (!refine(rows, dt, count)) return Waveform{};
  }
  return assemble(rows, dt, count);
}

Waveform LtiResponses::waveform(const std::vector<SourceInput>& inputs, const GridOptions& grid,
                                GridInfo* info) const {
  GridInfo local;
  GridInfo& gi = info ? *info : local;
  gi = GridInfo{};
  for (const SourceInput& in : inputs) gi.corners += static_cast<long>(in.ramps.size());
  const std::vector<double> base = base_values(inputs);
  if (model_) return modal_waveform(inputs, grid, base, gi);
  return MarchGrid(*this, inputs, grid, base, gi).build();
}

}  // namespace isolink
