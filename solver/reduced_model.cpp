#include "solver/reduced_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/ac.h"

namespace isolink {

Status ReducedModelOptions::validate() const {
  auto bad = [](const char* field, double v, const char* rule) {
    return Status::Error(fmt::format("reduced model option {} = {:g}: {}", field, v, rule));
  };
  if (!(tol > 0 && tol < 1)) return bad("tol", tol, "must be in (0, 1)");
  if (!(f_min > 0)) return bad("f_min", f_min, "must be positive");
  if (!(f_max > f_min) || !std::isfinite(f_max)) return bad("f_max", f_max, "must exceed f_min");
  if (check_points < 8) return bad("check_points", check_points, "must be at least 8");
  if (max_check_points < check_points)
    return bad("max_check_points", max_check_points, "must be at least check_points");
  if (moments < 1 || moments > 20) return bad("moments", moments, "must be in 1..20");
  if (max_points < 1) return bad("max_points", max_points, "must be positive");
  if (batch < 1) return bad("batch", batch, "must be positive");
  if (max_order < 1) return bad("max_order", max_order, "must be positive");
  if (!(horizon > 0) || !std::isfinite(horizon)) return bad("horizon", horizon, "must be positive");
  if (!(edge_time >= 0) || !std::isfinite(edge_time))
    return bad("edge_time", edge_time, "must be zero or positive");
  return Status::Ok();
}

double ReducedModelOptions::edge_error_bound() const {
  return tol * std::log(f_max / f_min) / std::numbers::pi;
}

std::complex<double> ReducedModel::transfer(size_t k, size_t p, std::complex<double> s) const {
  std::complex<double> h = direct[k][p];
  for (size_t i = 0; i < poles.size(); ++i) {
    const std::complex<double> z = s - poles[i];  // 1 / z as conj(z) / |z|^2: no __divdc3
    const std::complex<double> r = output[p][i] * input[k][i];
    if (!paired[i]) {
      h += r * std::conj(z) / std::norm(z);
    } else {  // r / 2 at p and conj(r / 2) at conj(p)
      const std::complex<double> zc = s - std::conj(poles[i]);
      h += 0.5 * (r * std::conj(z) / std::norm(z) + std::conj(r) * std::conj(zc) / std::norm(zc));
    }
  }
  return h;
}

namespace {

using Cplx = std::complex<double>;

// The growing orthonormal basis and its images under G and C.
struct Basis {
  Eigen::MatrixXd v, gv, cv;  // n x q
  int q = 0;
  // Orthogonalises x against the basis (twice, modified Gram-Schmidt) and appends it unless
  // nothing new is left (|x| below 1e-9 of what it was). Returns whether it was appended.
  bool add(Eigen::VectorXd x, const Eigen::SparseMatrix<double>& g,
           const Eigen::SparseMatrix<double>& c) {
    const double norm0 = x.norm();
    if (!(norm0 > 0) || !std::isfinite(norm0)) return false;
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < q; ++j) x -= v.col(j).dot(x) * v.col(j);
    const double norm = x.norm();
    if (!(norm > 1e-9 * norm0)) return false;
    x /= norm;
    if (q == v.cols()) {
      const int grow = std::max(16, q);
      v.conservativeResize(Eigen::NoChange, q + grow);
      gv.conservativeResize(Eigen::NoChange, q + grow);
      cv.conservativeResize(Eigen::NoChange, q + grow);
    }
    v.col(q) = x;
    gv.col(q) = g * x;
    cv.col(q) = c * x;
    ++q;
    return true;
  }
};

}  // namespace

