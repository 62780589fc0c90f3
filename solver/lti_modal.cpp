// The LTI engine's output from the reduced model (solver/lti.h): the modes marched over the
// query times (LtiResponses::modal_add) and the output grid refined where the response bends
// (LtiResponses::modal_waveform).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "base/wide_simd.h"
#include "solver/lti.h"
#include "solver/lti_internal.h"

namespace isolink {

// The march's hot loops: ISOLINK_WIDE_SIMD (base/wide_simd.h).

using lti_internal::coarsest_grid_step;
using lti_internal::Phi;
using lti_internal::phi;
using lti_internal::Rows;

namespace {

// A piecewise-linear input's corner: at t, source k's slope changes by `slope`.
struct Corner {
  double t;
  size_t k;
  double slope;
};

// The modes' poles p and their reciprocals 1 / p as real and imaginary parts: a step's factors
// without a complex division (ModalStep::set).
struct ModePoles {
  std::vector<double> pr, pi, ipr, ipi;
  explicit ModePoles(const ReducedModel& m) {
    for (const std::complex<double> p : m.poles) {
      const std::complex<double> ip = 1.0 / p;
      pr.push_back(p.real()), pi.push_back(p.imag());
      ipr.push_back(ip.real()), ipi.push_back(ip.imag());
    }
  }
};

// One step h of every mode: e^{ph}, h phi1(ph), h^2 phi2(ph) as real and imaginary parts.
// Away from ph = 0 (|ph| >= 1e-2, where phi's series is used): h phi1 = (e^{ph} - 1) / p and
// h^2 phi2 = (h phi1 - h) / p, from 1 / p, the same values as phi() gives (lti_internal.h) up
// to rounding, without its complex divisions (a long record sets millions of steps: the gaps
// to and from its corners).
struct ModalStep {
  double h = -1;
  std::vector<double> er, ei, f1r, f1i, f2r, f2i;
  void set(const ModePoles& m, double step) {
    h = step;
    const size_t n = m.pr.size();
    for (auto* v : {&er, &ei, &f1r, &f1i, &f2r, &f2i}) v->resize(n);
    for (size_t i = 0; i < n; ++i) {
      const double xr = m.pr[i] * step, xi = m.pi[i] * step;
      if (xr * xr + xi * xi < 1e-4) {
        const Phi f = phi({xr, xi});
        const std::complex<double> f1 = step * f.phi1, f2 = step * step * f.phi2;
        er[i] = f.e.real(), ei[i] = f.e.imag();
        f1r[i] = f1.real(), f1i[i] = f1.imag(), f2r[i] = f2.real(), f2i[i] = f2.imag();
        continue;
      }
      const double mag = std::exp(xr);
      er[i] = mag * std::cos(xi), ei[i] = mag * std::sin(xi);  // one sincos call (GCC)
      const double ar = er[i] - 1.0, ai = ei[i];               // (e - 1) / p
      f1r[i] = ar * m.ipr[i] - ai * m.ipi[i], f1i[i] = ar * m.ipi[i] + ai * m.ipr[i];
      const double br = f1r[i] - step, bi = f1i[i];  // (h phi1 - h) / p
      f2r[i] = br * m.ipr[i] - bi * m.ipi[i], f2i[i] = br * m.ipi[i] + bi * m.ipr[i];
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

  // Adds the response to the corners (sorted by time) at `times` into out[p][j]. A later call
  // continues from where the last one stopped (its last query time and the corners taken so far):
  // the next call's times and the corners passed must carry on from there (the same corners
  // vector). `record_end`: where the queries will end (0: this call's last time); the tail's
  // fast modes are those that decay within it.
  void run(const std::vector<Corner>& corners, const std::vector<double>& times,
           std::vector<std::vector<double>>& out, double record_end = 0.0);
  // For the next run(): the uniform step of its queries (0: none) and where its mode rates go
  // (nullptr: none; a march built without rates never gives them).
  void set_pass(double uniform_dt, std::vector<double>* rate) {
    if (uniform_dt > 0 && std::fabs(uniform_dt - uniform_.h) > 1e-9 * uniform_dt)
      uniform_.set(poles_, uniform_dt);
    rate_ = w2_.empty() ? nullptr : rate;
  }
  // After run() has taken every corner: each mode's state x split into its steady state
  // x_ss = -b / p and the transient d = x - x_ss (the probes' constant and amplitudes), when every
  // slope is zero; false otherwise.
  bool closed_tail(LtiResponses::ModalTail& tail) const;

 private:
  // Past the last corner with every source's slope back to zero (up to rounding): each mode's
  // input is then constant, and its state tends to steady_state(i) = -b_i / p_i.
  bool slopes_ended() const;
  std::complex<double> steady_state(size_t i) const {
    return -std::complex<double>(br_[i], bi_[i]) / m_.poles[i];
  }
  // The direct terms' share of probe p at the present inputs.
  double direct_value(size_t p) const;
  const ModalStep* step_for(double h);
  void advance(double h);
  void take_corner(const Corner& corner);
  void enter_tail(double left);
  void tail_step(double h);
  size_t uniform_run(const std::vector<double>& times, size_t j, double tc) const;
  void tail_block(size_t j, size_t end, std::vector<std::vector<double>>& out);
  void prune();
  bool fast_mode_live(size_t i, double dr, double di) const;
  void start_rates(const std::vector<double>& probe_weight, double threshold);
  void rate_at(size_t j);
  double tail_value(size_t p) const;
  double value(size_t p) const;

  // Past the last corner: see enter_tail.
  static constexpr double kTailTol = 1e-13;

  const ReducedModel& m_;
  ModePoles poles_;
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
  bool started_ = false;             // run() has been called: tc_ and c_ hold
  double tc_ = 0.0;                  // the time of the state
  size_t c_ = 0;                     // the corners taken
  std::vector<double> slope_scale_;  // largest |slope| a source has had
  bool tail_ = false;
  std::vector<size_t> slow_, fast_;  // mode indices in the tail; fast ones are dropped when decayed
  std::vector<double> dr_, di_;      // per fast mode: d = x - x_ss
  std::vector<double> tail_const_;   // per probe: what the modes settle to, and the direct term
  std::vector<double> tail_scale_;   // per probe: |tail_const| + sum |out d| at the tail's start
  std::vector<double> live_limit2_;  // per probe: (kTailTol tail_scale)^2
  std::vector<std::vector<double>> out_norm2_;  // [p][mode]: |output|^2
  // ModeRates: each mode's weight on the probes (squared, over the threshold squared), 1 / p^2 as
  // real arrays (1 / p: poles_), and |p|.
  std::vector<double> w2_, ip2r_, ip2i_, speed_;
  std::vector<size_t> by_speed_;  // the modes by |p|, fastest first
  // rate_at: by_speed_[0..dead_) were found below the threshold since the last corner. Between
  // corners each mode's transient part decays (d <- e^{ph} d, |e^{ph}| <= 1 when every pole is
  // stable: decays_), so a mode found below it stays below until the next corner.
  size_t dead_ = 0;
  bool decays_ = false;
  bool sloped_ = false;  // some source's slope is not zero (take_corner)
};

ModalMarch::ModalMarch(const ReducedModel& m, size_t np, size_t nk, double uniform_dt,
                       const std::vector<double>* probe_weight, double threshold,
                       std::vector<double>* rate)
    : m_(m), poles_(m), nm_(m.poles.size()), np_(np), nk_(nk), rate_(rate) {
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
  if (uniform_dt > 0) uniform_.set(poles_, uniform_dt);
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
  st.set(poles_, h);
  return &st;
}

ISOLINK_WIDE_SIMD void ModalMarch::advance(double h) {
  if (!(h > 0) || !active_) return;
  const ModalStep* st = step_for(h);
  const double *er = st->er.data(), *ei = st->ei.data(), *f1r = st->f1r.data(),
               *f1i = st->f1i.data(), *f2r = st->f2r.data(), *f2i = st->f2i.data();
  double *xr = xr_.data(), *xi = xi_.data(), *br = br_.data(), *bi = bi_.data();
  const double *gr = gr_.data(), *gi = gi_.data();
  if (!sloped_) {  // every input flat: x <- e x + h phi1 b, b constant
    for (size_t i = 0; i < nm_; ++i) {
      const double nr = er[i] * xr[i] - ei[i] * xi[i] + f1r[i] * br[i] - f1i[i] * bi[i];
      const double ni = er[i] * xi[i] + ei[i] * xr[i] + f1r[i] * bi[i] + f1i[i] * br[i];
      xr[i] = nr, xi[i] = ni;
    }
    return;
  }
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

// The corner's slope change joins its source's slope and every mode's input slope g. A ramp's
// end brings its source's slope back to zero up to rounding (1e-12 of the largest it has had,
// as slopes_ended tests): it is then set to zero, and once every source is flat, g is zero and
// advance takes its shorter form (no f2 g term, b constant) until the next ramp starts.
void ModalMarch::take_corner(const Corner& corner) {
  active_ = true;
  double& slope = slope_[corner.k];
  slope += corner.slope;
  slope_scale_[corner.k] =
      std::max({slope_scale_[corner.k], std::fabs(corner.slope), std::fabs(slope)});
  if (std::fabs(slope) <= 1e-12 * slope_scale_[corner.k]) slope = 0.0;
  dead_ = 0;
  sloped_ = std::any_of(slope_.begin(), slope_.end(), [](double g) { return g != 0.0; });
  if (!sloped_) {
    std::fill(gr_.begin(), gr_.end(), 0.0);
    std::fill(gi_.begin(), gi_.end(), 0.0);
    return;
  }
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
bool ModalMarch::slopes_ended() const {
  for (size_t k = 0; k < nk_; ++k)
    if (std::fabs(slope_[k]) > 1e-12 * slope_scale_[k]) return false;
  return true;
}

double ModalMarch::direct_value(size_t p) const {
  double d = 0;
  for (size_t k = 0; k < nk_; ++k) d += m_.direct[k][p] * u_[k];
  return d;
}

void ModalMarch::enter_tail(double left) {
  if (!slopes_ended()) return;
  tail_const_.assign(np_, 0.0);
  tail_scale_.assign(np_, 0.0);
  for (size_t p = 0; p < np_; ++p) tail_const_[p] = direct_value(p);
  for (size_t i = 0; i < nm_; ++i) {
    const std::complex<double> pole = m_.poles[i];
    if (!(-pole.real() * left > 1.0)) {
      slow_.push_back(i);
      continue;
    }
    const std::complex<double> xss = steady_state(i);
    fast_.push_back(i);
    dr_.push_back(xr_[i] - xss.real());
    di_.push_back(xi_[i] - xss.imag());
    for (size_t p = 0; p < np_; ++p) {
      tail_const_[p] += outr_[p][i] * xss.real() - outi_[p][i] * xss.imag();
      tail_scale_[p] += std::abs(m_.output[p][i]) * std::hypot(dr_.back(), di_.back());
    }
  }
  for (size_t p = 0; p < np_; ++p) tail_scale_[p] += std::fabs(tail_const_[p]);
  live_limit2_.assign(np_, 0.0);
  out_norm2_.assign(np_, std::vector<double>(nm_));
  for (size_t p = 0; p < np_; ++p) {
    live_limit2_[p] = kTailTol * tail_scale_[p] * (kTailTol * tail_scale_[p]);
    for (size_t i = 0; i < nm_; ++i) out_norm2_[p][i] = std::norm(m_.output[p][i]);
  }
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

// How many of the queries from j on follow each other (and tc) by the uniform step: the run
// tail_block takes.
size_t ModalMarch::uniform_run(const std::vector<double>& times, size_t j, double tc) const {
  if (!(uniform_.h > 0)) return 0;
  const double tol = 1e-9 * uniform_.h;
  size_t end = j;
  for (double prev = tc; end < times.size() && std::fabs(times[end] - prev - uniform_.h) <= tol;
       ++end)
    prev = times[end];
  return end - j;
}

// Two doubles as one SIMD register (GCC's and Clang's vector extension: SSE2 on x86-64, NEON on
// arm64); arithmetic on it is lane by lane, the same operations as on two doubles.
using Pair = double __attribute__((vector_size(16)));

// The modes' recursions over queries [q0, q1) of the uniform step, 2P of them a pair per SIMD
// register and one more on scalars when kOdd: x <- e x + c (kAffine; x <- e x for the fast
// modes' transient parts), and out[p][q] += Re(o_p x) for each mode in turn, after `base[p]`
// when kBase. One pass over out: the recursions are independent, so the modes share the
// multiplies' latency and the vector units, and each out[p][q] still gets its terms one after
// another in the modes' order, the sums of march mode by mode to the bit. mode[m]: the modes,
// cr, ci (nullptr unless kAffine) and xr, xi theirs (xr, xi updated).
template <int P, bool kOdd, bool kAffine, bool kBase>
void march_modes(const ModalStep& st, const size_t* mode, const double* cr, const double* ci,
                 double* xr, double* xi, const std::vector<std::vector<double>>& outr,
                 const std::vector<std::vector<double>>& outi, const std::vector<double>& base,
                 size_t q0, size_t q1, std::vector<std::vector<double>>& out) {
  constexpr int kLast = 2 * P;  // the odd mode's index
  auto pair = [](double lo, double hi) { return Pair{lo, hi}; };
  Pair er[P + 1], ei[P + 1], c_r[P + 1], c_i[P + 1], ar[P + 1], ai[P + 1];  // + 1: P may be 0
  for (int k = 0; k < P; ++k) {
    const size_t m0 = mode[2 * k], m1 = mode[2 * k + 1];
    er[k] = pair(st.er[m0], st.er[m1]), ei[k] = pair(st.ei[m0], st.ei[m1]);
    c_r[k] = kAffine ? pair(cr[2 * k], cr[2 * k + 1]) : Pair{0, 0};
    c_i[k] = kAffine ? pair(ci[2 * k], ci[2 * k + 1]) : Pair{0, 0};
  }
  const double er1 = kOdd ? st.er[mode[kLast]] : 0, ei1 = kOdd ? st.ei[mode[kLast]] : 0;
  const double cr1 = kOdd && kAffine ? cr[kLast] : 0, ci1 = kOdd && kAffine ? ci[kLast] : 0;
  for (size_t p = 0; p < out.size(); ++p) {
    Pair o_r[P + 1], o_i[P + 1];
    for (int k = 0; k < P; ++k) {
      ar[k] = pair(xr[2 * k], xr[2 * k + 1]), ai[k] = pair(xi[2 * k], xi[2 * k + 1]);
      o_r[k] = pair(outr[p][mode[2 * k]], outr[p][mode[2 * k + 1]]);
      o_i[k] = pair(outi[p][mode[2 * k]], outi[p][mode[2 * k + 1]]);
    }
    double ar1 = kOdd ? xr[kLast] : 0, ai1 = kOdd ? xi[kLast] : 0;
    const double o_r1 = kOdd ? outr[p][mode[kLast]] : 0, o_i1 = kOdd ? outi[p][mode[kLast]] : 0;
    const double b = kBase ? base[p] : 0;
    double* y = out[p].data();
    for (size_t q = q0; q < q1; ++q) {
      double acc = y[q];
      if constexpr (kBase) acc += b;
      for (int k = 0; k < P; ++k) {
        Pair nr = er[k] * ar[k] - ei[k] * ai[k];
        Pair ni = er[k] * ai[k] + ei[k] * ar[k];
        if constexpr (kAffine) nr += c_r[k], ni += c_i[k];
        ar[k] = nr, ai[k] = ni;
        const Pair term = o_r[k] * nr - o_i[k] * ni;
        acc += term[0];
        acc += term[1];
      }
      if constexpr (kOdd) {
        double nr = er1 * ar1 - ei1 * ai1;
        double ni = er1 * ai1 + ei1 * ar1;
        if constexpr (kAffine) nr += cr1, ni += ci1;
        ar1 = nr, ai1 = ni;
        acc += o_r1 * nr - o_i1 * ni;
      }
      y[q] = acc;
    }
    if (p + 1 < out.size()) continue;
    for (int k = 0; k < P; ++k)
      xr[2 * k] = ar[k][0], xr[2 * k + 1] = ar[k][1], xi[2 * k] = ai[k][0],
             xi[2 * k + 1] = ai[k][1];
    if constexpr (kOdd) xr[kLast] = ar1, xi[kLast] = ai1;
  }
}

// march_modes over `count` modes (any number), one pass over out per eight (nine for the last
// pass), out[p][q] += base[p] first (kBase; also when there are no modes).
template <bool kAffine, bool kBase>
void march_mode_groups(const ModalStep& st, const size_t* mode, const double* cr, const double* ci,
                       double* xr, double* xi, size_t count,
                       const std::vector<std::vector<double>>& outr,
                       const std::vector<std::vector<double>>& outi,
                       const std::vector<double>& base, size_t q0, size_t q1,
                       std::vector<std::vector<double>>& out) {
  auto pass = [&](auto pairs, auto odd, auto with_base, size_t g) {
    march_modes<decltype(pairs)::value, decltype(odd)::value, kAffine, decltype(with_base)::value>(
        st, mode + g, kAffine ? cr + g : nullptr, kAffine ? ci + g : nullptr, xr + g, xi + g, outr,
        outi, base, q0, q1, out);
  };
  using std::integral_constant;
  size_t g = 0;
  for (; count - g > 9; g += 8)  // the base with the first pass only
    if (g == 0)
      pass(integral_constant<int, 4>{}, std::false_type{}, integral_constant<bool, kBase>{}, g);
    else
      pass(integral_constant<int, 4>{}, std::false_type{}, std::false_type{}, g);
  // The last 0-9 modes: pairs, and the odd one; a pass with none only to add the base.
  auto last = [&](auto with_base) {
    using WithBase = decltype(with_base);
    auto rest = [&](auto left) {
      constexpr int k = decltype(left)::value;
      if constexpr (k > 0 || WithBase::value)
        pass(integral_constant<int, k / 2>{}, integral_constant<bool, k % 2 == 1>{}, WithBase{}, g);
    };
    [&]<int... K>(std::integer_sequence<int, K...>) {
      ((count - g == static_cast<size_t>(K) ? rest(integral_constant<int, K>{}) : void()), ...);
    }
    (std::make_integer_sequence<int, 10>{});
  };
  if (g == 0)
    last(integral_constant<bool, kBase>{});
  else
    last(std::false_type{});
}

// Queries j..end-1 of the tail on the uniform step, mode by mode rather than query by query (the
// same updates and sums as tail_step, prune and tail_value, in another order: a mode's state
// stays in registers over the whole run, and a long record costs its few live modes alone).
void ModalMarch::tail_block(size_t j, size_t end, std::vector<std::vector<double>>& out) {
  const ModalStep& st = uniform_;
  {  // The constant, and the slow modes: x <- e x + f1 b (b constant in the tail).
    const size_t ns = slow_.size();
    std::vector<double> cr(ns), ci(ns), xr(ns), xi(ns);
    for (size_t s = 0; s < ns; ++s) {
      const size_t i = slow_[s];
      cr[s] = st.f1r[i] * br_[i] - st.f1i[i] * bi_[i];
      ci[s] = st.f1r[i] * bi_[i] + st.f1i[i] * br_[i];
      xr[s] = xr_[i], xi[s] = xi_[i];
    }
    march_mode_groups<true, true>(st, slow_.data(), cr.data(), ci.data(), xr.data(), xi.data(), ns,
                                  outr_, outi_, tail_const_, j, end, out);
    for (size_t s = 0; s < ns; ++s) xr_[slow_[s]] = xr[s], xi_[slow_[s]] = xi[s];
  }
  // Fast modes: d <- e d, each dropped at the first query q (q % 64 == 0, as prune) where its
  // share of every probe is below kTailTol of its scale. In chunks from one such query to the
  // next: the chunk's first query steps, tests and adds mode by mode, the rest march_modes.
  for (size_t q = j; q < end && !fast_.empty();) {
    const size_t chunk_end = std::min(end, (q / 64 + 1) * 64);
    size_t kept = 0;
    for (size_t f = 0; f < fast_.size(); ++f) {
      const size_t i = fast_[f];
      const double dr = st.er[i] * dr_[f] - st.ei[i] * di_[f];
      const double di = st.er[i] * di_[f] + st.ei[i] * dr_[f];
      if (q % 64 == 0 && !fast_mode_live(i, dr, di)) continue;  // dropped
      for (size_t p = 0; p < np_; ++p) out[p][q] += outr_[p][i] * dr - outi_[p][i] * di;
      fast_[kept] = i, dr_[kept] = dr, di_[kept] = di;
      ++kept;
    }
    fast_.resize(kept), dr_.resize(kept), di_.resize(kept);
    march_mode_groups<false, false>(st, fast_.data(), nullptr, nullptr, dr_.data(), di_.data(),
                                    kept, outr_, outi_, tail_const_, q + 1, chunk_end, out);
    q = chunk_end;
  }
}

// Whether fast mode i, its transient part at d, still moves some probe by kTailTol of its scale.
// Squared (|o|^2 |d|^2 against (kTailTol scale)^2): two complex moduli per mode every 64
// queries cost a third of the march of the modes between.
bool ModalMarch::fast_mode_live(size_t i, double dr, double di) const {
  const double d2 = dr * dr + di * di;
  for (size_t p = 0; p < np_; ++p)
    if (out_norm2_[p][i] * d2 > live_limit2_[p]) return true;
  return false;
}

// Drops the fast modes whose share of every probe has decayed below kTailTol of its scale.
void ModalMarch::prune() {
  size_t kept = 0;
  for (size_t f = 0; f < fast_.size(); ++f) {
    const size_t i = fast_[f];
    if (!fast_mode_live(i, dr_[f], di_[f])) continue;
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
    const std::complex<double> ip(poles_.ipr[i], poles_.ipi[i]), ip2 = ip * ip;
    ip2r_.push_back(ip2.real()), ip2i_.push_back(ip2.imag());
    speed_.push_back(std::abs(m_.poles[i]));
  }
  by_speed_.resize(nm_);
  for (size_t i = 0; i < nm_; ++i) by_speed_[i] = i;
  std::stable_sort(by_speed_.begin(), by_speed_.end(),
                   [&](size_t a, size_t b) { return speed_[a] > speed_[b]; });
  decays_ = std::all_of(m_.poles.begin(), m_.poles.end(),
                        [](std::complex<double> p) { return p.real() <= 0.0; });
}

void ModalMarch::rate_at(size_t j) {
  if (!rate_) return;
  double fastest = 0.0;
  auto consider = [&](size_t i, double d_r, double d_i) {
    if (w2_[i] * (d_r * d_r + d_i * d_i) > 1.0) fastest = std::max(fastest, speed_[i]);
  };
  const std::vector<double>&xr = xr_, &xi = xi_, &br = br_, &bi = bi_, &gr = gr_, &gi = gi_;
  const std::vector<double>&ipr = poles_.ipr, &ipi = poles_.ipi, &ip2r = ip2r_, &ip2i = ip2i_;
  if (!tail_) {
    // Fastest first: the first live mode is the answer (right after a corner, where most rows
    // are, one of the first few), past those already found dead since the last corner.
    size_t k = dead_;
    for (; k < nm_; ++k) {
      const size_t i = by_speed_[k];
      const double d_r =
          xr[i] + br[i] * ipr[i] - bi[i] * ipi[i] + gr[i] * ip2r[i] - gi[i] * ip2i[i];
      const double d_i =
          xi[i] + br[i] * ipi[i] + bi[i] * ipr[i] + gr[i] * ip2i[i] + gi[i] * ip2r[i];
      if (w2_[i] * (d_r * d_r + d_i * d_i) > 1.0) {
        fastest = speed_[i];
        break;
      }
    }
    if (decays_) dead_ = k;
  } else {
    for (size_t i : slow_)
      consider(i, xr[i] + br[i] * ipr[i] - bi[i] * ipi[i], xi[i] + br[i] * ipi[i] + bi[i] * ipr[i]);
    for (size_t f = 0; f < fast_.size(); ++f) consider(fast_[f], dr_[f], di_[f]);
  }
  (*rate_)[j] = fastest;
}

bool ModalMarch::closed_tail(LtiResponses::ModalTail& tail) const {
  if (!slopes_ended()) return false;
  tail.poles = m_.poles;
  tail.amplitude.assign(np_, std::vector<std::complex<double>>(nm_));
  for (size_t p = 0; p < np_; ++p) tail.constant[p] += direct_value(p);
  for (size_t i = 0; i < nm_; ++i) {
    const std::complex<double> xss = steady_state(i);
    const std::complex<double> d = std::complex<double>(xr_[i], xi_[i]) - xss;
    for (size_t p = 0; p < np_; ++p) {
      tail.constant[p] += (m_.output[p][i] * xss).real();
      tail.amplitude[p][i] = m_.output[p][i] * d;
    }
  }
  return true;
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
ISOLINK_WIDE_SIMD double ModalMarch::value(size_t p) const {
  const double *orr = outr_[p].data(), *oi = outi_[p].data();
  const double *xr = xr_.data(), *xi = xi_.data();
  const size_t nm = nm_;
  // Four partial sums in one vector (lane k: the modes i = k mod 4), then the rest.
  using Quad = double __attribute__((vector_size(32)));
  Quad y{0, 0, 0, 0}, a, b, c, e;
  size_t i = 0;
  for (; i + 4 <= nm; i += 4) {
    std::memcpy(&a, orr + i, sizeof a), std::memcpy(&b, xr + i, sizeof b);
    std::memcpy(&c, oi + i, sizeof c), std::memcpy(&e, xi + i, sizeof e);
    y += a * b - c * e;
  }
  double d = (y[0] + y[1]) + (y[2] + y[3]);
  for (; i < nm; ++i) d += orr[i] * xr[i] - oi[i] * xi[i];
  for (size_t k = 0; k < nk_; ++k) d += m_.direct[k][p] * u_[k];
  return d;
}

void ModalMarch::run(const std::vector<Corner>& corners, const std::vector<double>& times,
                     std::vector<std::vector<double>>& out, double record_end) {
  if (rate_) rate_->assign(times.size(), 0.0);
  if (!started_) {
    tc_ = times.empty() ? 0.0 : times[0];
    if (!corners.empty()) tc_ = std::min(tc_, corners[0].t);
    started_ = true;
  }
  double tc = tc_;
  size_t c = c_;
  const double end = times.empty() ? tc : std::max(record_end, times.back());
  for (size_t j = 0; j < times.size(); ++j) {
    const double tq = times[j];
    if (tail_ && !rate_) {
      if (const size_t run = uniform_run(times, j, tc); run >= 64) {
        tail_block(j, j + run, out);
        j += run - 1;
        tc = times[j];
        continue;
      }
    }
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
    if (c == corners.size() && tc < end) enter_tail(end - tc);
    rate_at(j);
    for (size_t p = 0; p < np_; ++p) out[p][j] += value(p);
  }
  tc_ = tc, c_ = c;
}

}  // namespace

namespace {

// Every input's corners (the first nk inputs, but those `tied`: their leader's carry them), by
// time.
std::vector<Corner> sorted_corners(const std::vector<SourceInput>& inputs, size_t nk,
                                   const std::vector<char>& tied) {
  std::vector<Corner> corners;
  for (size_t k = 0; k < nk; ++k)
    if (!tied[k])
      for (const Ramp& r : inputs[k].ramps) corners.push_back({r.t, k, r.slope});
  std::stable_sort(corners.begin(), corners.end(),
                   [](const Corner& a, const Corner& b) { return a.t < b.t; });
  return corners;
}

}  // namespace

void LtiResponses::modal_add(const std::vector<SourceInput>& inputs,
                             const std::vector<double>& times, double uniform_dt,
                             std::vector<std::vector<double>>& out, ModeRates* rates) const {
  if (!follows_ties(inputs)) {
    for (auto& row : out)
      std::fill(row.begin(), row.end(), std::numeric_limits<double>::quiet_NaN());
    return;
  }
  const size_t nk = std::min(sources_.size(), inputs.size());
  const std::vector<Corner> corners = sorted_corners(inputs, nk, tied_sources());
  ModalMarch march(*model_, labels_.size(), nk, uniform_dt, rates ? &rates->probe_weight : nullptr,
                   rates ? rates->threshold : 0.0, rates ? &rates->rate : nullptr);
  march.run(corners, times, out);
}

std::optional<LtiResponses::ModalTail> LtiResponses::modal_tail(
    const std::vector<SourceInput>& inputs, double t0) const {
  if (!model_ || !follows_ties(inputs)) return std::nullopt;
  const size_t nk = std::min(sources_.size(), inputs.size());
  const std::vector<Corner> corners = sorted_corners(inputs, nk, tied_sources());
  if (!corners.empty() && corners.back().t > t0) return std::nullopt;
  ModalMarch march(*model_, labels_.size(), nk, 0.0, nullptr, 0.0, nullptr);
  std::vector<std::vector<double>> at_t0(labels_.size(), std::vector<double>(1, 0.0));
  march.run(corners, {t0}, at_t0);
  ModalTail tail;
  tail.t0 = t0;
  tail.constant = base_values(inputs);
  if (!march.closed_tail(tail)) return std::nullopt;
  return tail;
}

namespace {

// The reduced model's first grid level over uniform rows i0..i1 (t = tstart + i dt) and the
// corners (sorted) between them: one row per uniform time and per corner, where two are closer
// than 1e-6 dt one row, a corner's time rather than a uniform one's (the first of two corners).
// A window's ends depend only on the uniform time and the corners within 1e-6 dt of it, so two
// windows meeting there agree on their common row.
std::vector<double> first_level(double tstart, double dt, long i0, long i1,
                                const std::vector<double>& corners) {
  const double eps = 1e-6 * dt;
  const double ta = tstart + static_cast<double>(i0) * dt,
               tb = tstart + static_cast<double>(i1) * dt;
  auto c = std::lower_bound(corners.begin(), corners.end(), ta - eps);
  std::vector<double> out;
  std::vector<char> is_corner;
  auto add = [&](double x, bool corner) {
    if (!out.empty() && x < out.back() + eps) {
      if (corner && !is_corner.back()) out.back() = x, is_corner.back() = 1;
      return;
    }
    out.push_back(x), is_corner.push_back(corner);
  };
  for (long i = i0; i <= i1; ++i) {
    const double u = tstart + static_cast<double>(i) * dt;
    for (; c != corners.end() && *c < u && *c <= tb + eps; ++c) add(*c, true);
    add(u, false);
  }
  for (; c != corners.end() && *c <= tb + eps; ++c) add(*c, true);
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
// *capped to the bound on linear interpolation's error (in the probes' units, mV scale as
// interp_tol) when max_rows stops it.
using Evaluate = std::function<Rows(const std::vector<double>&, double, std::vector<double>&)>;
double refine_grid(std::vector<double>& times, Rows& rows, const Evaluate& evaluate,
                   const LtiResponses::GridOptions& grid, const std::vector<bool>& is_current,
                   double dt, long max_rows, double* capped) {
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
    if (static_cast<long>(times.size() + splits) > max_rows) {
      *capped = std::max(*capped, 2 * worst);
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

// The output grid window by window: each window's first level and refinement (refine_grid) on
// its own, the modes' state at its start carried from the last window (a march over its corners
// alone), so the memory is one window's and the work is the rows' and corners'.
namespace {

class WindowedGrid {
 public:
  // corners: every input's, sorted; those strictly inside (tstart, tstop) become rows.
  WindowedGrid(const ReducedModel& model, const std::vector<Corner>& corners, size_t np, size_t nk,
               const std::vector<double>& base, const std::vector<double>& probe_weight,
               double threshold, double tstart, double tstop)
      : corners_(corners),
        base_(base),
        np_(np),
        tstop_(tstop),
        start_(model, np, nk, 0.0, &probe_weight, threshold, &scratch_) {
    for (const Corner& c : corners)
      if (c.t > tstart && c.t < tstop) corner_times_.push_back(c.t);
  }
  const std::vector<double>& corner_times() const { return corner_times_; }

  // The modes' state at the present window's start (the next one's after move_to).
  const ModalMarch& state() const { return start_; }
  // The probes at `times` (ascending, from the start of the window whose state is `start`), and
  // each time's mode rate.
  Rows evaluate(const ModalMarch& start, const std::vector<double>& times, double dt,
                std::vector<double>& rate) const {
    Rows v(np_);
    for (size_t p = 0; p < np_; ++p) v[p].assign(times.size(), base_[p]);
    ModalMarch march = start;
    march.set_pass(dt, &rate);
    march.run(corners_, times, v, tstop_);
    return v;
  }
  // The state moved on to t (the next window's start).
  void move_to(double t) {
    Rows dummy(np_, std::vector<double>(1, 0.0));
    start_.set_pass(0.0, nullptr);
    start_.run(corners_, {t}, dummy, tstop_);
  }

 private:
  const std::vector<Corner>& corners_;
  const std::vector<double>& base_;
  const size_t np_;
  const double tstop_;
  std::vector<double> scratch_, corner_times_;
  ModalMarch start_;
};

// One window of the output grid: its first level, refined in place (rows, the finest step, and
// the bound when its share of max_rows stopped it).
struct GridWindow {
  std::vector<double> times;
  Rows rows;
  std::optional<ModalMarch> start;
  long cap = 0;
  double finest = 0.0;
  double capped = 0.0;
};

// The index of the last uniform row tstart + i dt at or before tstop.
long uniform_last(double tstart, double tstop, double dt) {
  return static_cast<long>(std::floor((tstop - tstart) / dt * (1 + 1e-12)));
}

}  // namespace

Waveform LtiResponses::modal_waveform(const std::vector<SourceInput>& inputs,
                                      const GridOptions& grid, const std::vector<double>& base,
                                      GridInfo& gi) const {
  const size_t np = labels_.size();
  Waveform w;
  w.names = labels_;
  w.columns.resize(np);
  auto emit = [&](std::vector<double>& t, Rows& rows, bool first) {
    const size_t skip = first ? 0 : 1;  // a window's first row is the last one's end
    gi.rows += static_cast<long>(t.size() - skip);
    if (grid.on_rows) {
      if (!first) {
        t.erase(t.begin());
        for (auto& r : rows) r.erase(r.begin());
      }
      grid.on_rows(t, rows);
      return;
    }
    w.time.insert(w.time.end(), t.begin() + static_cast<long>(skip), t.end());
    for (size_t p = 0; p < np; ++p)
      w.columns[p].insert(w.columns[p].end(), rows[p].begin() + static_cast<long>(skip),
                          rows[p].end());
  };
  if (grid.step > 0) {  // a given step: one pass over the whole grid
    std::vector<double> times = first_level(grid.tstart, grid.step, 0,
                                            uniform_last(grid.tstart, grid.tstop, grid.step), {});
    Rows rows(np);
    for (size_t p = 0; p < np; ++p) rows[p].assign(times.size(), base[p]);
    modal_add(inputs, times, grid.step, rows);
    gi.step = grid.step;
    emit(times, rows, true);
    return w;
  }
  const double span = grid.tstop - grid.tstart;
  double dt = span;
  while (dt > coarsest_grid_step(span)) dt *= 0.5;
  gi.coarse_step = dt;
  gi.step = dt;
  const long last = uniform_last(grid.tstart, grid.tstop, dt);
  if (!follows_ties(inputs)) {  // the model cannot evaluate them: NaN on the first level
    std::vector<double> times = first_level(grid.tstart, dt, 0, last, {});
    Rows rows(np, std::vector<double>(times.size(), std::numeric_limits<double>::quiet_NaN()));
    emit(times, rows, true);
    return w;
  }
  // The modes the grid must resolve: a share over a twentieth of the tolerance on a grid probe.
  std::vector<double> weight;
  for (size_t p = 0; p < np; ++p) {
    const bool looked_at =
        grid.grid_probes.empty() || (p < grid.grid_probes.size() && grid.grid_probes[p]);
    weight.push_back(!looked_at ? 0.0 : is_current_[p] ? 1e3 : 1.0);
  }
  const size_t nk = std::min(sources_.size(), inputs.size());
  const std::vector<Corner> corners = sorted_corners(inputs, nk, tied_sources());
  WindowedGrid wg(*model_, corners, np, nk, base, weight, 0.05 * grid.interp_tol, grid.tstart,
                  grid.tstop);
  // Rows gather where the response bends (after each corner, for as long as its fast modes
  // last) and stay coarse elsewhere: 1 ns and 1 ms time constants over 5 ms take about
  // 66,000 rows, where uniform halving went to its 4,000,000-row limit.
  const long cells = grid.window > 0 ? std::max(1L, std::lround(grid.window / dt)) : last;
  const size_t threads = static_cast<size_t>(std::max(1, grid.threads));
  auto refine = [&](GridWindow& win) {
    auto evaluate = [&](const std::vector<double>& t, double step, std::vector<double>& rate) {
      return wg.evaluate(*win.start, t, step, rate);
    };
    win.finest =
        refine_grid(win.times, win.rows, evaluate, grid, is_current_, dt, win.cap, &win.capped);
  };
  double capped = 0.0;
  bool first = true;
  // Batches of windows: their starting states by a march over the corners alone, then each
  // refined on its own (`threads` at a time), then handed on in order.
  for (long i0 = 0; i0 < last || first;) {
    std::vector<GridWindow> batch;
    for (; batch.size() < 4 * threads && (i0 < last || (first && batch.empty())); i0 += cells) {
      const long i1 = std::min(last, i0 + cells);
      GridWindow& win = batch.emplace_back();
      win.times = first_level(grid.tstart, dt, i0, i1, wg.corner_times());
      // The window's share of max_rows (all of it when the rows are handed on).
      win.cap = grid.on_rows ? grid.max_rows
                             : std::max(static_cast<long>(win.times.size()),
                                        static_cast<long>(static_cast<double>(grid.max_rows) *
                                                          static_cast<double>(i1 - i0) /
                                                          static_cast<double>(std::max(1L, last))));
      win.start.emplace(wg.state());
      wg.move_to(win.times.back());
    }
    if (threads == 1 || batch.size() == 1) {
      for (GridWindow& win : batch) refine(win);
    } else {
      std::vector<std::thread> workers;
      for (size_t k = 1; k < threads && k < batch.size(); ++k)
        workers.emplace_back([&, k] {
          for (size_t j = k; j < batch.size(); j += threads) refine(batch[j]);
        });
      for (size_t j = 0; j < batch.size(); j += threads) refine(batch[j]);
      for (std::thread& t : workers) t.join();
    }
    for (GridWindow& win : batch) {
      gi.step = std::min(gi.step, win.finest);
      capped = std::max(capped, win.capped);
      emit(win.times, win.rows, first);
      first = false;
    }
  }
  if (capped > 0)
    gi.warning = fmt::format(
        "LTI output grid stopped at {} rows (step {:g} s): linear interpolation between rows "
        "may be off by up to {:.3g} mV, over the {:g} mV target",
        gi.rows, gi.step, 1e3 * capped, 1e3 * grid.interp_tol);
  return w;
}

}  // namespace isolink
