#include "solver/vector_fit.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace isolink {

namespace {

using cd = std::complex<double>;
constexpr double kTwoPi = 2 * std::numbers::pi;

// Poles in scaled frequency (s / w0): real ones and one of each pair (Im > 0).
using Poles = std::vector<cd>;

int state_count(const Poles& p) {
  int n = 0;
  for (const cd& a : p) n += a.imag() > 0 ? 2 : 1;
  return n;
}

// The real basis at s: 1 / (s - a) for a real pole; 1 / (s - a) + 1 / (s - a*) and
// j / (s - a) - j / (s - a*) for a pair, so that real coefficients (c1, c2) stand for the residue
// c1 + j c2 at a (and its conjugate at a*).
void basis(cd s, const Poles& poles, cd* out) {
  int k = 0;
  for (const cd& a : poles) {
    if (a.imag() > 0) {
      const cd u = 1.0 / (s - a), v = 1.0 / (s - std::conj(a));
      out[k++] = u + v;
      out[k++] = cd(0, 1) * (u - v);
    } else {
      out[k++] = 1.0 / (s - a);
    }
  }
}

Poles starting_poles(int n, double f_lo) {
  // f_lo is scaled (f_min / f_max). Real poles below the band for the DC extrapolation, then
  // pairs spread linearly over it.
  Poles p;
  const int real = n % 2 == 0 ? 2 : 1;
  for (int k = 0; k < real; ++k) p.push_back(cd(-f_lo * std::pow(10.0, -k), 0));
  const int pairs = (n - real) / 2;
  for (int k = 0; k < pairs; ++k) {
    const double b = pairs == 1 ? 0.5 : f_lo + (1.0 - f_lo) * k / (pairs - 1);
    p.push_back(cd(-b / 100, b));
  }
  return p;
}

struct Data {
  std::vector<cd> s;                   // scaled: j f / f_max
  std::vector<std::vector<double>> w;  // [entry][frequency]: the rows' weights
  std::vector<std::vector<cd>> f;      // [entry][frequency], upper triangle row-major
  std::vector<std::pair<int, int>> ij;
  int ports = 0;
};

// One relocation: sigma's zeros from the relaxed least squares. Returns the new poles.
Poles relocate(const Data& d, const Poles& poles) {
  const int n = state_count(poles), ns = static_cast<int>(d.s.size());
  const int ne = static_cast<int>(d.f.size());
  Eigen::MatrixXd stack = Eigen::MatrixXd::Zero(ne * (n + 1) + 1, n + 1);
  std::vector<cd> phi(n);
  Eigen::MatrixXd a(2 * ns, 2 * (n + 1));
  double norm = 0;
  for (int e = 0; e < ne; ++e) {
    for (int i = 0; i < ns; ++i) {
      basis(d.s[i], poles, phi.data());
      const double w = d.w[e][i];
      const cd fw = w * d.f[e][i];
      norm += std::norm(fw);
      for (int k = 0; k <= n; ++k) {
        const cd b = k < n ? phi[k] : cd(1, 0);
        const cd left = w * b, right = -fw * b;
        a(2 * i, k) = left.real(), a(2 * i + 1, k) = left.imag();
        a(2 * i, n + 1 + k) = right.real(), a(2 * i + 1, n + 1 + k) = right.imag();
      }
    }
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
    const Eigen::MatrixXd r = qr.matrixQR().topRows(2 * (n + 1)).triangularView<Eigen::Upper>();
    stack.block(e * (n + 1), 0, n + 1, n + 1) = r.block(n + 1, n + 1, n + 1, n + 1);
  }
  // Relaxation: Re sum_i sigma(s_i) = ns, weighted to the data's size.
  const double weight = std::sqrt(norm) / ns;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(stack.rows());
  for (int i = 0; i < ns; ++i) {
    basis(d.s[i], poles, phi.data());
    for (int k = 0; k < n; ++k) stack(stack.rows() - 1, k) += weight * phi[k].real();
  }
  stack(stack.rows() - 1, n) = weight * ns;
  rhs[stack.rows() - 1] = weight * ns;
  Eigen::VectorXd scale(n + 1);
  for (int k = 0; k <= n; ++k) {
    scale[k] = stack.col(k).norm();
    if (!(scale[k] > 0)) scale[k] = 1;
    stack.col(k) /= scale[k];
  }
  Eigen::VectorXd x = stack.colPivHouseholderQr().solve(rhs);
  x = x.cwiseQuotient(scale);
  double dt = x[n];
  if (std::abs(dt) < 1e-8) dt = dt < 0 ? -1e-8 : 1e-8;
  // Zeros of sigma: eig(A - b c^T / d).
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd bvec = Eigen::VectorXd::Zero(n);
  int k = 0;
  for (const cd& p : poles) {
    if (p.imag() > 0) {
      h(k, k) = p.real(), h(k, k + 1) = p.imag();
      h(k + 1, k) = -p.imag(), h(k + 1, k + 1) = p.real();
      bvec[k] = 2;
      k += 2;
    } else {
      h(k, k) = p.real(), bvec[k] = 1;
      k += 1;
    }
  }
  h -= bvec * x.head(n).transpose() / dt;
  Eigen::EigenSolver<Eigen::MatrixXd> eig(h, false);
  Poles out;
  for (int i = 0; i < n; ++i) {
    cd z = eig.eigenvalues()[i];
    if (!std::isfinite(z.real()) || !std::isfinite(z.imag())) continue;
    const double mag = std::max(std::abs(z), 1e-12);
    if (std::abs(z.imag()) <= 1e-10 * mag) z = cd(z.real(), 0);
    if (z.imag() < 0) continue;
    double re = -std::abs(z.real());
    if (re == 0) re = -1e-6 * mag;
    out.push_back(cd(re, z.imag()));
  }
  if (state_count(out) != n) return poles;  // a lost eigenvalue: keep the previous set
  return out;
}

// Residues and D with the poles fixed: one least squares per entry (each weighted its own way),
// on the basis evaluated once.
Eigen::MatrixXd residues(const Data& d, const Poles& poles) {
  const int n = state_count(poles), ns = static_cast<int>(d.s.size());
  const int ne = static_cast<int>(d.f.size());
  Eigen::MatrixXcd basis_rows(ns, n + 1);  // row i: the basis at s_i, then 1 (for D)
  std::vector<cd> phi(n);
  for (int i = 0; i < ns; ++i) {
    basis(d.s[i], poles, phi.data());
    for (int k = 0; k < n; ++k) basis_rows(i, k) = phi[k];
    basis_rows(i, n) = 1;
  }
  Eigen::MatrixXd x(n + 1, ne), a(2 * ns, n + 1);
  Eigen::VectorXd b(2 * ns), scale(n + 1);
  for (int e = 0; e < ne; ++e) {
    for (int i = 0; i < ns; ++i) {
      const double w = d.w[e][i];
      a.row(2 * i) = w * basis_rows.row(i).real();
      a.row(2 * i + 1) = w * basis_rows.row(i).imag();
      const cd v = w * d.f[e][i];
      b[2 * i] = v.real(), b[2 * i + 1] = v.imag();
    }
    for (int k = 0; k <= n; ++k) {
      scale[k] = a.col(k).norm();
      if (!(scale[k] > 0)) scale[k] = 1;
      a.col(k) /= scale[k];
    }
    x.col(e) = a.colPivHouseholderQr().solve(b).cwiseQuotient(scale);
  }
  return x;
}

RationalModel to_model(const Data& d, const Poles& poles, const Eigen::MatrixXd& x, double w0) {
  RationalModel m;
  m.ports = d.ports;
  const int n = state_count(poles);
  m.d = Eigen::MatrixXd::Zero(d.ports, d.ports);
  int k = 0;
  for (const cd& p : poles) {
    Eigen::MatrixXcd r(d.ports, d.ports);
    for (size_t e = 0; e < d.ij.size(); ++e) {
      const auto [i, j] = d.ij[e];
      const cd v = p.imag() > 0 ? cd(x(k, e), x(k + 1, e)) : cd(x(k, e), 0);
      r(i, j) = r(j, i) = v * w0;
    }
    m.poles.push_back(p * w0);
    m.residues.push_back(r);
    k += p.imag() > 0 ? 2 : 1;
  }
  for (size_t e = 0; e < d.ij.size(); ++e) {
    const auto [i, j] = d.ij[e];
    m.d(i, j) = m.d(j, i) = x(n, e);
  }
  return m;
}

void score(const RationalModel& m, const std::vector<double>& freqs,
           const std::vector<Eigen::MatrixXcd>& s_data, double z0, FitResult& r) {
  r.entry_error = Eigen::MatrixXd::Zero(m.ports, m.ports);
  r.error = 0;
  double sum = 0;
  for (size_t i = 0; i < freqs.size(); ++i) {
    const Eigen::MatrixXcd s = s_from_y(m.eval(cd(0, kTwoPi * freqs[i])), z0);
    const Eigen::MatrixXd e = (s - s_data[i]).cwiseAbs();
    r.entry_error = r.entry_error.cwiseMax(e);
    sum += e.squaredNorm();
    if (e.maxCoeff() > r.error) r.error = e.maxCoeff(), r.error_frequency = freqs[i];
  }
  r.rms_error = std::sqrt(sum / (double(freqs.size()) * m.ports * m.ports));
  if (!std::isfinite(r.error) || !std::isfinite(r.rms_error)) r.error = r.rms_error = INFINITY;
}

}  // namespace

