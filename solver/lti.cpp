#include "solver/lti.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <functional>

#include "solver/mna_system.h"

namespace isolink {

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
    if (!e->linear_time_invariant())
      return error_at(e->loc(), "element '" + e->name() +
                                    "' is not linear and time-invariant: the LTI engine cannot "
                                    "simulate it (use --engine transient)");
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

// e^x, phi1(x) = (e^x - 1) / x and phi2(x) = (e^x - 1 - x) / x^2: a mode x' = p x + u(t) moves
// over a step h, with u = b + g t on it, to e^{ph} x + h phi1(ph) b + h^2 phi2(ph) g.
struct Phi {
  std::complex<double> e, phi1, phi2;
};
Phi phi(std::complex<double> x) {
  Phi f;
  if (std::abs(x) < 1e-2) {  // series: the next terms are below 1e-16 relative
    f.phi2 = 0.5 + x * (1.0 / 6 + x * (1.0 / 24 + x * (1.0 / 120 + x * (1.0 / 720))));
    f.phi1 = 1.0 + x * f.phi2;
    f.e = 1.0 + x * f.phi1;
    return f;
  }
  f.e = std::exp(x);
  f.phi1 = (f.e - 1.0) / x;
  f.phi2 = (f.phi1 - 1.0) / x;
  return f;
}

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

// The output grid rule's first level: 20 ns or finer on a link's microseconds, but never more
// than 65,536 rows to start with, so a run of seconds (an RC of 1 s over 7 s: 350 million rows
// at 20 ns) starts coarse and is refined only as far as the 1 mV rule asks.
double coarsest_grid_step(double span) {
  return std::max(20e-9, span / 65536.0);
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
  const auto started = std::chrono::steady_clock::now();
  StatusOr<ReducedModel> model = reduce_circuit(circuit, unit, dc_solutions, probes, ro);
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

namespace {

// A piecewise-linear input's corner: at t, source k's slope changes by `slope`.
struct Corner {
  double t;
  size_t k;
  double slope;
};

// One step h of every mode: e^{ph}, h phi1(ph), h^2 phi2(ph) as real and imaginary parts.
struct ModalStep {
  double h = -1;
  std::vector<double> er, ei, f1r, f1i, f2r, f2i;
  void set(const ReducedModel& m, double step) {
    h = step;
    const size_t n = m.poles.size();
    for (auto* v : {&er, &ei, &f1r, &f1i, &f2r, &f2i}) v->resize(n);
    for (size_t i = 0; i < n; ++i) {
      const Phi f = phi(m.poles[i] * step);
      const std::complex<double> f1 = step * f.phi1, f2 = step * step * f.phi2;
      er[i] = f.e.real(), ei[i] = f.e.imag();
      f1r[i] = f1.real(), f1i[i] = f1.imag(), f2r[i] = f2.real(), f2i[i] = f2.imag();
    }
  }
};

// The march of LtiResponses::modal_add: the modes' states from corner to corner and query to
// query, the tail past the last corner, and the mode rates (ModeRates) when asked. The model
// and the rate arguments must outlive it.
class ModalMarch {
 public:
  // probe_weight, threshold and rate: ModeRates's, or nullptr (no rates).
  ModalMarch(const ReducedModel& m, size_t np, size_t nk, double uniform_dt,
             const std::vector<double>* probe_weight, double threshold, std::vector<double>* rate);

  // Adds the response to the corners (sorted by time) at `times` into out[p][j].
  void run(const std::vector<Corner>& corners, const std::vector<double>& times,
           std::vector<std::vector<double>>& out);

 private:
  const ModalStep* step_for(double h);
  void advance(double h);
  void take_corner(const Corner& corner);
  void enter_tail(double left);
  void tail_step(double h);
  void prune();
  void start_rates(const std::vector<double>& probe_weight, double threshold);
  void rate_at(size_t j);
  double tail_value(size_t p) const;
  double value(size_t p) const;

  // Past the last corner: see enter_tail.
  static constexpr double kTailTol = 1e-13;

  const ReducedModel& m_;
  const size_t nm_, np_, nk_;
  std::vector<double>* rate_;
  // Per mode, as real and imaginary parts in separate arrays (the loops below vectorise): its
  // state x, its input b = sum_k in_k (u_k - u_k(start)) and that input's slope g.
  std::vector<double> xr_, xi_, br_, bi_, gr_, gi_;
  std::vector<std::vector<double>> outr_, outi_;  // [p][mode]
  std::vector<double> u_, slope_;                 // u_k - initial, and its slope
  // The uniform step, and a few recent others (a pass over the midpoints of a locally refined
  // grid repeats a handful of gaps: twice each refinement level's step).
  ModalStep uniform_;
  std::array<ModalStep, 8> recent_;
  size_t next_recent_ = 0;
  bool active_ = false;              // a corner has passed: before it everything is zero
  std::vector<double> slope_scale_;  // largest |slope| a source has had
  bool tail_ = false;
  std::vector<size_t> slow_, fast_;  // mode indices in the tail; fast ones are dropped when decayed
  std::vector<double> dr_, di_;      // per fast mode: d = x - x_ss
  std::vector<double> tail_const_;   // per probe: what the modes settle to, and the direct term
  std::vector<double> tail_scale_;   // per probe: |tail_const| + sum |out d| at the tail's start
  // ModeRates: each mode's weight on the probes (squared, over the threshold squared), and 1 / p
  // and 1 / p^2 as real arrays, and |p|.
  std::vector<double> w2_, ipr_, ipi_, ip2r_, ip2i_, speed_;
};

ModalMarch::ModalMarch(const ReducedModel& m, size_t np, size_t nk, double uniform_dt,
                       const std::vector<double>* probe_weight, double threshold,
                       std::vector<double>* rate)
    : m_(m), nm_(m.poles.size()), np_(np), nk_(nk), rate_(rate) {
  const size_t nm = nm_;
  for (auto* v : {&xr_, &xi_, &br_, &bi_, &gr_, &gi_}) v->assign(nm, 0.0);
  outr_.assign(np, std::vector<double>(nm));
  outi_ = outr_;
  for (size_t p = 0; p < np; ++p)
    for (size_t i = 0; i < nm; ++i)
      outr_[p][i] = m.output[p][i].real(), outi_[p][i] = m.output[p][i].imag();
  u_.assign(nk, 0.0);
  slope_.assign(nk, 0.0);
  slope_scale_.assign(nk, 0.0);
  if (uniform_dt > 0) uniform_.set(m, uniform_dt);
  if (rate_) start_rates(*probe_weight, threshold);
}

// A cached step serves any h within 1e-9 of it: times t0 + i dt differ from i dt by rounding
// of t0 (1e-11 relative at 100 us on a 1 ns step); the states are not moved in time by it
// (each query restarts from its own time), only the phase e^{ph} is off by |p| 1e-9 h.
const ModalStep* ModalMarch::step_for(double h) {
  if (std::fabs(h - uniform_.h) <= 1e-9 * uniform_.h) return &uniform_;
  for (const ModalStep& st : recent_)
    if (std::fabs(h - st.h) <= 1e-9 * st.h) return &st;
  ModalStep& st = recent_[next_recent_];
  next_recent_ = (next_recent_ + 1) % recent_.size();
  st.set(m_, h);
  return &st;
}

void ModalMarch::advance(double h) {
  if (!(h > 0) || !active_) return;
  const ModalStep* st = step_for(h);
  const double *er = st->er.data(), *ei = st->ei.data(), *f1r = st->f1r.data(),
               *f1i = st->f1i.data(), *f2r = st->f2r.data(), *f2i = st->f2i.data();
  double *xr = xr_.data(), *xi = xi_.data(), *br = br_.data(), *bi = bi_.data();
  const double *gr = gr_.data(), *gi = gi_.data();
  for (size_t i = 0; i < nm_; ++i) {
    const double nr = er[i] * xr[i] - ei[i] * xi[i] + f1r[i] * br[i] - f1i[i] * bi[i] +
                      f2r[i] * gr[i] - f2i[i] * gi[i];
    const double ni = er[i] * xi[i] + ei[i] * xr[i] + f1r[i] * bi[i] + f1i[i] * br[i] +
                      f2r[i] * gi[i] + f2i[i] * gr[i];
    xr[i] = nr, xi[i] = ni;
    br[i] += gr[i] * h, bi[i] += gi[i] * h;
  }
  for (size_t k = 0; k < nk_; ++k) u_[k] += slope_[k] * h;
}

// The corner's slope change joins its source's slope and every mode's input slope g.
void ModalMarch::take_corner(const Corner& corner) {
  active_ = true;
  slope_[corner.k] += corner.slope;
  slope_scale_[corner.k] =
      std::max({slope_scale_[corner.k], std::fabs(corner.slope), std::fabs(slope_[corner.k])});
  const auto& in = m_.input[corner.k];
  for (size_t i = 0; i < nm_; ++i)
    gr_[i] += in[i].real() * corner.slope, gi_[i] += in[i].imag() * corner.slope;
}

// Tail: past the last corner, with every source's slope back to zero (up to rounding), each
// mode's input b is constant. A mode that decays within what is left of the record (|Re p|
// times the span left above 1) is written x = x_ss + d, x_ss = -b / p its steady state, and
// d just decays by e^{p h}: its share of a probe is the constant Re(out x_ss) plus Re(out d),
// and once max_p |out_pi d_i| is below kTailTol of that probe's scale it leaves the loop for
// good (|e^{p h}| < 1). Slower modes keep the exact update. A long record after the last edge
// (the worst-case search's edge response: 160,000 samples) then costs the slow modes alone.
void ModalMarch::enter_tail(double left) {
  for (size_t k = 0; k < nk_; ++k)
    if (std::fabs(slope_[k]) > 1e-12 * slope_scale_[k]) return;
  tail_const_.assign(np_, 0.0);
  tail_scale_.assign(np_, 0.0);
  for (size_t p = 0; p < np_; ++p)
    for (size_t k = 0; k < nk_; ++k) tail_const_[p] += m_.direct[k][p] * u_[k];
  for (size_t i = 0; i < nm_; ++i) {
    const std::complex<double> pole = m_.poles[i];
    if (!(-pole.real() * left > 1.0)) {
      slow_.push_back(i);
      continue;
    }
    const std::complex<double> xss = -std::complex<double>(br_[i], bi_[i]) / pole;
    fast_.push_back(i);
    dr_.push_back(xr_[i] - xss.real());
    di_.push_back(xi_[i] - xss.imag());
    for (size_t p = 0; p < np_; ++p) {
      tail_const_[p] += outr_[p][i] * xss.real() - outi_[p][i] * xss.imag();
      tail_scale_[p] += std::abs(m_.output[p][i]) * std::hypot(dr_.back(), di_.back());
    }
  }
  for (size_t p = 0; p < np_; ++p) tail_scale_[p] += std::fabs(tail_const_[p]);
  tail_ = true;
}

// One tail step of h: the slow modes' exact update, the fast ones' decay.
void ModalMarch::tail_step(double h) {
  if (!(h > 0)) return;
  const ModalStep* st = step_for(h);
  for (size_t i : slow_) {
    const double nr =
        st->er[i] * xr_[i] - st->ei[i] * xi_[i] + st->f1r[i] * br_[i] - st->f1i[i] * bi_[i];
    const double ni =
        st->er[i] * xi_[i] + st->ei[i] * xr_[i] + st->f1r[i] * bi_[i] + st->f1i[i] * br_[i];
    xr_[i] = nr, xi_[i] = ni;
  }
  for (size_t f = 0; f < fast_.size(); ++f) {
    const size_t i = fast_[f];
    const double nr = st->er[i] * dr_[f] - st->ei[i] * di_[f];
    const double ni = st->er[i] * di_[f] + st->ei[i] * dr_[f];
    dr_[f] = nr, di_[f] = ni;
  }
}

// Drops the fast modes whose share of every probe has decayed below kTailTol of its scale.
void ModalMarch::prune() {
  size_t kept = 0;
  for (size_t f = 0; f < fast_.size(); ++f) {
    const size_t i = fast_[f];
    const double d = std::hypot(dr_[f], di_[f]);
    bool live = false;
    for (size_t p = 0; p < np_ && !live; ++p)
      live = std::abs(m_.output[p][i]) * d > kTailTol * tail_scale_[p];
    if (!live) continue;
    fast_[kept] = i, dr_[kept] = dr_[f], di_[kept] = di_[f];
    ++kept;
  }
  fast_.resize(kept), dr_.resize(kept), di_.resize(kept);
}

// ModeRates: each mode's weight on the probes (squared, over the threshold squared), and the
// transient part d = x - x_ss of its state (x_ss = -(b + g t) / p - g / p^2 follows the input;
// d decays as e^{p t}), from 1 / p and 1 / p^2 kept as real arrays.
void ModalMarch::start_rates(const std::vector<double>& probe_weight, double threshold) {
  w2_.assign(nm_, 0.0);
  for (size_t p = 0; p < np_ && p < probe_weight.size(); ++p)
    for (size_t i = 0; i < nm_; ++i)
      w2_[i] = std::max(w2_[i], probe_weight[p] * std::abs(m_.output[p][i]));
  for (size_t i = 0; i < nm_; ++i) {
    w2_[i] = w2_[i] * w2_[i] / (threshold * threshold);
    const std::complex<double> ip = 1.0 / m_.poles[i], ip2 = ip * ip;
    ipr_.push_back(ip.real()), ipi_.push_back(ip.imag());
    ip2r_.push_back(ip2.real()), ip2i_.push_back(ip2.imag());
    speed_.push_back(std::abs(m_.poles[i]));
  }
}

void ModalMarch::rate_at(size_t j) {
  if (!rate_) return;
  double fastest = 0.0;
  auto consider = [&](size_t i, double d_r, double d_i) {
    if (w2_[i] * (d_r * d_r + d_i * d_i) > 1.0) fastest = std::max(fastest, speed_[i]);
  };
  const std::vector<double>&xr = xr_, &xi = xi_, &br = br_, &bi = bi_, &gr = gr_, &gi = gi_;
  const std::vector<double>&ipr = ipr_, &ipi = ipi_, &ip2r = ip2r_, &ip2i = ip2i_;
  if (!tail_) {
    for (size_t i = 0; i < nm_; ++i)
      consider(i, xr[i] + br[i] * ipr[i] - bi[i] * ipi[i] + gr[i] * ip2r[i] - gi[i] * ip2i[i],
               xi[i] + br[i] * ipi[i] + bi[i] * ipr[i] + gr[i] * ip2i[i] + gi[i] * ip2r[i]);
  } else {
    for (size_t i : slow_)
      consider(i, xr[i] + br[i] * ipr[i] - bi[i] * ipi[i], xi[i] + br[i] * ipi[i] + bi[i] * ipr[i]);
    for (size_t f = 0; f < fast_.size(); ++f) consider(fast_[f], dr_[f], di_[f]);
  }
  (*rate_)[j] = fastest;
}

// Probe p's value in the tail.
double ModalMarch::tail_value(size_t p) const {
  double d = tail_const_[p];
  for (size_t i : slow_) d += outr_[p][i] * xr_[i] - outi_[p][i] * xi_[i];
  for (size_t f = 0; f < fast_.size(); ++f)
    d += outr_[p][fast_[f]] * dr_[f] - outi_[p][fast_[f]] * di_[f];
  return d;
}

// Probe p's value before the tail.
double ModalMarch::value(size_t p) const {
  const double *orr = outr_[p].data(), *oi = outi_[p].data();
  const double *xr = xr_.data(), *xi = xi_.data();
  const size_t nm = nm_;
  double y0 = 0, y1 = 0;  // two partial sums: a shorter dependency chain
  size_t i = 0;
  for (; i + 1 < nm; i += 2) {
    y0 += orr[i] * xr[i] - oi[i] * xi[i];
    y1 += orr[i + 1] * xr[i + 1] - oi[i + 1] * xi[i + 1];
  }
  if (i < nm) y0 += orr[i] * xr[i] - oi[i] * xi[i];
  double d = y0 + y1;
  for (size_t k = 0; k < nk_; ++k) d += m_.direct[k][p] * u_[k];
  return d;
}

void ModalMarch::run(const std::vector<Corner>& corners, const std::vector<double>& times,
                     std::vector<std::vector<double>>& out) {
  if (rate_) rate_->assign(times.size(), 0.0);
  double tc = times.empty() ? 0.0 : times[0];
  if (!corners.empty()) tc = std::min(tc, corners[0].t);
  size_t c = 0;
  for (size_t j = 0; j < times.size(); ++j) {
    const double tq = times[j];
    if (tail_) {
      tail_step(tq - tc);
      tc = tq;
      if (j % 64 == 0) prune();
      rate_at(j);
      for (size_t p = 0; p < np_; ++p) out[p][j] += tail_value(p);
      continue;
    }
    for (; c < corners.size() && corners[c].t <= tq; ++c) {
      advance(corners[c].t - tc);
      tc = corners[c].t;
      take_corner(corners[c]);
    }
    advance(tq - tc);
    tc = tq;
    if (!active_) continue;
    if (c == corners.size() && j + 1 < times.size()) enter_tail(times.back() - tc);
    rate_at(j);
    for (size_t p = 0; p < np_; ++p) out[p][j] += value(p);
  }
}

}  // namespace

void LtiResponses::modal_add(const std::vector<SourceInput>& inputs,
                             const std::vector<double>& times, double uniform_dt,
                             std::vector<std::vector<double>>& out, ModeRates* rates) const {
  const size_t nk = std::min(sources_.size(), inputs.size());
  std::vector<Corner> corners;
  for (size_t k = 0; k < nk; ++k)
    for (const Ramp& r : inputs[k].ramps) corners.push_back({r.t, k, r.slope});
  std::stable_sort(corners.begin(), corners.end(),
                   [](const Corner& a, const Corner& b) { return a.t < b.t; });
  ModalMarch march(*model_, labels_.size(), nk, uniform_dt, rates ? &rates->probe_weight : nullptr,
                   rates ? rates->threshold : 0.0, rates ? &rates->rate : nullptr);
  march.run(corners, times, out);
}

std::vector<std::vector<double>> LtiResponses::values(const std::vector<SourceInput>& inputs,
                                                      const std::vector<double>& times) const {
  const size_t np = labels_.size();
  std::vector<std::vector<double>> out(np, std::vector<double>(times.size(), 0.0));
  const std::vector<double> base = base_values(inputs);
  for (size_t p = 0; p < np; ++p) {
    if (model_)
      std::fill(out[p].begin(), out[p].end(), base[p]);
    else
      for (size_t j = 0; j < times.size(); ++j) out[p][j] = value(p, times[j], inputs);
  }
  if (model_) {
    const double dt = times.size() >= 2 ? times[1] - times[0] : 0.0;
    modal_add(inputs, times, dt, out);
  }
  return out;
}

namespace {

using Rows = std::vector<std::vector<double>>;  // [probe][row]

// The reduced model's first grid level: the uniform grid of step dt, plus every corner inside the
// span as a row of its own.
std::vector<double> first_level(double tstart, double tstop, double dt,
                                const std::vector<double>& corners) {
  std::vector<double> t;
  const long count = static_cast<long>(std::floor((tstop - tstart) / dt * (1 + 1e-12))) + 1;
  for (long i = 0; i < count; ++i) t.push_back(tstart + static_cast<double>(i) * dt);
  t.insert(t.end(), corners.begin(), corners.end());
  std::sort(t.begin(), t.end());
  std::vector<double> out;  // closer than 1e-6 dt: one row (the uniform one first)
  for (double x : t)
    if (out.empty() || x >= out.back() + 1e-6 * dt) out.push_back(x);
  return out;
}

// GridOptions' rule by local refinement, as adaptive quadrature refines: every interval not yet
// accepted is tested at its midpoint; one that fails is split there (the midpoint, already
// computed, becomes a row) and its two halves are tested in the next pass. Each pass evaluates
// only the new midpoints. A midpoint alone can be fooled by a mode that turns through a whole
// period inside the interval (0, 0 and 0 at its ends and middle: the 15 m transformer link's
// ringing was 9 mV off that way), so an interval is also split while it is longer than 1 / |p|
// of the fastest mode still active at either end (`evaluate` gives those rates, ModeRates): the
// grid is sized from the circuit's time constants where they act. Returns the finest step; sets
// `warning` when max_rows stops it.
using Evaluate = std::function<Rows(const std::vector<double>&, double, std::vector<double>&)>;
double refine_grid(std::vector<double>& times, Rows& rows, const Evaluate& evaluate,
                   const LtiResponses::GridOptions& grid, const std::vector<bool>& is_current,
                   double dt, std::string& warning) {
  const size_t np = is_current.size();
  std::vector<double> mids, row_rate, mid_rate;
  Rows mid_values;
  {  // The first level's rows and midpoints in one pass (interleaved: dt / 2 is cached).
    std::vector<double> all, rate;
    all.reserve(2 * times.size());
    for (size_t j = 0; j < times.size(); ++j) {
      all.push_back(times[j]);
      if (j + 1 < times.size()) all.push_back(0.5 * (times[j] + times[j + 1]));
    }
    rows = evaluate(all, 0.5 * dt, rate);
    mid_values.resize(np);
    for (size_t p = 0; p < np; ++p) {
      mid_values[p].resize(times.size() - 1);
      for (size_t j = 0; j + 1 < times.size(); ++j) mid_values[p][j] = rows[p][2 * j + 1];
      for (size_t j = 0; 2 * j < all.size(); ++j) rows[p][j] = rows[p][2 * j];
      rows[p].resize(times.size());
    }
    for (size_t j = 0; j < times.size(); ++j) row_rate.push_back(rate[2 * j]);
    for (size_t j = 0; j + 1 < times.size(); ++j) mid_rate.push_back(rate[2 * j + 1]);
  }
  std::vector<size_t> open(times.size() - 1);  // intervals [times[i], times[i + 1]] to test
  for (size_t i = 0; i < open.size(); ++i) open[i] = i;
  double finest = dt;
  while (!open.empty()) {
    std::vector<char> split(open.size(), 0);
    size_t splits = 0;
    double worst = 0.0;
    for (size_t j = 0; j < open.size(); ++j) {
      const size_t i = open[j];
      double e = 0.0;
      for (size_t p = 0; p < np; ++p) {
        if (!grid.grid_probes.empty() && (p >= grid.grid_probes.size() || !grid.grid_probes[p]))
          continue;
        const double scale = is_current[p] ? 1e3 : 1.0;  // 1 mV -> 1 uA
        e = std::max(e, scale * std::fabs(mid_values[p][j] - 0.5 * (rows[p][i] + rows[p][i + 1])));
      }
      worst = std::max(worst, e);
      const double rate = std::max(row_rate[i], row_rate[i + 1]);
      if (e > 0.5 * grid.interp_tol || (times[i + 1] - times[i]) * rate > 1.0)
        split[j] = 1, ++splits;
    }
    if (splits == 0) break;
    if (static_cast<long>(times.size() + splits) > grid.max_rows) {
      warning = fmt::format(
          "LTI output grid stopped at {} rows (step {:g} s): linear interpolation between rows "
          "may be off by up to {:.3g} mV, over the {:g} mV target",
          times.size(), finest, 2e3 * worst, 1e3 * grid.interp_tol);
      break;
    }
    // The failing midpoints join the rows; their halves are the next pass's intervals.
    std::vector<double> new_times, new_rate;
    new_times.reserve(times.size() + splits);
    new_rate.reserve(times.size() + splits);
    Rows new_rows(np);
    for (auto& r : new_rows) r.reserve(times.size() + splits);
    std::vector<size_t> new_open;
    new_open.reserve(2 * splits);
    size_t j = 0;
    for (size_t i = 0; i < times.size(); ++i) {
      new_times.push_back(times[i]);
      new_rate.push_back(row_rate[i]);
      for (size_t p = 0; p < np; ++p) new_rows[p].push_back(rows[p][i]);
      if (j == open.size() || open[j] != i) continue;  // open is ascending
      if (split[j]) {
        new_open.push_back(new_times.size() - 1);
        new_times.push_back(0.5 * (times[i] + times[i + 1]));
        new_rate.push_back(mid_rate[j]);
        for (size_t p = 0; p < np; ++p) new_rows[p].push_back(mid_values[p][j]);
        new_open.push_back(new_times.size() - 1);
        finest = std::min(finest, 0.5 * (times[i + 1] - times[i]));
      }
      ++j;
    }
    times = std::move(new_times);
    row_rate = std::move(new_rate);
    rows = std::move(new_rows);
    open = std::move(new_open);
    mids.resize(open.size());
    for (size_t k = 0; k < open.size(); ++k) mids[k] = 0.5 * (times[open[k]] + times[open[k] + 1]);
    mid_values = evaluate(mids, 0.0, mid_rate);
  }
  return finest;
}

}  // namespace

Waveform LtiResponses::modal_waveform(const std::vector<SourceInput>& inputs,
                                      const GridOptions& grid, const std::vector<double>& base,
                                      GridInfo& gi) const {
  const size_t np = labels_.size();
  const double span = grid.tstop - grid.tstart;
  // The modes the grid must resolve: a share over a twentieth of the tolerance on a grid probe.
  ModeRates mode_rates;
  mode_rates.threshold = 0.05 * grid.interp_tol;
  for (size_t p = 0; p < np; ++p) {
    const bool looked_at =
        grid.grid_probes.empty() || (p < grid.grid_probes.size() && grid.grid_probes[p]);
    mode_rates.probe_weight.push_back(!looked_at ? 0.0 : is_current_[p] ? 1e3 : 1.0);
  }
  auto evaluate = [&](const std::vector<double>& times, double dt, std::vector<double>& rate) {
    Rows v(np);
    for (size_t p = 0; p < np; ++p) v[p].assign(times.size(), base[p]);
    modal_add(inputs, times, dt, v, &mode_rates);
    rate = std::move(mode_rates.rate);
    return v;
  };
  std::vector<double> times;
  Rows rows;
  double dt = grid.step;
  if (dt > 0) {
    times = first_level(grid.tstart, grid.tstop, dt, {});
    rows = Rows(np);
    for (size_t p = 0; p < np; ++p) rows[p].assign(times.size(), base[p]);
    modal_add(inputs, times, dt, rows);
  } else {
    // Rows gather where the response bends (after each corner, for as long as its fast modes
    // last) and stay coarse elsewhere: 1 ns and 1 ms time constants over 5 ms take about
    // 66,000 rows, where uniform halving went to its 4,000,000-row limit.
    std::vector<double> corners;
    for (const SourceInput& in : inputs)
      for (const Ramp& ramp : in.ramps)
        if (ramp.t > grid.tstart && ramp.t < grid.tstop) corners.push_back(ramp.t);
    dt = span;
    while (dt > coarsest_grid_step(span)) dt *= 0.5;
    gi.coarse_step = dt;
    times = first_level(grid.tstart, grid.tstop, dt, corners);
    dt = refine_grid(times, rows, evaluate, grid, is_current_, dt, gi.warning);
  }
  Waveform w;
  w.time = std::move(times);
  for (size_t p = 0; p < np; ++p) w.add_column(labels_[p], std::move(rows[p]));
  gi.rows = static_cast<long>(w.time.size());
  gi.step = dt;
  return w;
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
