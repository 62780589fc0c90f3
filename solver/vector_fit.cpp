#include "solver/vector_fit.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/nnls.h"

namespace isolink {

namespace {

using cd = std::complex<double>;
constexpr double kTwoPi = 2 * std::numbers::pi;
// Relative to the largest |eigenvalue| of Re Y over the sweep (the model's scale): below
// -kRoundingFloor an eigenvalue is a violation, above it rounding; a perturbation lifts every
// constrained eigenvalue to kMargin, well clear of the floor.
constexpr double kRoundingFloor = 1e-12;
constexpr double kMargin = 1e-9;
constexpr int kPerturbations = 20;
// Rounds of constraint generation in one perturbation.
constexpr int kConstraintRounds = 8;
// A perturbation's change above the band counts this much against one in it.
constexpr double kOutOfBandWeight = 0.01;

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

// One eigenvalue of Re Y at one sweep frequency, with its eigenvector.
struct Eigenpair {
  double f;           // Hz (infinity: D)
  double lambda;      // S
  Eigen::VectorXd u;  // unit eigenvector
  double target;      // S: where a perturbation must leave it, at least
  bool seed;          // a violation, or at infinity: in the first solution's constraints
};

// Re Y over the sweep: the eigenpairs a perturbation is constrained by, the model's scale and the
// floor below which an eigenvalue is a violation.
struct Scan {
  std::vector<Eigenpair> pairs;
  double largest = 0;          // S, the largest |eigenvalue| over the sweep
  double floor = 0;            // S, -kRoundingFloor * largest
  double margin = 0;           // S, kMargin * largest
  std::vector<double> y_size;  // S, max |Y_ij| at each finite sweep point (the change's weights)
};

Scan scan(const RationalModel& m, const std::vector<double>& f, PassivityReport* r) {
  Scan out;
  r->min_eigenvalue = INFINITY;
  std::vector<double> at(f);
  at.push_back(INFINITY);
  std::vector<Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>> es;
  for (double x : at) {
    Eigen::MatrixXd g = m.d;
    if (std::isfinite(x)) {
      const Eigen::MatrixXcd y = m.eval(cd(0, kTwoPi * x));
      out.y_size.push_back(y.cwiseAbs().maxCoeff());
      g = y.real();
    }
    es.emplace_back((g + g.transpose()) / 2);
    out.largest = std::max(out.largest, es.back().eigenvalues().cwiseAbs().maxCoeff());
    if (es.back().eigenvalues()[0] < r->min_eigenvalue)
      r->min_eigenvalue = es.back().eigenvalues()[0], r->at_frequency = x;
  }
  // An eigenvalue within the rounding of the largest is zero: a cable without a shunt conductance
  // has Re Y's common-mode eigenvalue exactly 0 at DC, evaluated as -1e-15 S, and lifting it would
  // add a conductance the data does not have.
  out.floor = -kRoundingFloor * out.largest;
  // Every eigenpair is a constraint: a violation (below the floor) is to rise to the margin, any
  // other to stay where it is or above the margin. The violations and the eigenvalues at infinity
  // seed the first solution; the others join where a solution would take them below.
  const double margin = kMargin * out.largest;
  const size_t np = at.size();
  for (size_t i = 0; i < np; ++i)
    for (int k = 0; k < es[i].eigenvalues().size(); ++k) {
      const double lambda = es[i].eigenvalues()[k];
      const bool violation = lambda < out.floor;
      out.pairs.push_back({at[i], lambda, es[i].eigenvectors().col(k),
                           violation ? margin : std::min(lambda, margin),
                           violation || i + 1 == np});
    }
  out.margin = margin;
  r->sweep_points = static_cast<int>(np);
  r->passive = r->min_eigenvalue >= out.floor;
  return out;
}

// One residue perturbation (Gustavsen, "Fast passivity enforcement ... residue perturbation",
// 2008): the smallest change x of the residues and D such that every eigenvalue of Re Y at every
// sweep point, linearised with its eigenvector held (the change u^T dG u, linear in x), ends at
// the target or above. The constraints are inequalities at every point, so a point already
// passive is held above the target but left free, and a fix at one frequency cannot push another
// below zero (as equalities at the violations alone did: a clean 1 m line to 100 MHz bounced from
// one violation to the next and was refused).
//
// The change is measured as the fit measures its error: Y's change over the sweep weighted by
// 1 / (1/z0 + |Y|) (dS ~ dY / (1 + z0 |Y|)), from DC (the band alone would let the poles below it
// trade their residues against D, and move DC), and above the band, where there is no data to
// keep, at kOutOfBandWeight. Solved exactly as a least-distance problem through NNLS (Lawson and
// Hanson, Solving Least Squares Problems, ch. 23): with R the objective's triangular factor and
// z = R x, min |z| subject to F z >= h.
class ResiduePerturbation {
 public:
  // y_size: max |Y_ij| of m at each sweep point (Scan::y_size).
  ResiduePerturbation(const RationalModel& m, const std::vector<double>& sweep,
                      const std::vector<double>& y_size, double f_top, double z0)
      : w0_(kTwoPi * f_top), f_top_(f_top) {
    for (const cd& p : m.poles) poles_.push_back(p / w0_);
    n_ = state_count(poles_);
    for (int i = 0; i < m.ports; ++i)
      for (int j = i; j < m.ports; ++j) ij_.push_back({i, j});
    factor(sweep, y_size, z0);
  }