int RationalModel::order() const {
  int n = 0;
  for (const cd& p : poles) n += p.imag() > 0 ? 2 : 1;
  return n * ports;
}

Eigen::MatrixXcd RationalModel::eval(cd s) const {
  Eigen::MatrixXcd y = d.cast<cd>();
  for (size_t k = 0; k < poles.size(); ++k) {
    y += residues[k] / (s - poles[k]);
    if (poles[k].imag() > 0) y += residues[k].conjugate() / (s - std::conj(poles[k]));
  }
  return y;
}

Eigen::MatrixXcd s_from_y(const Eigen::MatrixXcd& y, double z0) {
  const Eigen::MatrixXcd id = Eigen::MatrixXcd::Identity(y.rows(), y.cols());
  return (id + z0 * y).transpose().partialPivLu().solve((id - z0 * y).transpose()).transpose();
}

Eigen::MatrixXcd y_from_s(const Eigen::MatrixXcd& s, double z0) {
  const Eigen::MatrixXcd id = Eigen::MatrixXcd::Identity(s.rows(), s.cols());
  return (id + s).partialPivLu().solve(id - s) / z0;
}

StatusOr<FitResult> vector_fit(const std::vector<double>& freqs,
                               const std::vector<Eigen::MatrixXcd>& y, const FitOptions& opt) {
  const int ns = static_cast<int>(freqs.size());
  if (ns < 2 || y.size() != freqs.size())
    return Status::Error("vector fit: needs at least 2 frequencies, one matrix each");
  Data d;
  d.ports = static_cast<int>(y[0].rows());
  for (int i = 0; i < d.ports; ++i)
    for (int j = i; j < d.ports; ++j) d.ij.push_back({i, j});
  d.f.assign(d.ij.size(), {});
  d.w.assign(d.ij.size(), {});
  const Eigen::MatrixXd& t = opt.transform;
  if (t.size() && (t.rows() != d.ports || t.cols() != d.ports ||
                   !(t * t.transpose()).isApprox(Eigen::MatrixXd::Identity(d.ports, d.ports))))
    return Status::Error("vector fit: the transform must be an orthogonal N x N matrix");
  const double f_max = freqs.back();
  std::vector<Eigen::MatrixXcd> s_data;
  for (int i = 0; i < ns; ++i) {
    if (!(freqs[i] >= 0) || (i > 0 && !(freqs[i] > freqs[i - 1])) || !std::isfinite(freqs[i]))
      return Status::Error("vector fit: frequencies must be >= 0 and increasing");
    const Eigen::MatrixXcd ys = (y[i] + y[i].transpose()) / 2.0;
    if (!ys.allFinite()) return Status::Error("vector fit: non-finite data");
    d.s.push_back(cd(0, freqs[i] / f_max));
    s_data.push_back(s_from_y(ys, opt.z0));
    // Header, Weighting: the fitted entries are those of T Y T^T when a transform is given.
    const Eigen::MatrixXcd yt = t.size() ? Eigen::MatrixXcd(t * ys * t.transpose()) : ys;
    const double row = 1.0 / (1.0 / opt.z0 + ys.cwiseAbs().maxCoeff());
    for (size_t e = 0; e < d.ij.size(); ++e) {
      const cd v = yt(d.ij[e].first, d.ij[e].second);
      d.f[e].push_back(v);
      d.w[e].push_back(t.size() ? 1.0 / (1.0 / opt.z0 + std::abs(v)) : row);
    }
  }
  const double w0 = kTwoPi * f_max;
  FitResult best;
  best.error = best.rms_error = INFINITY;
  int stalled = 0;
  for (int n = opt.min_order; n <= opt.max_order; n += opt.order_step) {
    if (n + 1 > ns) break;  // more unknowns than data
    Poles poles = starting_poles(n, (freqs[0] > 0 ? freqs[0] : freqs[1]) / f_max);
    for (int it = 0; it < opt.iterations; ++it) poles = relocate(d, poles);
    FitResult r;
    r.model = to_model(d, poles, residues(d, poles), w0);
    if (t.size()) {  // back from T Y T^T: Y = T^T (T Y T^T) T
      for (Eigen::MatrixXcd& res : r.model.residues) res = t.transpose() * res * t;
      r.model.d = t.transpose() * r.model.d * t;
    }
    score(r.model, freqs, s_data, opt.z0, r);
    best.orders_tried.push_back(n);
    best.errors.push_back(r.rms_error);
    // Raise the order while it pays: down to the target, or, once within the tolerance, until
    // two steps in a row gain less than a fifth (the data's noise floor, or the model's).
    stalled = r.rms_error < 0.8 * best.rms_error ? 0 : stalled + 1;
    if (std::min(r.rms_error, best.rms_error) > opt.tolerance) stalled = 0;
    if (r.rms_error < best.rms_error) {
      r.orders_tried = best.orders_tried;
      r.errors = best.errors;
      best = std::move(r);
    }
    if (best.rms_error <= opt.target || stalled >= 2) break;
  }
  if (best.model.ports == 0)
    return Status::Error(fmt::format("vector fit: {} frequencies are too few for a fit of order {}",
                                     ns, opt.min_order));
  best.converged = best.rms_error <= opt.tolerance;
  return best;
}