namespace {

// The search of the header's steps 1-4 in one sign form of the equations (`passive_form`: the
// branch rows negated, below).
StatusOr<ReducedModel> reduce_in_form(const Circuit& circuit,
                                      const std::vector<std::vector<double>>& excitations,
                                      const std::vector<std::vector<double>>& dc_solutions,
                                      const std::vector<Probe>& probes,
                                      const ReducedModelOptions& opt, bool passive_form) {
  StatusOr<AcAnalysis> ac = AcAnalysis::create(circuit);
  if (!ac) return ac.status();
  const int n = circuit.unknown_count();
  const size_t nk = excitations.size(), np = probes.size();
  ReducedModel model;
  ReducedModelStats st;  // factorizations and expansion points so far

  // G and C as real sparse matrices over unknowns 1..n (index 0 = unknown 1), with the rows of
  // the branch unknowns (inductors, voltage sources) negated: -v_a + v_b + s L i = 0 instead of
  // MNA's v_a - v_b - s L i = 0. The solution is the same for every s (the Krylov vectors too),
  // but in this form G + G' is positive semi-definite (resistors only; the branch incidence is
  // skew) and C symmetric positive semi-definite (capacitances, the inductance matrix), so the
  // congruence projection below keeps the circuit's passivity (PRIMA's theorem): every pole of
  // the reduced model is stable. With MNA's own signs C is indefinite, and on long links the
  // projection made dozens of right-half-plane poles and a modal form that could not get within
  // 2e-5 of a projection that was itself within 1e-11 of the circuit.
  std::vector<double> row_sign(n);
  for (int i = 0; i < n; ++i)
    row_sign[i] = passive_form && !circuit.unknown_is_node(i + 1) ? -1.0 : 1.0;
  Eigen::SparseMatrix<double> g(n, n), c(n, n);
  {
    std::vector<Eigen::Triplet<double>> tg, tc;
    const auto& cp = ac->col_start();
    const auto& ri = ac->row_index();
    for (int col = 0; col < n; ++col)
      for (int k = cp[col]; k < cp[col + 1]; ++k) {
        const double sign = row_sign[ri[k]];
        if (ac->g_values()[k] != 0) tg.emplace_back(ri[k], col, sign * ac->g_values()[k]);
        if (ac->c_values()[k] != 0) tc.emplace_back(ri[k], col, sign * ac->c_values()[k]);
      }
    g.setFromTriplets(tg.begin(), tg.end());
    c.setFromTriplets(tc.begin(), tc.end());
  }
  auto to_full = [n](const Eigen::VectorXcd& x) {
    AcAnalysis::Vector out(n + 1, 0.0);
    for (int i = 0; i < n; ++i) out[i + 1] = x[i];
    return out;
  };
  auto probe_of = [](const Probe& p, const AcAnalysis::Vector& x) { return x[p.a] - x[p.b]; };

  // The exact transfer at the check frequencies, and each (k, p)'s scale: peak |H| with DC.
  std::vector<double> freqs;
  std::vector<std::vector<std::vector<Cplx>>> exact;  // [check][k][p]
  std::vector<std::vector<double>> scale(nk, std::vector<double>(np, 0.0));
  for (size_t k = 0; k < nk; ++k)
    for (size_t p = 0; p < np; ++p)
      scale[k][p] =
          std::max(1e-15, std::fabs(dc_solutions[k][probes[p].a] - dc_solutions[k][probes[p].b]));
  auto add_checks = [&](const std::vector<double>& fs) -> Status {
    for (double f : fs) {
      if (Status s = ac->factor(f); !s.ok()) return s;
      ++st.factorizations;
      freqs.push_back(f);
      exact.emplace_back(nk);
      for (size_t k = 0; k < nk; ++k) {
        AcAnalysis::Vector b(excitations[k].begin(), excitations[k].end());
        b[0] = 0.0;
        const AcAnalysis::Vector x = ac->solve_factored(b);
        for (size_t p = 0; p < np; ++p) {
          exact.back()[k].push_back(probe_of(probes[p], x));
          scale[k][p] = std::max(scale[k][p], std::abs(exact.back()[k][p]));
        }
      }
    }
    return Status::Ok();
  };
  // Pivots from the middle of the band first: the refactorizations below reuse them, and the
  // ones a 1 kHz matrix would choose (its 1e-12 S ties on floating nodes) fill in badly.
  if (Status s = ac->factor(std::sqrt(opt.f_min * opt.f_max)); !s.ok()) return s;
  ++st.factorizations;
  {
    std::vector<double> fs(opt.check_points);
    for (int i = 0; i < opt.check_points; ++i)
      fs[i] = opt.f_min *
              std::pow(opt.f_max / opt.f_min, static_cast<double>(i) / (opt.check_points - 1));
    if (Status s = add_checks(fs); !s.ok()) return s;
  }

  Basis basis;
  basis.v.resize(n, 0);
  basis.gv.resize(n, 0);
  basis.cv.resize(n, 0);
  for (size_t k = 0; k < nk; ++k) {
    Eigen::VectorXd x(n);
    for (int i = 0; i < n; ++i) x[i] = dc_solutions[k][i + 1];
    basis.add(x, g, c);
  }
  // A voltage source's excitation is its own branch unknown (unit at its branch row). The
  // Galerkin projection tests each equation only along the basis, and the source's equation
  // v_a - v_b = u only along a basis direction that moves the source's current on its own.
  // The DC and Krylov vectors never do that when node a has no resistor (a source straight
  // into an inductor: KCL at a ties the source's current to the inductor's in every one of
  // them), so v_a was left undetermined and the projected pencil singular in both sign forms
  // (issue 28: V -> L -> R). The excitation itself is that direction; one more per source.
  for (size_t k = 0; k < nk; ++k) {
    Eigen::VectorXd e(n);
    bool on_branch = false;
    for (int i = 0; i < n; ++i) {
      e[i] = excitations[k][i + 1];
      on_branch |= e[i] != 0 && !circuit.unknown_is_node(i + 1);
    }
    if (on_branch) basis.add(e, g, c);
  }
  // Adds the Krylov vectors at j 2 pi f; false when none was new.
  auto expand_at = [&](double f) -> StatusOr<bool> {
    if (Status s = ac->factor(f); !s.ok()) return s;
    ++st.factorizations;
    bool added = false;
    for (size_t k = 0; k < nk; ++k) {
      AcAnalysis::Vector b(excitations[k].begin(), excitations[k].end());
      b[0] = 0.0;
      for (int m = 0; m < opt.moments; ++m) {
        AcAnalysis::Vector x = ac->solve_factored(b);
        Eigen::VectorXd re(n), im(n);
        for (int i = 0; i < n; ++i) re[i] = x[i + 1].real(), im[i] = x[i + 1].imag();
        const double norm = std::sqrt(re.squaredNorm() + im.squaredNorm());
        if (!(norm > 0) || !std::isfinite(norm)) break;
        added |= basis.add(re, g, c);
        added |= basis.add(im, g, c);
        // Next moment: A^-1 C x (normalised; only the direction matters).
        Eigen::VectorXcd xc(n);
        for (int i = 0; i < n; ++i) xc[i] = x[i + 1] / norm;
        Eigen::VectorXcd cx = c.cast<Cplx>() * xc;  // the circuit's own C x: undo row_sign
        for (int i = 0; i < n; ++i) cx[i] *= row_sign[i];
        b = to_full(cx);
      }
    }
    ++st.expansion_points;
    return added;
  };

  // A model's error at check frequency f (index into freqs): the largest over sources and probes
  // of |H_model - H_exact| over that pair's peak |H|.
  auto error_at = [&](const ReducedModel& m, size_t f) {
    const Cplx jw(0.0, 2 * std::numbers::pi * freqs[f]);
    // The edge spectrum's envelope (header: what the check guarantees).
    const double weight = opt.edge_time > 0
                              ? std::min(1.0, 1.0 / (std::numbers::pi * freqs[f] * opt.edge_time))
                              : 1.0;
    double e = 0;
    for (size_t k = 0; k < nk; ++k)
      for (size_t p = 0; p < np; ++p) {
        const double x = weight * std::abs(m.transfer(k, p, jw) - exact[f][k][p]) / scale[k][p];
        if (!(x <= e)) e = x;  // a NaN sticks: such a model never passes
      }
    return e;
  };

  // Gr = V'GV and Cr = V'CV, grown by the rows and columns of the vectors added since the last
  // build (the basis only grows, and its earlier vectors do not change).
  Eigen::MatrixXd gr, cr;
  auto project = [&]() {
    const int q = basis.q, q0 = static_cast<int>(gr.rows());
    if (q == q0) return;
    gr.conservativeResize(q, q);
    cr.conservativeResize(q, q);
    const auto v = basis.v.leftCols(q);
    const auto added = basis.v.middleCols(q0, q - q0);
    gr.rightCols(q - q0) = v.transpose() * basis.gv.middleCols(q0, q - q0);
    cr.rightCols(q - q0) = v.transpose() * basis.cv.middleCols(q0, q - q0);
    gr.bottomLeftCorner(q - q0, q0) = added.transpose() * basis.gv.leftCols(q0);
    cr.bottomLeftCorner(q - q0, q0) = added.transpose() * basis.cv.leftCols(q0);
  };

  // Builds the pole-residue model from the current basis and measures its error.
  auto build = [&]() -> Status {
    const int q = basis.q;
    ReducedModel mod;
    ++st.steps;
    mod.direct.assign(nk, std::vector<double>(np, 0.0));
    mod.input.assign(nk, {});
    mod.output.assign(np, {});
    mod.stats = st;
    mod.stats.order = q;
    // The model's error over the check grid, and where it is largest.
    auto measure = [&]() {
      mod.stats.error = 0;
      for (size_t f = 0; f < freqs.size(); ++f) {
        const double e = error_at(mod, f);
        if (!(e <= mod.stats.error)) mod.stats.error = e, mod.stats.error_frequency = freqs[f];
      }
    };
    if (q == 0) {  // nothing reaches the probes (no source drives anything): H = 0
      measure();
      model = std::move(mod);
      return Status::Ok();
    }
    const auto v = basis.v.leftCols(q);
    project();
    Eigen::MatrixXd br(q, nk), lr(np, q);
    for (size_t k = 0; k < nk; ++k) {
      Eigen::VectorXd e(n);
      for (int i = 0; i < n; ++i) e[i] = row_sign[i] * excitations[k][i + 1];
      br.col(k) = v.transpose() * e;
    }
    for (size_t p = 0; p < np; ++p)
      for (int j = 0; j < q; ++j)
        lr(p, j) = (probes[p].a > 0 ? v(probes[p].a - 1, j) : 0.0) -
                   (probes[p].b > 0 ? v(probes[p].b - 1, j) : 0.0);
    // sigma: the middle of the band on a log scale, where G + sigma C is far from singular.
    const double sigma = 2 * std::numbers::pi * std::sqrt(opt.f_min * opt.f_max);
    Eigen::PartialPivLU<Eigen::MatrixXd> a(gr + sigma * cr);
    const Eigen::MatrixXd m = a.solve(cr);
    const Eigen::MatrixXd ab = a.solve(br);
    if (!m.allFinite() || !ab.allFinite())
      return Status::Error("reduced model: the projected system is singular");
    Eigen::EigenSolver<Eigen::MatrixXd> es(m);
    if (es.info() != Eigen::Success)
      return Status::Error("reduced model: the eigenvalue problem did not converge");
    const Eigen::VectorXcd lambda = es.eigenvalues();
    const Eigen::MatrixXcd w = es.eigenvectors();
    Eigen::PartialPivLU<Eigen::MatrixXcd> wlu(w);
    const Eigen::MatrixXcd d = wlu.solve(ab.cast<Cplx>());  // q x nk
    const Eigen::MatrixXcd cw = lr.cast<Cplx>() * w;        // np x q
    if (!d.allFinite() || !cw.allFinite())
      return Status::Error("reduced model: the eigenvectors are singular");
    double lmax = 0;
    for (int i = 0; i < q; ++i) lmax = std::max(lmax, std::abs(lambda[i]));
    // Instantaneous: lambda = 0, or a mode so fast (|lambda| under 1e-6 / (2 pi f_max): a time
    // constant of 0.05 fs, a pole over 2e16 rad/s) that its share 1 / (1 + (s - sigma) lambda)
    // is constant within 1e-6 over the whole band. The zero eigenvalues of a singular Cr come
    // out at about 1e-12 of the largest, of either sign: on V -> L -> R at +-1e-19 s against
    // 9e-8 s, one was a pole at -8.9e18 rad/s and the other a right-half-plane pole, dropped,
    // and v(in) lost its direct term (error 1).
    const double instant = 1e-6 / (2 * std::numbers::pi * opt.f_max);
    for (int i = 0; i < q; ++i) {
      if (std::abs(lambda[i]) <= std::max(1e-14 * lmax, instant)) {
        ++mod.stats.direct_modes;
        for (size_t k = 0; k < nk; ++k)
          for (size_t p = 0; p < np; ++p) mod.direct[k][p] += (cw(p, i) * d(i, k)).real();
        continue;
      }
      const Cplx pole = sigma - 1.0 / lambda[i];
      // A complex pole's conjugate (the next eigenvalue: a real matrix's come in exact pairs,
      // with conjugate vectors) is carried by it: one mode, output doubled, real part taken.
      const bool paired =
          lambda[i].imag() != 0 && i + 1 < q && lambda[i + 1] == std::conj(lambda[i]);
      const int modes = paired ? 2 : 1;
      if (paired) ++i;
      const int at = paired ? i - 1 : i;
      if (pole.real() > 0 && pole.real() * opt.horizon >= 1e-3) {
        // Dropped; the check below sees what that costs (a pole with weight fails it).
        double weight = 0;
        for (size_t k = 0; k < nk; ++k)
          for (size_t p = 0; p < np; ++p)
            weight =
                std::max(weight, std::abs(cw(p, at) * d(at, k) / lambda[at] / pole) / scale[k][p]);
        mod.stats.dropped += modes;
        mod.stats.dropped_weight = std::max(mod.stats.dropped_weight, weight);
        continue;
      }
      mod.poles.push_back(pole);
      mod.paired.push_back(paired);
      mod.stats.poles += modes;
      for (size_t k = 0; k < nk; ++k) mod.input[k].push_back(d(at, k) / lambda[at]);
      for (size_t p = 0; p < np; ++p)
        mod.output[p].push_back(static_cast<double>(modes) * cw(p, at));
    }
    measure();
    model = std::move(mod);
    return Status::Ok();
  };

  // The basis and its images are three dense n x q arrays: at most kMaxBasisBytes in all (their
  // capacity, grown by doubling, at most twice that).
  constexpr double kMaxBasisBytes = 384.0 * (1 << 20);
  const int max_order = static_cast<int>(
      std::min<double>(opt.max_order, kMaxBasisBytes / (3.0 * sizeof(double) * n)));
  std::vector<double> used;
  std::vector<std::pair<double, double>> open;  // check intervals not yet refined
  for (size_t i = 0; i + 1 < freqs.size(); ++i) open.push_back({freqs[i], freqs[i + 1]});
  std::vector<double> first = {opt.f_min, opt.f_max / 10};
  for (double f : opt.start_points)
    if (f >= opt.f_min && f <= opt.f_max && std::find(first.begin(), first.end(), f) == first.end())
      first.push_back(f);
  for (double f : first) {
    StatusOr<bool> added = expand_at(f);
    if (!added) return added.status();
    used.push_back(f);
  }
  while (true) {
    if (Status s = build(); !s.ok()) return s;
    if (model.stats.error <= opt.tol) {
      // Refinement, as adaptive quadrature refines: every open interval of the check grid
      // (at first all of them) is tested at its geometric midpoint, where a resonance could
      // hide. An interval whose midpoint passes is closed; one whose midpoint fails leaves its
      // two halves open, the midpoint joins the grid and the search goes on.
      std::vector<std::pair<double, double>> next;
      std::vector<double> mids;
      for (const auto& [lo, hi] : open)
        if (hi > lo * (1 + 1e-9)) mids.push_back(std::sqrt(lo * hi));
      if (freqs.size() + mids.size() > static_cast<size_t>(opt.max_check_points)) break;
      const size_t before = freqs.size();
      if (Status s = add_checks(mids); !s.ok()) return s;
      double worst = 0, worst_f = 0;
      for (size_t f = before; f < freqs.size(); ++f) {
        const double e = error_at(model, f);
        if (e > opt.tol) {
          const auto it = std::find_if(open.begin(), open.end(), [&](const auto& iv) {
            return iv.first < freqs[f] && freqs[f] < iv.second;
          });
          next.push_back({it->first, freqs[f]});
          next.push_back({freqs[f], it->second});
        }
        if (!(e <= worst)) worst = e, worst_f = freqs[f];
      }
      open = std::move(next);
      if (worst <= opt.tol) break;
      model.stats.error = worst;
      model.stats.error_frequency = worst_f;
    }
    if (static_cast<int>(used.size()) >= opt.max_points || basis.q >= max_order)
      return Status::Error(fmt::format(
          "reduced model: error {:.2g} at {:.4g} Hz after {} expansion points (order {}), over "
          "the {:.2g} allowed",
          model.stats.error, model.stats.error_frequency, used.size(), basis.q, opt.tol));
    // Check frequencies by the error there, worst first; the first one whose vectors are new.
    // Then, up to `batch` points in all, the next-worst local maxima of the error over the grid
    // (other resonances): one build per step instead of one per point.
    std::vector<std::pair<double, double>> ranked;  // (error, f)
    std::vector<std::pair<double, double>> by_f;    // (f, error), by frequency
    for (size_t f = 0; f < freqs.size(); ++f) {
      const double e = error_at(model, f);
      by_f.emplace_back(freqs[f], e);
      if (e > opt.tol) ranked.emplace_back(e, freqs[f]);
    }
    std::sort(ranked.rbegin(), ranked.rend());
    std::sort(by_f.begin(), by_f.end());
    std::vector<std::pair<double, double>> peaks;  // (error, f): local maxima over tol
    for (size_t i = 0; i < by_f.size(); ++i) {
      const double e = by_f[i].second;
      if (e > opt.tol && !(i > 0 && by_f[i - 1].second > e) &&
          !(i + 1 < by_f.size() && by_f[i + 1].second > e))
        peaks.emplace_back(e, by_f[i].first);
    }
    std::sort(peaks.rbegin(), peaks.rend());
    auto is_used = [&](double f) { return std::find(used.begin(), used.end(), f) != used.end(); };
    bool grew = false;
    for (const auto& [e, f] : ranked) {
      if (is_used(f)) continue;
      StatusOr<bool> added = expand_at(f);
      if (!added) return added.status();
      used.push_back(f);
      if (*added) {
        grew = true;
        break;
      }
      if (static_cast<int>(used.size()) >= opt.max_points) break;
    }
    for (int taken = 1; taken < opt.batch && grew;) {
      const auto next = std::find_if(peaks.begin(), peaks.end(),
                                     [&](const auto& pk) { return !is_used(pk.second); });
      if (next == peaks.end() || static_cast<int>(used.size()) >= opt.max_points) break;
      StatusOr<bool> added = expand_at(next->second);
      if (!added) return added.status();
      used.push_back(next->second);
      ++taken;
    }
    if (!grew)
      return Status::Error(fmt::format(
          "reduced model: error {:.2g} at {:.4g} Hz and no expansion point adds a new direction "
          "(order {})",
          model.stats.error, model.stats.error_frequency, basis.q));
  }
  model.stats.factorizations = st.factorizations;
  model.stats.check_points = static_cast<int>(freqs.size());
  model.stats.expansion_points = st.expansion_points;
  model.stats.steps = st.steps;
  model.stats.points = used;
  return model;
}

}  // namespace

// The passive form first (it converges on the long links, where MNA's signs stall); MNA's own
// signs when it does not pass (a 3-unknown-deep series RLC driven by a voltage source projected
// onto a singular pencil in the passive form, tests/solver/lti_test.cpp). The error of a search
// that fails in both forms is the passive form's.
StatusOr<ReducedModel> reduce_circuit(const Circuit& circuit,
                                      const std::vector<std::vector<double>>& excitations,
                                      const std::vector<std::vector<double>>& dc_solutions,
                                      const std::vector<Probe>& probes,
                                      const ReducedModelOptions& opt) {
  if (Status s = opt.validate(); !s.ok()) return s;
  StatusOr<ReducedModel> passive =
      reduce_in_form(circuit, excitations, dc_solutions, probes, opt, true);
  if (passive) return passive;
  StatusOr<ReducedModel> mna =
      reduce_in_form(circuit, excitations, dc_solutions, probes, opt, false);
  if (mna) return mna;
  return passive;
}

}  // namespace isolink