  // The change for the constraints c: each eigenvalue to the target or above. The least-distance
  // problem is solved on the seeded constraints first (the violations and infinity); the change is
  // then predicted at every constraint, those it would take below the target join, and it is
  // solved again (constraint generation: the solution of the whole set from a fraction of it).
  // x per entry (cols each); empty when no constraint asks for a change or they cannot be met.
  Eigen::VectorXd solve(const std::vector<Eigenpair>& c, double margin) const {
    const int cols = n_ + 1, ne = static_cast<int>(ij_.size()), nc = static_cast<int>(c.size());
    // B R^-1: each constraint's row of Re phi through the factor, shared by the entries, and
    // its weight per entry, uu_e = (2 - [i == j]) u_i u_j (u^T dG u = sum_e uu_e dG_e).
    Eigen::MatrixXd b(nc, cols), uu(nc, ne);
    std::vector<cd> phi(n_);
    for (int q = 0; q < nc; ++q) {
      if (std::isfinite(c[q].f)) basis(cd(0, c[q].f / f_top_), poles_, phi.data());
      for (int k = 0; k < n_; ++k) b(q, k) = std::isfinite(c[q].f) ? phi[k].real() : 0.0;
      b(q, n_) = 1.0;  // D
      for (int k = 0; k < ne; ++k) {
        const auto [i, j] = ij_[k];
        uu(q, k) = (i == j ? 1.0 : 2.0) * c[q].u[i] * c[q].u[j];
      }
    }
    const Eigen::MatrixXd br =
        r_.transpose().triangularView<Eigen::Lower>().solve(b.transpose()).transpose();
    std::vector<int> active;
    for (int q = 0; q < nc; ++q)
      if (c[q].seed) active.push_back(q);
    Eigen::VectorXd z;
    for (int round = 0; round < kConstraintRounds; ++round) {
      if (!least_distance(c, br, uu, active, &z)) return {};
      // The eigenvalues the change predicts, at every constraint.
      const Eigen::MatrixXd zk = Eigen::Map<const Eigen::MatrixXd>(z.data(), cols, ne);
      const Eigen::VectorXd moved = (uu.array() * (br * zk).array()).rowwise().sum();
      std::vector<bool> in(nc, false);
      for (int q : active) in[q] = true;
      const size_t before = active.size();
      for (int q = 0; q < nc; ++q)
        if (!in[q] && c[q].lambda + moved[q] < c[q].target - 0.5 * margin) active.push_back(q);
      if (active.size() == before) break;
    }
    if (z.size() == 0) return {};
    Eigen::VectorXd x(ne * cols);
    for (int k = 0; k < ne; ++k)
      x.segment(k * cols, cols) =
          r_.triangularView<Eigen::Upper>().solve(Eigen::VectorXd(z.segment(k * cols, cols)));
    return x;
  }