namespace {

// The sweep of the passivity check: DC, log-spaced from f_top 1e-6 to 10 f_top, and each pair's
// resonance (where Re Y changes fastest).
std::vector<double> passivity_sweep(const RationalModel& m, double f_top) {
  std::vector<double> f = {0.0};
  const int n = 2000;
  for (int i = 0; i < n; ++i) f.push_back(f_top * 1e-6 * std::pow(1e7, double(i) / (n - 1)));
  for (const cd& p : m.poles)
    if (p.imag() > 0) f.push_back(p.imag() / kTwoPi);
  std::sort(f.begin(), f.end());
  return f;
}

struct Violation {
  double f;           // Hz (infinity: D)
  double lambda;      // the smallest eigenvalue of Re Y there
  Eigen::VectorXd u;  // its eigenvector
};

// The smallest eigenvalue of Re Y at each sweep frequency; the violations are the local minima
// below zero.
std::vector<Violation> violations(const RationalModel& m, const std::vector<double>& f,
                                  PassivityReport* r) {
  std::vector<Violation> all;
  auto test = [&](const Eigen::MatrixXd& g, double at) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es((g + g.transpose()) / 2);
    Violation v{at, es.eigenvalues()[0], es.eigenvectors().col(0)};
    all.push_back(v);
  };
  for (double x : f) test(m.eval(cd(0, kTwoPi * x)).real(), x);
  test(m.d, INFINITY);
  std::vector<Violation> out;
  r->min_eigenvalue = INFINITY;
  for (size_t i = 0; i < all.size(); ++i) {
    if (all[i].lambda < r->min_eigenvalue)
      r->min_eigenvalue = all[i].lambda, r->at_frequency = all[i].f;
    const bool minimum = (i == 0 || all[i].lambda <= all[i - 1].lambda) &&
                         (i + 1 >= all.size() || all[i].lambda <= all[i + 1].lambda);
    if (all[i].lambda < 0 && (minimum || i + 1 == all.size())) out.push_back(all[i]);
  }
  r->sweep_points = static_cast<int>(all.size());
  r->passive = r->min_eigenvalue >= 0;
  return out;
}

