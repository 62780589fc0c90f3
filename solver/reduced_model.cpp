#include "solver/reduced_model.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>

#include "solver/ac.h"
#include "solver/dense_lapack.h"
#include "solver/hessenberg_transfer.h"

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
  if (refine_batch < 0) return bad("refine_batch", refine_batch, "must be 0 (batch) or positive");
  if (max_order < 1) return bad("max_order", max_order, "must be positive");
  if (!(horizon > 0) || !std::isfinite(horizon)) return bad("horizon", horizon, "must be positive");
  if (!(edge_time >= 0) || !std::isfinite(edge_time))
    return bad("edge_time", edge_time, "must be zero or positive");
  if (!(stall_tol == 0 || (stall_tol >= tol && stall_tol < 1)))
    return bad("stall_tol", stall_tol, "must be 0 (off) or in [tol, 1)");
  return Status::Ok();
}

double ReducedModelOptions::edge_error_bound() const {
  return edge_error_bound(tol);
}

double ReducedModelOptions::edge_error_bound(double error) const {
  return error * std::log(f_max / f_min) / std::numbers::pi;
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
//
// Each vector is orthogonalised against everything before it with classical Gram-Schmidt
// repeated ("twice is enough": Giraud, Langou and Rozloznik 2005), and appended unless nothing new
// is left (below 1e-9 of its own norm). Vector by vector, not as a block projected against the
// basis and then within itself in single passes: that left the 72 m link of the corpus (spec 72) at
// 2e-3 after 64 expansion points against 8.5e-6 after 59 (its Krylov vectors are nearly dependent).
// An expansion point's vectors go as a block (add_block), each pass against the basis as it was
// a matrix product (the basis read once per pass and point, not once per vector):
// 1. one pass against the basis, every vector;
// 2. the point's vectors orthonormalised among themselves, in order, twice each, and those left
//    with 1e-9 of their first norm or less dropped: the same test as a vector's alone, made here
//    on all of them before the second pass. One pass leaves each vector about eps of its first
//    norm along the basis, which cannot lift a dropped vector's 1e-9 over the line, and what a
//    kept one carries along the basis after the cancellation goes in step 3;
// 3. the second pass against the basis, for the vectors kept (most are dropped in step 2: the
//    64 m link of the nonlinear corpus keeps at most 24 of a point's 108, its inputs reaching
//    the cable through four wires);
// 4. each vector twice against the point's vectors appended before it, and once more against
//    everything should that cancel more than half of it (after step 2 it does not: a guard).
// Vector by vector (steps 2 and 4 on each in turn, with a third pass against the whole basis
// when a vector cancelled to a thousandth, the criterion of Daniel, Gragg, Kaufman and Stewart)
// built models of orders within 2 % of these that pass the same check on the corpus's 44-100 m
// nonlinear links (033: 972 and 973, 019: 972 and 992, 000: 902 and 904), but made about 250 of
// those third passes per model, each reading the basis two or three times: 0.6 s of link 033's
// 4.3 s model, with the passes of steps 1 and 3 on all 108 vectors another 0.3 s.
struct Basis {
  Eigen::MatrixXd v, gv, cv;  // n x q
  int q = 0;

  // Appends x orthogonalised, unless nothing new is left. Returns whether it was appended.
  bool add(Eigen::VectorXd x, const Eigen::SparseMatrix<double>& g,
           const Eigen::SparseMatrix<double>& c) {
    const double norm0 = x.norm();
    if (!(norm0 > 0) || !std::isfinite(norm0)) return false;
    orthogonalise(0, q, &x, norm0);
    return append(x, norm0, g, c);
  }

  // The columns of x (an expansion point's vectors) orthogonalised as a block (above) and the new
  // directions appended. Returns how many were appended.
  int add_block(Eigen::MatrixXd x, const Eigen::SparseMatrix<double>& g,
                const Eigen::SparseMatrix<double>& c) {
    const int q0 = q;
    const Eigen::VectorXd norm0 = x.colwise().norm().transpose();
    project_out(q0, &x);
    Eigen::MatrixXd y = screen(x, norm0);
    project_out(q0, &y);
    int added = 0;
    for (Eigen::Index j = 0; j < y.cols(); ++j) {
      Eigen::VectorXd z = y.col(j);
      const double left = orthogonalise(q0, q, &z, 1.0);
      if (left < 0.5) orthogonalise(0, q, &z, 1.0);
      added += append(z, 1.0, g, c);
    }
    return added;
  }

 private:
  // One pass of x -= V (V' x) over the first q0 columns of the basis, for every column of x.
  // In slices of kSlice columns on every core (the products run on one each); the slices do
  // not depend on the core count, so neither does the rounding.
  void project_out(int q0, Eigen::MatrixXd* x) const {
    if (q0 == 0 || x->cols() == 0) return;
    constexpr Eigen::Index kSlice = 32;
    const Eigen::Index cols = x->cols();
    tbb::parallel_for(Eigen::Index{0}, (cols + kSlice - 1) / kSlice, [&](Eigen::Index s) {
      auto xs = x->middleCols(s * kSlice, std::min(kSlice, cols - s * kSlice));
      const auto old = v.leftCols(q0);
      Eigen::MatrixXd h(q0, xs.cols());
      dense_multiply(true, 1.0, old, xs, 0.0, h);    // h = old' xs
      dense_multiply(false, -1.0, old, h, 1.0, xs);  // xs -= old h
    });
  }

  // Step 2 of the block: x's columns orthonormalised among themselves, in order, twice each;
  // a column left with 1e-9 of its first norm (norm0) or less dropped.
  static Eigen::MatrixXd screen(const Eigen::MatrixXd& x, const Eigen::VectorXd& norm0) {
    Eigen::MatrixXd kept(x.rows(), x.cols());
    Eigen::Index k = 0;
    Eigen::VectorXd h;
    for (Eigen::Index j = 0; j < x.cols(); ++j) {
      if (!(norm0[j] > 0) || !std::isfinite(norm0[j])) continue;
      Eigen::VectorXd y = x.col(j);
      const auto s = kept.leftCols(k);
      for (int pass = 0; pass < 2 && k > 0; ++pass) {
        h.noalias() = s.transpose() * y;
        y.noalias() -= s * h;
      }
      const double left = y.norm();
      if (!(left > 1e-9 * norm0[j]) || !std::isfinite(left)) continue;
      kept.col(k++) = y / left;
    }
    kept.conservativeResize(Eigen::NoChange, k);
    return kept;
  }

  // Removes from x its components along columns [from, to), in two passes, or three while a
  // pass still removes more than half of what was left; stops once nothing is left. Returns |x|.
  double orthogonalise(int from, int to, Eigen::VectorXd* x, double norm0) const {
    double norm = x->norm();
    if (to <= from) return norm;
    const auto basis = v.middleCols(from, to - from);
    Eigen::VectorXd h(to - from);
    for (int pass = 0; pass < 3; ++pass) {
      dense_multiply(true, 1.0, basis, *x, 0.0, h);
      dense_multiply(false, -1.0, basis, h, 1.0, *x);
      const double left = x->norm();
      const bool enough = pass >= 1 && left > 0.5 * norm;
      norm = left;
      if (enough || !(norm > 1e-9 * norm0)) break;
    }
    return norm;
  }

  bool append(Eigen::VectorXd& x, double norm0, const Eigen::SparseMatrix<double>& g,
              const Eigen::SparseMatrix<double>& c) {
    const double norm = x.norm();
    if (!(norm > 1e-9 * norm0) || !std::isfinite(norm)) return false;
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
// branch rows negated, see the constructor): the basis, the expansion points, the check of each
// model at the check frequencies and the projection. One Reducer per search; `ac` and every
// argument must outlive it.
class Reducer {
 public:
  Reducer(const Circuit& circuit, AcAnalysis& ac,
          const std::vector<std::vector<double>>& excitations,
          const std::vector<std::vector<double>>& dc_solutions, const std::vector<Probe>& probes,
          const ReducedModelOptions& opt, bool passive_form);

  // Runs the search once: the model within opt.tol at every check frequency, or the error.
  StatusOr<ReducedModel> run();

 private:
  void assemble_pencil(bool passive_form);
  struct CheckRows {
    bool transposed = false;
    std::vector<std::array<AcAnalysis::Vector, 2>> node_rows;  // per probe
    std::vector<std::vector<int>> source_rows;                 // per source: its nonzeros
  };
  struct ExactPoint {
    std::vector<std::vector<Cplx>> h;            // [k][p]
    std::vector<std::vector<double>> node_peak;  // [k][p]: max(|H_ka|, |H_kb|)
  };
  Status add_checks(const std::vector<double>& fs);
  CheckRows check_rows() const;
  Status exact_at(AcAnalysis& ac, const CheckRows& rows, double f, ExactPoint* out) const;
  Status start_checks();
  void seed_basis();
  StatusOr<bool> expand_at(double f);
  Status expand_at_all(const std::vector<double>& fs);
  Status krylov_block(AcAnalysis& ac, double f, Eigen::MatrixXd* out) const;
  Status expand_at_first_points();
  double error_at(size_t f) const;
  void measure();
  void measure_range(size_t from);
  void project();
  void project_ports(Eigen::MatrixXd* br, Eigen::MatrixXd* lr);
  ReducedModel empty_model(const ReducedModelStats& stats) const;
  double sigma() const;
  Status build();
  StatusOr<bool> accept();
  Status project_hessenberg();
  // The modes of the current basis's projection, from its Hessenberg form (projected_).
  Status modal_form(ReducedModel* mod);
  StatusOr<bool> refine_checks();
  Status expand_where_worst();
  // The search can go no further: the check's tolerance becomes opt_.stall_tol when the error is
  // within it (and was not already). True when relaxed.
  bool relax() {
    if (!(opt_.stall_tol > tol_) || !(model_.stats.error <= opt_.stall_tol)) return false;
    tol_ = opt_.stall_tol;
    relaxed_ = true;
    return true;
  }

  const Circuit& circuit_;
  AcAnalysis& ac_;
  // The second core's sparse LU (add_checks, expand_at_all), made by start_checks.
  std::unique_ptr<AcAnalysis> ac_second_;
  const std::vector<std::vector<double>>& excitations_;
  const std::vector<std::vector<double>>& dc_solutions_;
  const std::vector<Probe>& probes_;
  const ReducedModelOptions& opt_;
  const int n_;
  const size_t nk_, np_;
  double tol_;                    // the check's tolerance: opt_.tol, or opt_.stall_tol once relaxed
  bool relaxed_ = false;          // relax() took it
  std::vector<double> row_sign_;  // per unknown 1..n (index 0 = unknown 1): +1 or -1
  Eigen::SparseMatrix<double> g_, c_;  // the pencil in this sign form
  ReducedModelStats st_;               // factorizations and expansion points so far
  ReducedModel model_;                 // the last model built: its stats; poles when modal_
  // The last model as a projection (its transfer through the Hessenberg form) while !modal_.
  // The search measures every intermediate model that way and diagonalises only the one that
  // passes (accept()); should that modal form fail the check where the projection passed (a
  // right-half-plane pole dropped, eigenvectors too ill-conditioned), every later step is modal.
  HessenbergTransfer projected_;
  int projected_order_ = -1;  // the basis order projected_ was made at
  bool modal_ = false;
  bool modal_each_step_ = false;
  int refine_failures_ = 0;     // midpoints the last refinement failed at (0 when it passed)
  std::vector<double> errors_;  // the last model's error at each check frequency
  std::vector<double> freqs_;   // the check frequencies
  std::vector<std::vector<std::vector<Cplx>>> exact_;  // [check][k][p]
  CheckRows check_rows_;                    // add_checks's right-hand sides (start_checks)
  std::vector<std::vector<double>> scale_;  // [k][p]: peak |H| with DC
  // [k][p]: the peak over the grid and DC of max(|H_ka|, |H_kb|), probe p = v(a, b): what its
  // nodes carry (opt_.difference_scale).
  std::vector<std::vector<double>> node_scale_;
  Basis basis_;
  Eigen::MatrixXd gr_, cr_;  // V'GV and V'CV over the basis so far
  int max_order_ = 0;
  std::vector<double> used_;                     // expansion points so far
  std::vector<std::pair<double, double>> open_;  // check intervals not yet refined
};

Reducer::Reducer(const Circuit& circuit, AcAnalysis& ac,
                 const std::vector<std::vector<double>>& excitations,
                 const std::vector<std::vector<double>>& dc_solutions,
                 const std::vector<Probe>& probes, const ReducedModelOptions& opt,
                 bool passive_form)
    : circuit_(circuit),
      ac_(ac),
      excitations_(excitations),
      dc_solutions_(dc_solutions),
      probes_(probes),
      opt_(opt),
      n_(circuit.unknown_count()),
      nk_(excitations.size()),
      np_(probes.size()),
      tol_(opt.tol) {
  assemble_pencil(passive_form);
  scale_.assign(nk_, std::vector<double>(np_, 0.0));
  node_scale_.assign(nk_, std::vector<double>(np_, 0.0));
  for (size_t k = 0; k < nk_; ++k)
    for (size_t p = 0; p < np_; ++p) {
      const double a = dc_solutions_[k][probes_[p].a], b = dc_solutions_[k][probes_[p].b];
      scale_[k][p] = std::max(1e-15, std::fabs(a - b));
      node_scale_[k][p] = std::max(std::fabs(a), std::fabs(b));
    }
  // The basis and its images are three dense n x q arrays: at most kMaxBasisBytes in all (their
  // capacity, grown by doubling, at most twice that).
  constexpr double kMaxBasisBytes = 384.0 * (1 << 20);
  max_order_ = static_cast<int>(
      std::min<double>(opt_.max_order, kMaxBasisBytes / (3.0 * sizeof(double) * n_)));
}

// G and C as real sparse matrices over unknowns 1..n (index 0 = unknown 1), with the rows of
// the branch unknowns (inductors, voltage sources) negated: -v_a + v_b + s L i = 0 instead of
// MNA's v_a - v_b - s L i = 0. The solution is the same for every s (the Krylov vectors too),
// but in this form G + G' is positive semi-definite (resistors only; the branch incidence is
// skew) and C symmetric positive semi-definite (capacitances, the inductance matrix), so the
// congruence projection below keeps the circuit's passivity (PRIMA's theorem): every pole of
// the reduced model is stable. With MNA's own signs C is indefinite, and on long links the
// projection made dozens of right-half-plane poles and a modal form that could not get within
// 2e-5 of a projection that was itself within 1e-11 of the circuit.
void Reducer::assemble_pencil(bool passive_form) {
  const int n = n_;
  row_sign_.assign(n, 0.0);
  for (int i = 0; i < n; ++i)
    row_sign_[i] = passive_form && !circuit_.unknown_is_node(i + 1) ? -1.0 : 1.0;
  g_.resize(n, n);
  c_.resize(n, n);
  std::vector<Eigen::Triplet<double>> tg, tc;
  const auto& cp = ac_.col_start();
  const auto& ri = ac_.row_index();
  for (int col = 0; col < n; ++col)
    for (int k = cp[col]; k < cp[col + 1]; ++k) {
      const double sign = row_sign_[ri[k]];
      if (ac_.g_values()[k] != 0) tg.emplace_back(ri[k], col, sign * ac_.g_values()[k]);
      if (ac_.c_values()[k] != 0) tc.emplace_back(ri[k], col, sign * ac_.c_values()[k]);
    }
  g_.setFromTriplets(tg.begin(), tg.end());
  c_.setFromTriplets(tc.begin(), tc.end());
}

// The exact transfer at check frequencies `fs` (appended to the grid), and each (k, p)'s scale
// grown to the peak |H|. H_kp = l_p' A^-1 e_k takes one solve per source, or one transposed
// solve per probe, z_p = A^-T l_p and H_kp = z_p' e_k: whichever is fewer (an edge response
// drives two sources and reads one probe). The frequencies go in two halves on two cores, each
// with its own sparse LU (ac_ and ac_second_); each half's values
// depend on the split alone, not on the cores.
Status Reducer::add_checks(const std::vector<double>& fs) {
  const CheckRows& rows = check_rows_;
  std::vector<ExactPoint> points(fs.size());
  const size_t half = fs.size() / 2;
  Status first_status = Status::Ok(), second_status = Status::Ok();
  auto run = [&](AcAnalysis& ac, size_t from, size_t to, Status* status) {
    for (size_t i = from; i < to && status->ok(); ++i)
      *status = exact_at(ac, rows, fs[i], &points[i]);
  };
  tbb::parallel_invoke([&] { run(ac_, half, fs.size(), &first_status); },
                       [&] {
                         if (half > 0) run(*ac_second_, 0, half, &second_status);
                       });
  if (!second_status.ok()) return second_status;
  if (!first_status.ok()) return first_status;
  for (size_t i = 0; i < fs.size(); ++i) {
    ++st_.factorizations;
    freqs_.push_back(fs[i]);
    for (size_t k = 0; k < nk_; ++k)
      for (size_t p = 0; p < np_; ++p) {
        scale_[k][p] = std::max(scale_[k][p], std::abs(points[i].h[k][p]));
        node_scale_[k][p] = std::max(node_scale_[k][p], points[i].node_peak[k][p]);
      }
    exact_.push_back(std::move(points[i].h));
  }
  return Status::Ok();
}

// The right-hand sides of add_checks's solves (transposed: per probe; else per source).
Reducer::CheckRows Reducer::check_rows() const {
  CheckRows r;
  r.transposed = np_ < nk_;
  if (!r.transposed) return r;
  // Per probe: with difference_scale, a row e_u per probe node (u = 0: ground, no row), H_kp the
  // difference of the two nodes' transfers and node_scale_ the larger; without it, one row l_p
  // (one solve per probe, as the LTI engine's checks need).
  for (size_t p = 0; p < np_; ++p) {
    std::array<AcAnalysis::Vector, 2>& rows = r.node_rows.emplace_back();
    const int a = probes_[p].a, b = probes_[p].b;
    if (!opt_.difference_scale) {
      rows[0].assign(static_cast<size_t>(n_) + 1, 0.0);
      rows[0][a] += 1.0;
      rows[0][b] -= 1.0;
      rows[0][0] = 0.0;
      continue;
    }
    for (int side = 0; side < 2; ++side) {
      const int u = side == 0 ? a : b;
      if (u == 0) continue;
      rows[side].assign(static_cast<size_t>(n_) + 1, 0.0);
      rows[side][u] = 1.0;
    }
  }
  for (size_t k = 0; k < nk_; ++k) {
    std::vector<int>& nz = r.source_rows.emplace_back();
    for (int i = 1; i <= n_; ++i)
      if (excitations_[k][i] != 0) nz.push_back(i);
  }
  return r;
}

// The exact transfer at f through `ac` (factored there), and per pair the larger node transfer.
Status Reducer::exact_at(AcAnalysis& ac, const CheckRows& rows, double f, ExactPoint* out) const {
  if (Status s = ac.factor(f); !s.ok()) return s;
  out->h.assign(nk_, std::vector<Cplx>(np_));
  out->node_peak.assign(nk_, std::vector<double>(np_, 0.0));
  // Per source and probe: the transfers to the probe's nodes a and b (0 for ground).
  auto take = [&](size_t k, size_t p, Cplx at_a, Cplx at_b) {
    out->h[k][p] = at_a - at_b;
    out->node_peak[k][p] = std::max(std::abs(at_a), std::abs(at_b));
  };
  if (rows.transposed) {
    for (size_t p = 0; p < np_; ++p) {
      std::array<std::vector<Cplx>, 2> at;  // [side][k]
      for (int side = 0; side < 2; ++side) {
        at[side].assign(nk_, 0.0);
        if (rows.node_rows[p][side].empty()) continue;
        const AcAnalysis::Vector z = ac.solve_transposed(rows.node_rows[p][side]);
        for (size_t k = 0; k < nk_; ++k)
          for (int i : rows.source_rows[k]) at[side][k] += z[i] * excitations_[k][i];
      }
      for (size_t k = 0; k < nk_; ++k) take(k, p, at[0][k], at[1][k]);
    }
  } else {
    for (size_t k = 0; k < nk_; ++k) {
      AcAnalysis::Vector b(excitations_[k].begin(), excitations_[k].end());
      b[0] = 0.0;
      const AcAnalysis::Vector x = ac.solve_factored(b);
      for (size_t p = 0; p < np_; ++p)
        take(k, p, probes_[p].a ? x[probes_[p].a] : 0.0, probes_[p].b ? x[probes_[p].b] : 0.0);
    }
  }
  return Status::Ok();
}

// Pivots from the middle of the band first: the refactorizations below reuse them, and the
// ones a 1 kHz matrix would choose (its 1e-12 S ties on floating nodes) fill in badly. Then the
// check grid: opt.check_points frequencies, log-spaced over the band.
// The second core's AC solver starts from the same pivots.
Status Reducer::start_checks() {
  StatusOr<AcAnalysis> second = AcAnalysis::create(circuit_);
  if (!second) return second.status();
  ac_second_ = std::make_unique<AcAnalysis>(std::move(*second));
  for (AcAnalysis* ac : {&ac_, ac_second_.get()})
    if (Status s = ac->factor(std::sqrt(opt_.f_min * opt_.f_max)); !s.ok()) return s;
  ++st_.factorizations;
  check_rows_ = check_rows();
  std::vector<double> fs(opt_.check_points);
  for (int i = 0; i < opt_.check_points; ++i)
    fs[i] = opt_.f_min *
            std::pow(opt_.f_max / opt_.f_min, static_cast<double>(i) / (opt_.check_points - 1));
  return add_checks(fs);
}

// The DC solutions, and the excitations that sit on a branch row.
void Reducer::seed_basis() {
  const int n = n_;
  basis_.v.resize(n, 0);
  basis_.gv.resize(n, 0);
  basis_.cv.resize(n, 0);
  for (size_t k = 0; k < nk_; ++k) {
    Eigen::VectorXd x(n);
    for (int i = 0; i < n; ++i) x[i] = dc_solutions_[k][i + 1];
    basis_.add(x, g_, c_);
  }
  if (n <= opt_.full_order_at_most)  // the full basis: every unknown's unit vector
    for (int i = 0; i < n; ++i) basis_.add(Eigen::VectorXd::Unit(n, i), g_, c_);
  // A voltage source's excitation is its own branch unknown (unit at its branch row). The
  // Galerkin projection tests each equation only along the basis, and the source's equation
  // v_a - v_b = u only along a basis direction that moves the source's current on its own.
  // The DC and Krylov vectors never do that when node a has no resistor (a source straight
  // into an inductor: KCL at a ties the source's current to the inductor's in every one of
  // them), so v_a was left undetermined and the projected pencil singular in both sign forms
  // (issue 28: V -> L -> R). The excitation itself is that direction; one more per source.
  for (size_t k = 0; k < nk_; ++k) {
    Eigen::VectorXd e(n);
    bool on_branch = false;
    for (int i = 0; i < n; ++i) {
      e[i] = excitations_[k][i + 1];
      on_branch |= e[i] != 0 && !circuit_.unknown_is_node(i + 1);
    }
    if (on_branch) basis_.add(e, g_, c_);
  }
}

// Adds the Krylov vectors at j 2 pi f; false when none was new.
StatusOr<bool> Reducer::expand_at(double f) {
  Eigen::MatrixXd block;
  if (Status s = krylov_block(ac_, f, &block); !s.ok()) return s;
  ++st_.factorizations;
  ++st_.expansion_points;
  return basis_.add_block(std::move(block), g_, c_) > 0;
}

// expand_at for each of fs in turn, their Krylov vectors computed two points at a time (the
// second through add_checks's second AC solver). Each point's vectors depend on the point and
// the solver it went to, the split fixed by fs's order: not on the cores.
Status Reducer::expand_at_all(const std::vector<double>& fs) {
  std::vector<Eigen::MatrixXd> blocks(fs.size());
  std::vector<Status> status(fs.size(), Status::Ok());
  for (size_t i = 0; i < fs.size(); i += 2) {
    if (i + 1 < fs.size()) {
      tbb::parallel_invoke(
          [&] { status[i] = krylov_block(ac_, fs[i], &blocks[i]); },
          [&] { status[i + 1] = krylov_block(*ac_second_, fs[i + 1], &blocks[i + 1]); });
    } else {
      for (size_t j = i; j < std::min(i + 2, fs.size()); ++j)
        status[j] = krylov_block(ac_, fs[j], &blocks[j]);
    }
  }
  for (size_t i = 0; i < fs.size(); ++i) {
    if (!status[i].ok()) return status[i];
    ++st_.factorizations;
    ++st_.expansion_points;
    basis_.add_block(std::move(blocks[i]), g_, c_);
    used_.push_back(fs[i]);
  }
  return Status::Ok();
}

// The point's Krylov vectors, real and imaginary parts, in the order they are added: per source,
// A^-1 e_k, (A^-1 C) A^-1 e_k, ... (opt_.moments of them), A = G + j 2 pi f C factored in `ac`.
Status Reducer::krylov_block(AcAnalysis& ac, double f, Eigen::MatrixXd* out) const {
  const int n = n_;
  if (Status s = ac.factor(f); !s.ok()) return s;
  Eigen::MatrixXd& block = *out;
  block.resize(n, 2 * opt_.moments * static_cast<Eigen::Index>(nk_));
  Eigen::Index cols = 0;
  Eigen::VectorXd cr(n), ci(n);
  for (size_t k = 0; k < nk_; ++k) {
    AcAnalysis::Vector b(excitations_[k].begin(), excitations_[k].end());
    b[0] = 0.0;
    for (int m = 0; m < opt_.moments; ++m) {
      AcAnalysis::Vector x = ac.solve_factored(b);
      Eigen::VectorXd re(n), im(n);
      for (int i = 0; i < n; ++i) re[i] = x[i + 1].real(), im[i] = x[i + 1].imag();
      const double norm = std::sqrt(re.squaredNorm() + im.squaredNorm());
      if (!(norm > 0) || !std::isfinite(norm)) break;
      block.col(cols++) = re;
      block.col(cols++) = im;
      // Next moment: A^-1 C x (normalised; only the direction matters), the circuit's own C x
      // (row_sign undone).
      cr.noalias() = c_ * re;
      ci.noalias() = c_ * im;
      b.assign(n + 1, 0.0);
      for (int i = 0; i < n; ++i) b[i + 1] = Cplx(cr[i], ci[i]) * (row_sign_[i] / norm);
    }
  }
  block.conservativeResize(Eigen::NoChange, cols);
  return Status::Ok();
}

// The first expansion points: f_min, f_max / 10 and the caller's start points in the band.
Status Reducer::expand_at_first_points() {
  std::vector<double> first = {opt_.f_min, opt_.f_max / 10};
  for (double f : opt_.start_points)
    if (f >= opt_.f_min && f <= opt_.f_max &&
        std::find(first.begin(), first.end(), f) == first.end())
      first.push_back(f);
  for (double f : first) {
    StatusOr<bool> added = expand_at(f);
    if (!added) return added.status();
    used_.push_back(f);
  }
  return Status::Ok();
}

// The last model's error at check frequency f (index into freqs_): the largest over sources and
// probes of |H_model - H_exact| over that pair's peak |H|.
double Reducer::error_at(size_t f) const {
  const Cplx jw(0.0, 2 * std::numbers::pi * freqs_[f]);
  Eigen::MatrixXcd h;
  if (modal_) {
    // ReducedModel::transfer's sum, each mode's 1 / (jw - p) computed once for every pair.
    const size_t q = model_.poles.size();
    std::vector<Cplx> w1(q), w2(q);
    for (size_t i = 0; i < q; ++i) {
      const Cplx z = jw - model_.poles[i], zc = jw - std::conj(model_.poles[i]);
      w1[i] = std::conj(z) / std::norm(z);
      w2[i] = std::conj(zc) / std::norm(zc);
    }
    h.resize(nk_, np_);
    for (size_t k = 0; k < nk_; ++k)
      for (size_t p = 0; p < np_; ++p) {
        Cplx sum = model_.direct[k][p];
        const Cplx* in = model_.input[k].data();
        const Cplx* out = model_.output[p].data();
        for (size_t i = 0; i < q; ++i) {
          const Cplx r = out[i] * in[i];
          sum += model_.paired[i] ? 0.5 * (r * w1[i] + std::conj(r) * w2[i]) : r * w1[i];
        }
        h(k, p) = sum;
      }
  } else {
    h = projected_.at(jw);
  }
  // The edge spectrum's envelope (header: what the check guarantees).
  const double weight = opt_.edge_time > 0
                            ? std::min(1.0, 1.0 / (std::numbers::pi * freqs_[f] * opt_.edge_time))
                            : 1.0;
  double e = 0;
  for (size_t p = 0; p < np_; ++p) {
    // A source that hardly reaches the probe (not at all: a part of the circuit the probe is
    // not in) is measured against a millionth of the strongest source's peak there, not its
    // own: its transfer, 0 but for the model's rounding, would otherwise never pass.
    double strongest = 0;
    for (size_t k = 0; k < nk_; ++k) strongest = std::max(strongest, scale_[k][p]);
    for (size_t k = 0; k < nk_; ++k) {
      double scale = std::max(scale_[k][p], 1e-6 * strongest);
      if (opt_.difference_scale) scale = std::max(scale, node_scale_[k][p]);
      const double x = weight * std::abs(h(k, p) - exact_[f][k][p]) / scale;
      if (!(x <= e)) e = x;  // a NaN sticks: such a model never passes
    }
  }
  return e;
}

// The last model's error over the check grid, and where it is largest.
// The frequencies are measured on every core (error_at reads the model only): on the 28 m
// link's port model (order up to 667, 13 models, 48-133 frequencies) a fifth of its time.
// Every frequency, every model. Measuring first where the model before failed (the rest once
// those pass) took 7-13 % off the 44-100 m nonlinear links' models, but the search, choosing
// from stale errors, then stalled at 2.8e-5 on a fitted Touchstone cable
// (tests/analysis/touchstone_export_test.cpp, Capchoke5m), measuring everything before giving
// up included.
void Reducer::measure() {
  model_.stats.error = 0;
  measure_range(0);
  for (size_t f = 0; f < freqs_.size(); ++f) {
    const double e = errors_[f];
    if (!(e <= model_.stats.error))
      model_.stats.error = e, model_.stats.error_frequency = freqs_[f];
  }
}

// errors_[f] = error_at(f) for f from `from` on, in parallel.
void Reducer::measure_range(size_t from) {
  errors_.resize(freqs_.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(from, freqs_.size()),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t f = r.begin(); f != r.end(); ++f) errors_[f] = error_at(f);
                    });
}

// Gr = V'GV and Cr = V'CV, grown by the rows and columns of the vectors added since the last
// build (the basis only grows, and its earlier vectors do not change).
void Reducer::project() {
  const int q = basis_.q, q0 = static_cast<int>(gr_.rows());
  if (q == q0) return;
  gr_.conservativeResize(q, q);
  cr_.conservativeResize(q, q);
  const auto v = basis_.v.leftCols(q);
  const auto added = basis_.v.middleCols(q0, q - q0);
  dense_multiply(true, 1.0, v, basis_.gv.middleCols(q0, q - q0), 0.0, gr_.rightCols(q - q0));
  dense_multiply(true, 1.0, v, basis_.cv.middleCols(q0, q - q0), 0.0, cr_.rightCols(q - q0));
  dense_multiply(true, 1.0, added, basis_.gv.leftCols(q0), 0.0, gr_.bottomLeftCorner(q - q0, q0));
  dense_multiply(true, 1.0, added, basis_.cv.leftCols(q0), 0.0, cr_.bottomLeftCorner(q - q0, q0));
}

// Brings Gr and Cr up to the basis (project()) and gives the projected inputs Br = V'B (q x nk,
// in this sign form) and outputs Lr = LV (np x q).
void Reducer::project_ports(Eigen::MatrixXd* br, Eigen::MatrixXd* lr) {
  project();
  const int q = basis_.q, n = n_;
  br->resize(q, static_cast<Eigen::Index>(nk_));
  lr->resize(static_cast<Eigen::Index>(np_), q);
  const auto v = basis_.v.leftCols(q);
  for (size_t k = 0; k < nk_; ++k) {
    Eigen::VectorXd e(n);
    for (int i = 0; i < n; ++i) e[i] = row_sign_[i] * excitations_[k][i + 1];
    br->col(k) = v.transpose() * e;
  }
  for (size_t p = 0; p < np_; ++p)
    for (int j = 0; j < q; ++j)
      (*lr)(p, j) = (probes_[p].a > 0 ? v(probes_[p].a - 1, j) : 0.0) -
                    (probes_[p].b > 0 ? v(probes_[p].b - 1, j) : 0.0);
}

// A model with no modes yet (H = 0) and the given stats.
ReducedModel Reducer::empty_model(const ReducedModelStats& stats) const {
  ReducedModel mod;
  mod.direct.assign(nk_, std::vector<double>(np_, 0.0));
  mod.input.assign(nk_, {});
  mod.output.assign(np_, {});
  mod.stats = stats;
  return mod;
}

// sigma: the middle of the band on a log scale, where G + sigma C is far from singular.
double Reducer::sigma() const {
  return 2 * std::numbers::pi * std::sqrt(opt_.f_min * opt_.f_max);
}

// Builds the model of the current basis into model_ (and projected_) and measures its error:
// the projection's transfer through its Hessenberg form, or the pole-residue form (below, and
// at every step once modal_each_step_).
Status Reducer::build() {
  ++st_.steps;
  ReducedModel mod = empty_model(st_);
  mod.stats.order = basis_.q;
  // Diagonalised directly where staging does not pay. The Hessenberg evaluation costs about
  // 9 q^2 flops a check frequency, the eigendecomposition about 25 q^3 once: below q of about
  // the number of check frequencies, the grid's evaluations cost more than the
  // eigendecomposition they save. And the first model from a neighbour's expansion points
  // (opt_.start_points: a sweep's or a fit's next circuit) usually passes at once, so staging it
  // would add the evaluations to the eigendecomposition. (4-point bridge-to-stack sweep, order
  // about 150: 13.17 G instructions with every step staged, 12.54 G before staging.)
  // The full basis (opt_.full_order_at_most) passes at once too: diagonalised directly.
  // And a model after a refinement that failed at one or two midpoints is usually the last
  // (on the corpus's 44-100 m nonlinear links, four of five): diagonalised at once, it skips the
  // Hessenberg evaluation of the grid (a tenth of a 64 m link's model) and the accepted
  // model's second measurement; should it fail, its eigendecomposition was the loss.
  const bool small = basis_.q < static_cast<int>(freqs_.size());
  const bool full = n_ <= opt_.full_order_at_most;
  const bool likely_last = refine_failures_ > 0 && refine_failures_ <= 2;
  refine_failures_ = 0;
  modal_ = modal_each_step_ || small || full || likely_last ||
           (st_.steps == 1 && !opt_.start_points.empty());
  // q = 0: nothing reaches the probes (no source drives anything): H = 0
  if (basis_.q != 0) {
    if (Status s = project_hessenberg(); !s.ok()) return s;
    if (modal_)
      if (Status s = modal_form(&mod); !s.ok()) return s;
  }
  model_ = std::move(mod);
  measure();
  return Status::Ok();
}

// The model that passed the check as a projection, diagonalised and measured again over the
// whole grid (refinements included): true when it passes too. If it does not, model_ is the
// failed modal form and the search goes on with a modal form at every step.
StatusOr<bool> Reducer::accept() {
  if (modal_) return true;
  ReducedModel mod = empty_model(model_.stats);
  if (basis_.q != 0)
    if (Status s = modal_form(&mod); !s.ok()) return s;
  model_ = std::move(mod);
  modal_ = true;
  measure();
  if (model_.stats.error <= tol_) return true;
  modal_each_step_ = true;
  return false;
}

// projected_ made for the current basis (once per order: the basis only grows).
Status Reducer::project_hessenberg() {
  if (projected_order_ == basis_.q) return Status::Ok();
  Eigen::MatrixXd br, lr;
  project_ports(&br, &lr);
  if (Status s = projected_.set(gr_, cr_, br, lr, sigma()); !s.ok()) return s;
  projected_order_ = basis_.q;
  return Status::Ok();
}

// The reduced pencil's eigen-decomposition as poles and residues in `mod`: direct terms for the
// instantaneous modes, right-half-plane poles dropped (and counted).
Status Reducer::modal_form(ReducedModel* mod) {
  const double sigma = this->sigma();
  // Instantaneous: lambda = 0, or a mode so fast (|lambda| under 1e-6 / (2 pi f_max): a time
  // constant of 0.05 fs, a pole over 2e16 rad/s) that its share 1 / (1 + (s - sigma) lambda)
  // is constant within 1e-6 over the whole band: the direct terms. The zero eigenvalues of a
  // singular Cr come out at about 1e-12 of the largest, of either sign: on V -> L -> R at +-1e-19
  // s against 9e-8 s, one was a pole at -8.9e18 rad/s and the other a right-half-plane pole,
  // dropped, and v(in) lost its direct term (error 1).
  const double instant = 1e-6 / (2 * std::numbers::pi * opt_.f_max);
  if (Status s = project_hessenberg(); !s.ok()) return s;
  StatusOr<ModalSplit> split = projected_.modes(1e-14, instant);
  if (!split) return Status::Error("reduced model: " + split.status().message());
  mod->stats.direct_modes += split->rest_count;
  for (size_t k = 0; k < nk_; ++k)
    for (size_t p = 0; p < np_; ++p) mod->direct[k][p] += split->rest(p, k);
  const Eigen::VectorXcd& lambda = split->values;
  const Eigen::MatrixXcd& d = split->inputs;    // modes x nk
  const Eigen::MatrixXcd& cw = split->outputs;  // np x modes
  const int modes_in = static_cast<int>(lambda.size());
  for (int i = 0; i < modes_in; ++i) {
    const Cplx pole = sigma - 1.0 / lambda[i];
    // A complex pole's conjugate (the next eigenvalue: a real matrix's come in exact pairs,
    // with conjugate vectors) is carried by it: one mode, output doubled, real part taken.
    const bool paired =
        lambda[i].imag() != 0 && i + 1 < modes_in && lambda[i + 1] == std::conj(lambda[i]);
    const int modes = paired ? 2 : 1;
    if (paired) ++i;
    const int at = paired ? i - 1 : i;
    if (pole.real() > 0 && pole.real() * opt_.horizon >= 1e-3) {
      // Dropped; the check sees what that costs (a pole with weight fails it).
      double weight = 0;
      for (size_t k = 0; k < nk_; ++k)
        for (size_t p = 0; p < np_; ++p)
          weight =
              std::max(weight, std::abs(cw(p, at) * d(at, k) / lambda[at] / pole) / scale_[k][p]);
      mod->stats.dropped += modes;
      mod->stats.dropped_weight = std::max(mod->stats.dropped_weight, weight);
      continue;
    }
    mod->poles.push_back(pole);
    mod->paired.push_back(paired);
    mod->stats.poles += modes;
    for (size_t k = 0; k < nk_; ++k) mod->input[k].push_back(d(at, k) / lambda[at]);
    for (size_t p = 0; p < np_; ++p)
      mod->output[p].push_back(static_cast<double>(modes) * cw(p, at));
  }
  return Status::Ok();
}

// Refinement of a model that passes the grid, as adaptive quadrature refines: every open
// interval of the check grid (at first all of them) is tested at its geometric midpoint, where
// a resonance could hide. An interval whose midpoint passes is closed; one whose midpoint fails
// leaves its two halves open, the midpoint joins the grid and the search goes on (model_'s error
// then the worst midpoint's). True when the search is done: every midpoint passed, or the grid
// would grow past opt.max_check_points.
StatusOr<bool> Reducer::refine_checks() {
  std::vector<std::pair<double, double>> next;
  std::vector<double> mids;
  for (const auto& [lo, hi] : open_)
    if (hi > lo * (1 + 1e-9)) mids.push_back(std::sqrt(lo * hi));
  if (freqs_.size() + mids.size() > static_cast<size_t>(opt_.max_check_points)) return true;
  const size_t before = freqs_.size();
  if (Status s = add_checks(mids); !s.ok()) return s;
  double worst = 0, worst_f = 0;
  measure_range(before);
  for (size_t f = before; f < freqs_.size(); ++f) {
    const double e = errors_[f];
    if (e > tol_) {
      const auto it = std::find_if(open_.begin(), open_.end(), [&](const auto& iv) {
        return iv.first < freqs_[f] && freqs_[f] < iv.second;
      });
      next.push_back({it->first, freqs_[f]});
      next.push_back({freqs_[f], it->second});
    }
    if (!(e <= worst)) worst = e, worst_f = freqs_[f];
  }
  refine_failures_ = static_cast<int>(next.size() / 2);
  open_ = std::move(next);
  if (worst <= tol_) return true;
  model_.stats.error = worst;
  model_.stats.error_frequency = worst_f;
  return false;
}

// Check frequencies by the error there, worst first; the first one whose vectors are new.
// Then, up to `batch` points in all, the next-worst local maxima of the error over the grid
// (other resonances): one build per step instead of one per point. An error when no point adds
// a new direction.
Status Reducer::expand_where_worst() {
  std::vector<std::pair<double, double>> ranked;  // (error, f)
  std::vector<std::pair<double, double>> by_f;    // (f, error), by frequency
  for (size_t f = 0; f < freqs_.size(); ++f) {
    const double e = errors_[f];
    by_f.emplace_back(freqs_[f], e);
    if (e > tol_) ranked.emplace_back(e, freqs_[f]);
  }
  std::sort(ranked.rbegin(), ranked.rend());
  std::sort(by_f.begin(), by_f.end());
  std::vector<std::pair<double, double>> peaks;  // (error, f): local maxima over tol
  for (size_t i = 0; i < by_f.size(); ++i) {
    const double e = by_f[i].second;
    if (e > tol_ && !(i > 0 && by_f[i - 1].second > e) &&
        !(i + 1 < by_f.size() && by_f[i + 1].second > e))
      peaks.emplace_back(e, by_f[i].first);
  }
  std::sort(peaks.rbegin(), peaks.rend());
  auto is_used = [&](double f) { return std::find(used_.begin(), used_.end(), f) != used_.end(); };
  bool grew = false;
  for (const auto& [e, f] : ranked) {
    if (is_used(f)) continue;
    StatusOr<bool> added = expand_at(f);
    if (!added) return added.status();
    used_.push_back(f);
    if (*added) {
      grew = true;
      break;
    }
    if (static_cast<int>(used_.size()) >= opt_.max_points) break;
  }
  std::vector<double> more;  // the batch's other points: the next-worst peaks not yet used
  const int batch = refine_failures_ > 0 && opt_.refine_batch > 0 ? opt_.refine_batch : opt_.batch;
  for (const auto& pk : peaks) {
    if (!grew || 1 + static_cast<int>(more.size()) >= batch ||
        static_cast<int>(used_.size() + more.size()) >= opt_.max_points)
      break;
    if (!is_used(pk.second)) more.push_back(pk.second);
  }
  if (Status s = expand_at_all(more); !s.ok()) return s;
  if (!grew && relax()) return Status::Ok();
  if (!grew)
    return Status::Error(fmt::format(
        "reduced model: error {:.2g} at {:.4g} Hz and no expansion point adds a new direction "
        "(order {})",
        model_.stats.error, model_.stats.error_frequency, basis_.q));
  return Status::Ok();
}

StatusOr<ReducedModel> Reducer::run() {
  if (Status s = start_checks(); !s.ok()) return s;
  seed_basis();
  for (size_t i = 0; i + 1 < freqs_.size(); ++i) open_.push_back({freqs_[i], freqs_[i + 1]});
  if (Status s = expand_at_first_points(); !s.ok()) return s;
  while (true) {
    if (Status s = build(); !s.ok()) return s;
    if (model_.stats.error <= tol_) {
      StatusOr<bool> done = refine_checks();
      if (!done) return done.status();
      if (*done) {
        StatusOr<bool> accepted = accept();
        if (!accepted) return accepted.status();
        if (*accepted) break;
      }
    }
    const bool at_limit =
        static_cast<int>(used_.size()) >= opt_.max_points || basis_.q >= max_order_;
    if (at_limit && relax()) continue;
    if (static_cast<int>(used_.size()) >= opt_.max_points || basis_.q >= max_order_)
      return Status::Error(fmt::format(
          "reduced model: error {:.2g} at {:.4g} Hz after {} expansion points (order {}), over "
          "the {:.2g} allowed",
          model_.stats.error, model_.stats.error_frequency, used_.size(), basis_.q, opt_.tol));
    if (Status s = expand_where_worst(); !s.ok()) return s;
  }
  model_.stats.factorizations = st_.factorizations;
  model_.stats.check_points = static_cast<int>(freqs_.size());
  model_.stats.expansion_points = st_.expansion_points;
  model_.stats.steps = st_.steps;
  model_.stats.points = used_;
  model_.stats.tol = tol_;
  model_.stats.relaxed = relaxed_;
  return model_;
}

// One search in one sign form.
StatusOr<ReducedModel> reduce_in_form(const Circuit& circuit,
                                      const std::vector<std::vector<double>>& excitations,
                                      const std::vector<std::vector<double>>& dc_solutions,
                                      const std::vector<Probe>& probes,
                                      const ReducedModelOptions& opt, bool passive_form) {
  StatusOr<AcAnalysis> ac = AcAnalysis::create(circuit);
  if (!ac) return ac.status();
  Reducer reducer(circuit, *ac, excitations, dc_solutions, probes, opt, passive_form);
  return reducer.run();
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