  // m plus alpha times the change x.
  void apply(RationalModel& m, const Eigen::VectorXd& x, double alpha) const {
    const int cols = n_ + 1;
    for (size_t k = 0; k < ij_.size(); ++k) {
      const auto [i, j] = ij_[k];
      const Eigen::VectorXd dx = alpha * x.segment(static_cast<Eigen::Index>(k) * cols, cols);
      int col = 0;
      for (size_t q = 0; q < m.poles.size(); ++q) {
        const bool pair = m.poles[q].imag() > 0;
        m.residues[q](i, j) += (pair ? cd(dx[col], dx[col + 1]) : cd(dx[col], 0)) * w0_;
        m.residues[q](j, i) = m.residues[q](i, j);
        col += pair ? 2 : 1;
      }
      m.d(i, j) += dx[n_];
      m.d(j, i) = m.d(i, j);
    }
  }

 private:
  // min |z| subject to F z >= h over the constraints `active` (F's row q, entry e's block
  // uu_e(q) (B R^-1)_q; h_q = target - lambda_q), through NNLS on E = [F^T; h^T] (Lawson and
  // Hanson's LDP): u = argmin |E u - e_last|, u >= 0, r = E u - e_last, z = -r_head / r_last.
  // E's Gram matrix has the constraints' structure, (B R^-1 (B R^-1)^T) .* (U U^T) + h h^T, and
  // is formed from it. False when none asks for a change or they are incompatible.
  bool least_distance(const std::vector<Eigenpair>& c, const Eigen::MatrixXd& br,
                      const Eigen::MatrixXd& uu, const std::vector<int>& active,
                      Eigen::VectorXd* z) const {
    const int cols = n_ + 1, ne = static_cast<int>(ij_.size());
    const int na = static_cast<int>(active.size());
    Eigen::MatrixXd bra(na, cols), ua(na, ne);
    Eigen::VectorXd h(na);
    for (int a = 0; a < na; ++a) {
      bra.row(a) = br.row(active[a]);
      ua.row(a) = uu.row(active[a]);
      h[a] = c[active[a]].target - c[active[a]].lambda;
    }
    if (!(h.maxCoeff() > 0)) return false;
    auto gram_column = [&](int j) -> Eigen::VectorXd {
      return ((bra * bra.row(j).transpose()).array() * (ua * ua.row(j).transpose()).array())
                 .matrix() +
             h * h[j];
    };
    const Eigen::VectorXd diagonal =
        (bra.rowwise().squaredNorm().array() * ua.rowwise().squaredNorm().array()).matrix() +
        h.cwiseAbs2();
    const Eigen::VectorXd u = nnls_gram(gram_column, diagonal, h);
    // r_head, entry k: sum_a u_a uu_k(a) (B R^-1)_a; r_last = h . u - 1.
    const Eigen::MatrixXd head = bra.transpose() * (ua.array().colwise() * u.array()).matrix();
    const double last = h.dot(u) - 1;
    if (!(std::abs(last) > 1e-12) || !head.allFinite()) return false;  // incompatible
    *z = -Eigen::Map<const Eigen::VectorXd>(head.data(), cols * ne) / last;
    return true;
  }