// One residue perturbation: the smallest change of the residues and D, in absolute siemens (a
// small conductance between P and N moves a waveform as much as a large one) over the
// passivity sweep (DC to 10 f_top: the
// band alone would let the poles below it trade their residues against D, and move DC), that
// lifts each violation's eigenvalue
// to a small positive margin (the eigenvector held fixed: the first-order change of the
// eigenvalue). Gustavsen, "Fast passivity enforcement ... residue perturbation", 2008, with the
// constraints as heavily weighted equations.
void perturb(RationalModel& m, const std::vector<double>& freqs, double f_top,
             const std::vector<Violation>& v, double margin) {
  Poles poles;
  const double w0 = kTwoPi * f_top;
  for (const cd& p : m.poles) poles.push_back(p / w0);
  const int n = state_count(poles), np = m.ports, ns = static_cast<int>(freqs.size());
  std::vector<std::pair<int, int>> ij;
  for (int i = 0; i < np; ++i)
    for (int j = i; j < np; ++j) ij.push_back({i, j});
  const int ne = static_cast<int>(ij.size()), cols = n + 1;
  // The objective's factor, the same for every entry: R of the weighted basis.
  Eigen::MatrixXd a(2 * ns, cols);
  std::vector<cd> phi(n);
  for (int i = 0; i < ns; ++i) {
    basis(cd(0, freqs[i] / f_top), poles, phi.data());
    for (int k = 0; k < cols; ++k) {
      const cd b = k < n ? phi[k] : cd(1, 0);
      a(2 * i, k) = b.real(), a(2 * i + 1, k) = b.imag();
    }
  }
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::MatrixXd r = qr.matrixQR().topRows(cols).triangularView<Eigen::Upper>();
  const int nv = static_cast<int>(v.size());
  Eigen::MatrixXd big = Eigen::MatrixXd::Zero(ne * cols + nv, ne * cols);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(ne * cols + nv);
  for (int e = 0; e < ne; ++e) big.block(e * cols, e * cols, cols, cols) = r;
  const double heavy = 1e3 * r.norm();
  for (int c = 0; c < nv; ++c) {
    if (std::isfinite(v[c].f)) basis(cd(0, v[c].f / f_top), poles, phi.data());
    for (int e = 0; e < ne; ++e) {
      const auto [i, j] = ij[e];
      const double uu = (i == j ? 1.0 : 2.0) * v[c].u[i] * v[c].u[j];
      for (int k = 0; k < cols; ++k) {
        const double re = k == n ? 1.0 : std::isfinite(v[c].f) ? phi[k].real() : 0.0;
        big(ne * cols + c, e * cols + k) = heavy * uu * re;
      }
    }
    rhs[ne * cols + c] = heavy * (margin - v[c].lambda);
  }
  const Eigen::VectorXd dx = big.colPivHouseholderQr().solve(rhs);
  for (int e = 0; e < ne; ++e) {
    const auto [i, j] = ij[e];
    int k = 0;
    for (size_t q = 0; q < m.poles.size(); ++q) {
      const bool pair = m.poles[q].imag() > 0;
      const cd d = pair ? cd(dx[e * cols + k], dx[e * cols + k + 1]) : cd(dx[e * cols + k], 0);
      m.residues[q](i, j) += d * w0;
      if (i != j) m.residues[q](j, i) = m.residues[q](i, j);
      k += pair ? 2 : 1;
    }
    m.d(i, j) += dx[e * cols + n];
    if (i != j) m.d(j, i) = m.d(i, j);
  }
}

}  // namespace

PassivityReport check_passivity(const RationalModel& m, double f_top) {
  PassivityReport r;
  violations(m, passivity_sweep(m, f_top), &r);
  return r;
}

PassivityReport enforce_passivity(RationalModel& m, const std::vector<double>& freqs) {
  const double f_top = freqs.back();
  PassivityReport first = check_passivity(m, f_top);
  if (first.passive) return first;
  const double scale = m.d.cwiseAbs().maxCoeff() + 1e-12;
  // The constrained frequencies accumulate over the iterations (a violation fixed at one
  // frequency must not come back there while another is fixed): each is held at
  // max(lambda, margin) - lambda or more, linearised with its current eigenvector.
  std::vector<double> held;
  const std::vector<double> sweep = passivity_sweep(m, f_top);
  for (int it = 0; it < 20; ++it) {
    PassivityReport now;
    const std::vector<Violation> v = violations(m, sweep, &now);
    if (now.passive) {
      first.perturbation_iterations = it;
      first.enforced_min_eigenvalue = now.min_eigenvalue;
      return first;
    }
    for (const Violation& x : v)
      if (std::find(held.begin(), held.end(), x.f) == held.end()) held.push_back(x.f);
    const double margin = 1e-9 * scale + 0.01 * std::abs(now.min_eigenvalue);
    std::vector<Violation> c;
    for (double f : held) {
      const Eigen::MatrixXd g =
          std::isfinite(f) ? Eigen::MatrixXd(m.eval(cd(0, kTwoPi * f)).real()) : m.d;
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es((g + g.transpose()) / 2);
      c.push_back({f, std::min(es.eigenvalues()[0], margin), es.eigenvectors().col(0)});
    }
    perturb(m, sweep, f_top, c, margin);
  }
  // Not passive after the perturbations: the shunt conductance that lifts every eigenvalue.
  PassivityReport now = check_passivity(m, f_top);
  first.perturbation_iterations = 20;
  if (!now.passive) {
    const double add = -now.min_eigenvalue * 1.01 + 1e-12;
    m.d += add * Eigen::MatrixXd::Identity(m.ports, m.ports);
    first.added_conductance = add;
  }
  first.enforced_min_eigenvalue = check_passivity(m, f_top).min_eigenvalue;
  return first;
}

}  // namespace isolink