  // R of the weighted basis over the sweep, with a ridge so that poles close together (columns
  // nearly alike) leave it invertible.
  void factor(const std::vector<double>& sweep, const std::vector<double>& y_size, double z0) {
    const int cols = n_ + 1, ns = static_cast<int>(sweep.size());
    Eigen::MatrixXd a(2 * ns + cols, cols);
    std::vector<cd> phi(n_);
    for (int i = 0; i < ns; ++i) {
      const double w = (sweep[i] <= f_top_ ? 1.0 : kOutOfBandWeight) / (1 / z0 + y_size[i]);
      basis(cd(0, sweep[i] / f_top_), poles_, phi.data());
      for (int k = 0; k < cols; ++k) {
        const cd v = w * (k < n_ ? phi[k] : cd(1, 0));
        a(2 * i, k) = v.real(), a(2 * i + 1, k) = v.imag();
      }
    }
    const double ridge = 1e-9 * a.topRows(2 * ns).cwiseAbs().maxCoeff();
    a.bottomRows(cols) = ridge * Eigen::MatrixXd::Identity(cols, cols);
    r_ = Eigen::HouseholderQR<Eigen::MatrixXd>(a)
             .matrixQR()
             .topRows(cols)
             .triangularView<Eigen::Upper>();
  }

  double w0_, f_top_;
  Poles poles_;  // scaled by w0
  int n_ = 0;    // real basis functions
  std::vector<std::pair<int, int>> ij_;
  Eigen::MatrixXd r_;
};

// One perturbation of m, the step halved until it leaves the smallest eigenvalue higher than it
// found it (the linearisation holds for small changes only). False when no step does.
bool perturb(RationalModel& m, const std::vector<double>& sweep, double f_top, double z0,
             const Scan& now, double min_eigenvalue) {
  const ResiduePerturbation rp(m, sweep, now.y_size, f_top, z0);
  const Eigen::VectorXd x = rp.solve(now.pairs, now.margin);
  if (x.size() == 0) return false;
  for (double alpha = 1; alpha > 1e-3; alpha /= 2) {
    RationalModel trial = m;
    rp.apply(trial, x, alpha);
    PassivityReport after;
    scan(trial, sweep, &after);
    if (after.min_eigenvalue > min_eigenvalue) {
      m = std::move(trial);
      return true;
    }
  }
  return false;
}

}  // namespace

PassivityReport check_passivity(const RationalModel& m, double f_top) {
  PassivityReport r;
  scan(m, passivity_sweep(m, f_top), &r);
  return r;
}

PassivityReport enforce_passivity(RationalModel& m, const std::vector<double>& freqs, double z0) {
  const double f_top = freqs.back();
  const std::vector<double> sweep = passivity_sweep(m, f_top);
  PassivityReport first;
  Scan now = scan(m, sweep, &first);
  if (first.passive) return first;
  // Each perturbation is linear in the eigenvalues; what the linearisation missed (the
  // eigenvectors turn) is taken up by the next.
  // Steps that each lift the worst violation by less than a tenth have stalled (near-degenerate
  // eigenvalues at a sharp resonance, whose splitting the linearisation does not see: a 15 m line
  // with a stub, fitted with 68 poles, crept from -0.89 S by thousandths for minutes): two such
  // end the perturbations, which bounds their time.
  double min_eigenvalue = first.min_eigenvalue;
  int stalled = 0;
  for (int it = 1; it <= kPerturbations && stalled < 2; ++it) {
    if (!perturb(m, sweep, f_top, z0, now, min_eigenvalue)) break;
    first.perturbation_iterations = it;
    PassivityReport after;
    now = scan(m, sweep, &after);
    if (after.passive) {
      first.enforced_min_eigenvalue = after.min_eigenvalue;
      return first;
    }
    stalled = after.min_eigenvalue - min_eigenvalue < 0.1 * -min_eigenvalue ? stalled + 1 : 0;
    min_eigenvalue = after.min_eigenvalue;
  }
  // Not passive after the perturbations: the shunt conductance that lifts every eigenvalue.
  PassivityReport after = check_passivity(m, f_top);
  if (!after.passive) {
    const double add = -after.min_eigenvalue * 1.01 + 1e-12;
    m.d += add * Eigen::MatrixXd::Identity(m.ports, m.ports);
    first.added_conductance = add;
  }
  first.enforced_min_eigenvalue = check_passivity(m, f_top).min_eigenvalue;
  return first;
}

}  // namespace isolink
