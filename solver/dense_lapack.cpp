#include "solver/dense_lapack.h"

#include <dlfcn.h>

#include <algorithm>
#include <cassert>
#include <complex>
#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

// LAPACK's and BLAS's Fortran entry points (OpenBLAS carries them; Debian ships no LAPACKE for
// it). Each character argument has its length passed after the others, as gfortran compiles them.
extern "C" {
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
            const double* beta, double* c, const int* ldc, std::size_t transa_len,
            std::size_t transb_len);
void zgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const std::complex<double>* alpha, const std::complex<double>* a, const int* lda,
            const std::complex<double>* b, const int* ldb, const std::complex<double>* beta,
            std::complex<double>* c, const int* ldc, std::size_t transa_len,
            std::size_t transb_len);
void dgees_(const char* jobvs, const char* sort, void* select, const int* n, double* a,
            const int* lda, int* sdim, double* wr, double* wi, double* vs, const int* ldvs,
            double* work, const int* lwork, int* bwork, int* info, std::size_t jobvs_len,
            std::size_t sort_len);
void dtrsen_(const char* job, const char* compq, const int* select, const int* n, double* t,
             const int* ldt, double* q, const int* ldq, double* wr, double* wi, int* m, double* s,
             double* sep, double* work, const int* lwork, int* iwork, const int* liwork, int* info,
             std::size_t job_len, std::size_t compq_len);
void dtrsyl_(const char* trana, const char* tranb, const int* isgn, const int* m, const int* n,
             const double* a, const int* lda, const double* b, const int* ldb, double* c,
             const int* ldc, double* scale, int* info, std::size_t trana_len,
             std::size_t tranb_len);
void dtrevc3_(const char* side, const char* howmny, int* select, const int* n, const double* t,
              const int* ldt, double* vl, const int* ldvl, double* vr, const int* ldvr,
              const int* mm, int* m, double* work, const int* lwork, int* info,
              std::size_t side_len, std::size_t howmny_len);
void dhseqr_(const char* job, const char* compz, const int* n, const int* ilo, const int* ihi,
             double* h, const int* ldh, double* wr, double* wi, double* z, const int* ldz,
             double* work, const int* lwork, int* info, std::size_t job_len, std::size_t compz_len);
void dgehrd_(const int* n, const int* ilo, const int* ihi, double* a, const int* lda, double* tau,
             double* work, const int* lwork, int* info);
void dormhr_(const char* side, const char* trans, const int* m, const int* n, const int* ilo,
             const int* ihi, const double* a, const int* lda, const double* tau, double* c,
             const int* ldc, double* work, const int* lwork, int* info, std::size_t side_len,
             std::size_t trans_len);
void dgesv_(const int* n, const int* nrhs, double* a, const int* lda, int* ipiv, double* b,
            const int* ldb, int* info);
void zgesv_(const int* n, const int* nrhs, std::complex<double>* a, const int* lda, int* ipiv,
            std::complex<double>* b, const int* ldb, int* info);
void openblas_set_num_threads(int threads);
}

namespace isolink {

namespace {

// OpenBLAS on one thread (the header says why), once per process.
void one_blas_thread() {
  static std::once_flag once;
  std::call_once(once, [] { openblas_set_num_threads(1); });
}

}  // namespace

void stop_blas_worker_threads() {
  one_blas_thread();
  // The worker threads OpenBLAS started when it loaded spin (sched_yield) for 2^28 cycles, about
  // 0.1 s, before they sleep; stopped here they give that core back to the program's own threads
  // (the port model's two runs: 1-2 % of a 5 m link's wall time on two cores). Looked up, not
  // linked: OpenBLAS's serial build has no thread server to stop.
  using Shutdown = int (*)();
  if (auto stop = reinterpret_cast<Shutdown>(dlsym(RTLD_DEFAULT, "blas_thread_shutdown_"))) stop();
}

namespace {

Status check_square(const Eigen::MatrixXd& m, const char* what) {
  if (m.rows() != m.cols()) return Status::Error(std::string(what) + ": the matrix is not square");
  if (!m.allFinite()) return Status::Error(std::string(what) + ": the matrix is not finite");
  return Status::Ok();
}

// The real Schur form m = z s z' (dgees) with eigenvalues wr + i wi.
struct Schur {
  Eigen::MatrixXd s, z;
  Eigen::VectorXd wr, wi;
};

StatusOr<Schur> real_schur(const Eigen::MatrixXd& m) {
  const int n = static_cast<int>(m.rows());
  Schur f{m, Eigen::MatrixXd(n, n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  int sdim = 0, lwork = -1, info = 0;
  double size = 0;
  dgees_("V", "N", nullptr, &n, f.s.data(), &n, &sdim, f.wr.data(), f.wi.data(), f.z.data(), &n,
         &size, &lwork, nullptr, &info, 1, 1);
  std::vector<double> work(static_cast<std::size_t>(std::max(static_cast<int>(size), 3 * n)));
  lwork = static_cast<int>(work.size());
  dgees_("V", "N", nullptr, &n, f.s.data(), &n, &sdim, f.wr.data(), f.wi.data(), f.z.data(), &n,
         work.data(), &lwork, nullptr, &info, 1, 1);
  if (info != 0)
    return Status::Error("eigen-decomposition: the QR iteration did not converge (LAPACK dgees " +
                         std::to_string(info) + ")");
  return f;
}

// The real Schur form of an upper Hessenberg h (dhseqr alone: dgees would reduce it again).
StatusOr<Schur> hessenberg_schur(const Eigen::MatrixXd& h) {
  const int n = static_cast<int>(h.rows()), ilo = 1;
  Schur f{h, Eigen::MatrixXd(n, n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  f.s.triangularView<Eigen::StrictlyLower>().setZero();
  for (int j = 0; j + 1 < n; ++j) f.s(j + 1, j) = h(j + 1, j);
  int lwork = -1, info = 0;
  double size = 0;
  dhseqr_("S", "I", &n, &ilo, &n, f.s.data(), &n, f.wr.data(), f.wi.data(), f.z.data(), &n, &size,
          &lwork, &info, 1, 1);
  std::vector<double> work(static_cast<std::size_t>(std::max(static_cast<int>(size), n)));
  lwork = static_cast<int>(work.size());
  dhseqr_("S", "I", &n, &ilo, &n, f.s.data(), &n, f.wr.data(), f.wi.data(), f.z.data(), &n,
          work.data(), &lwork, &info, 1, 1);
  if (info != 0)
    return Status::Error("eigen-decomposition: the QR iteration did not converge (LAPACK dhseqr " +
                         std::to_string(info) + ")");
  return f;
}

// The eigenvectors of the quasi-triangular n x n block at t (leading dimension ldt), as complex
// columns (dtrevc3's real and imaginary column pairs joined).
StatusOr<Eigen::MatrixXcd> block_eigenvectors(const double* t, int n, int ldt,
                                              const Eigen::VectorXd& wi, int from) {
  Eigen::MatrixXd vr(n, n);
  double vl = 0, size = 0;
  int one = 1, used = 0, lwork = -1, info = 0;
  dtrevc3_("R", "A", nullptr, &n, t, &ldt, &vl, &one, vr.data(), &n, &n, &used, &size, &lwork,
           &info, 1, 1);
  std::vector<double> work(static_cast<std::size_t>(std::max(static_cast<int>(size), 3 * n)));
  lwork = static_cast<int>(work.size());
  dtrevc3_("R", "A", nullptr, &n, t, &ldt, &vl, &one, vr.data(), &n, &n, &used, work.data(), &lwork,
           &info, 1, 1);
  if (info != 0) return Status::Error("eigen-decomposition: LAPACK dtrevc3 failed");
  Eigen::MatrixXcd v(n, n);
  for (int j = 0; j < n; ++j) {
    if (wi[from + j] == 0 || j + 1 == n) {
      v.col(j) = vr.col(j).cast<std::complex<double>>();
      continue;
    }
    // A pair: columns j and j + 1 are the real and imaginary parts of the first one's vector.
    for (int i = 0; i < n; ++i) {
      v(i, j) = {vr(i, j), vr(i, j + 1)};
      v(i, j + 1) = {vr(i, j), -vr(i, j + 1)};
    }
    ++j;
  }
  return v;
}

// Moves the eigenvalues `chosen` marks to the leading block of f (dtrsen).
Status reorder(Schur* f, const std::vector<int>& chosen) {
  const int n = static_cast<int>(f->s.rows());
  int m = 0, info = 0, liwork = 1, iwork = 0;
  double s = 0, sep = 0;
  std::vector<double> work(static_cast<std::size_t>(std::max(n, 1)));
  const int lwork = static_cast<int>(work.size());
  dtrsen_("N", "V", chosen.data(), &n, f->s.data(), &n, f->z.data(), &n, f->wr.data(), f->wi.data(),
          &m, &s, &sep, work.data(), &lwork, &iwork, &liwork, &info, 1, 1);
  if (info != 0)
    return Status::Error("eigen-decomposition: the eigenvalues are too close to reorder");
  return Status::Ok();
}

}  // namespace

StatusOr<ModalSplit> modal_split(const Eigen::MatrixXd& m, const Eigen::MatrixXd& b,
                                 const Eigen::MatrixXd& l, double relative, double absolute,
                                 MatrixShape shape) {
  if (Status s = check_square(m, "eigen-decomposition"); !s.ok()) return s;
  if (b.rows() != m.rows() || l.cols() != m.rows())
    return Status::Error("eigen-decomposition: the sizes do not agree");
  one_blas_thread();
  const int q = static_cast<int>(m.rows());
  ModalSplit out;
  out.rest.setZero(l.rows(), b.cols());
  if (q == 0) return out;
  StatusOr<Schur> f = shape == MatrixShape::Hessenberg ? hessenberg_schur(m) : real_schur(m);
  if (!f) return f.status();
  double largest = 0;
  for (int j = 0; j < q; ++j)
    largest = std::max(largest, std::abs(std::complex<double>(f->wr[j], f->wi[j])));
  const double bound = std::max(relative * largest, absolute);
  std::vector<int> chosen(static_cast<std::size_t>(q));
  for (int j = 0; j < q; ++j) {
    chosen[j] = std::abs(std::complex<double>(f->wr[j], f->wi[j])) <= bound;
    out.rest_count += chosen[j];
  }
  const int k0 = out.rest_count, q2 = q - k0;
  if (k0 > 0 && q2 > 0)
    if (Status s = reorder(&*f, chosen); !s.ok()) return s;
  // Decoupled: m = Z Y diag(S11, S22) Y^-1 Z' with Y = [I X; 0 I], S11 X - X S22 = -S12.
  Eigen::MatrixXd x = -f->s.topRightCorner(k0, q2);
  if (k0 > 0 && q2 > 0) {
    const int isgn = -1;
    double scale = 1;
    int info = 0;
    dtrsyl_("N", "N", &isgn, &k0, &q2, f->s.data(), &q, f->s.data() + (std::size_t(k0) * q + k0),
            &q, x.data(), &k0, &scale, &info, 1, 1);
    if (info < 0 || !(scale > 0)) return Status::Error("eigen-decomposition: LAPACK dtrsyl failed");
    x /= scale;
  }
  const Eigen::MatrixXd zb = f->z.transpose() * b;                         // q x nk
  const Eigen::MatrixXd lz = l * f->z;                                     // np x q
  const Eigen::MatrixXd rest_in = zb.topRows(k0) - x * zb.bottomRows(q2);  // Y^-1 Z' b, top
  out.rest = lz.leftCols(k0) * rest_in;
  out.values.resize(q2);
  for (int j = 0; j < q2; ++j) out.values[j] = {f->wr[k0 + j], f->wi[k0 + j]};
  if (q2 == 0) {
    out.inputs.resize(0, b.cols());
    out.outputs.resize(l.rows(), 0);
    return out;
  }
  StatusOr<Eigen::MatrixXcd> w =
      block_eigenvectors(f->s.data() + (std::size_t(k0) * q + k0), q2, q, f->wi, k0);
  if (!w) return w.status();
  const Eigen::MatrixXd e = lz.leftCols(k0) * x + lz.rightCols(q2);  // l Z Y, the modes' columns
  out.outputs = e.cast<std::complex<double>>() * *w;
  StatusOr<Eigen::MatrixXcd> inputs =
      dense_solve(*w, zb.bottomRows(q2).cast<std::complex<double>>());
  if (!inputs || !inputs->allFinite() || !out.outputs.allFinite())
    return Status::Error("eigen-decomposition: the eigenvectors are singular");
  out.inputs = std::move(*inputs);
  return out;
}

StatusOr<DenseHessenberg> dense_hessenberg(const Eigen::MatrixXd& m) {
  if (Status s = check_square(m, "Hessenberg reduction"); !s.ok()) return s;
  one_blas_thread();
  const int n = static_cast<int>(m.rows()), ilo = 1;
  DenseHessenberg d;
  d.reflectors_ = m;
  d.tau_.setZero(std::max(n - 1, 1));
  if (n > 1) {
    double size = 0;
    int lwork = -1, info = 0;
    dgehrd_(&n, &ilo, &n, d.reflectors_.data(), &n, d.tau_.data(), &size, &lwork, &info);
    std::vector<double> work(static_cast<std::size_t>(std::max(static_cast<int>(size), n)));
    lwork = static_cast<int>(work.size());
    dgehrd_(&n, &ilo, &n, d.reflectors_.data(), &n, d.tau_.data(), work.data(), &lwork, &info);
    if (info != 0)
      return Status::Error("Hessenberg reduction: LAPACK dgehrd " + std::to_string(info));
  }
  d.h_ = d.reflectors_.triangularView<Eigen::Upper>();
  for (int j = 0; j + 1 < n; ++j) d.h_(j + 1, j) = d.reflectors_(j + 1, j);
  return d;
}

namespace {

// dormhr with Q from `reflectors` and `tau`: C <- C Q (side R, trans N) or Q' C (L, T).
void apply_reflections(const Eigen::MatrixXd& reflectors, const Eigen::VectorXd& tau,
                       const char* side, const char* trans, Eigen::MatrixXd* c) {
  const int q = static_cast<int>(reflectors.rows());
  if (q < 2 || c->size() == 0) return;
  const int rows = static_cast<int>(c->rows()), cols = static_cast<int>(c->cols()), ilo = 1;
  double size = 0;
  int lwork = -1, info = 0;
  dormhr_(side, trans, &rows, &cols, &ilo, &q, reflectors.data(), &q, tau.data(), c->data(), &rows,
          &size, &lwork, &info, 1, 1);
  std::vector<double> work(
      static_cast<std::size_t>(std::max({static_cast<int>(size), rows, cols})));
  lwork = static_cast<int>(work.size());
  dormhr_(side, trans, &rows, &cols, &ilo, &q, reflectors.data(), &q, tau.data(), c->data(), &rows,
          work.data(), &lwork, &info, 1, 1);
  assert(info == 0);  // only an argument error, which the sizes above rule out
}

}  // namespace

void DenseHessenberg::apply_q(Eigen::MatrixXd* x) const {
  apply_reflections(reflectors_, tau_, "R", "N", x);
}

void DenseHessenberg::apply_q_transposed(Eigen::MatrixXd* y) const {
  apply_reflections(reflectors_, tau_, "L", "T", y);
}

namespace {

// dgemm or zgemm on Eigen's column-major blocks (their outer strides as leading dimensions).
template <typename Scalar, typename Gemm>
void multiply_with(Gemm gemm, bool transpose_a, Scalar alpha, const Scalar* a, Eigen::Index lda,
                   const Scalar* b, Eigen::Index ldb, Scalar beta, Scalar* c, Eigen::Index ldc,
                   int m, int n, int k) {
  if (m == 0 || n == 0) return;
  one_blas_thread();
  const int la = static_cast<int>(std::max<Eigen::Index>(1, lda)),
            lb = static_cast<int>(std::max<Eigen::Index>(1, ldb)),
            lc = static_cast<int>(std::max<Eigen::Index>(1, ldc));
  gemm(transpose_a ? "T" : "N", "N", &m, &n, &k, &alpha, a, &la, b, &lb, &beta, c, &lc, 1, 1);
}

}  // namespace

void dense_multiply(bool transpose_a, double alpha, const Eigen::Ref<const Eigen::MatrixXd>& a,
                    const Eigen::Ref<const Eigen::MatrixXd>& b, double beta,
                    Eigen::Ref<Eigen::MatrixXd> c) {
  assert((transpose_a ? a.cols() : a.rows()) == c.rows() &&
         (transpose_a ? a.rows() : a.cols()) == b.rows() && b.cols() == c.cols());
  multiply_with<double>(dgemm_, transpose_a, alpha, a.data(), a.outerStride(), b.data(),
                        b.outerStride(), beta, c.data(), c.outerStride(),
                        static_cast<int>(c.rows()), static_cast<int>(c.cols()),
                        static_cast<int>(b.rows()));
}

void dense_multiply(bool transpose_a, std::complex<double> alpha,
                    const Eigen::Ref<const Eigen::MatrixXcd>& a,
                    const Eigen::Ref<const Eigen::MatrixXcd>& b, std::complex<double> beta,
                    Eigen::Ref<Eigen::MatrixXcd> c) {
  assert((transpose_a ? a.cols() : a.rows()) == c.rows() &&
         (transpose_a ? a.rows() : a.cols()) == b.rows() && b.cols() == c.cols());
  multiply_with<std::complex<double>>(zgemm_, transpose_a, alpha, a.data(), a.outerStride(),
                                      b.data(), b.outerStride(), beta, c.data(), c.outerStride(),
                                      static_cast<int>(c.rows()), static_cast<int>(c.cols()),
                                      static_cast<int>(b.rows()));
}

namespace {

// dgesv or zgesv on a and b (overwritten: b becomes x).
template <typename Matrix, typename Gesv>
StatusOr<Matrix> solve_with(Gesv gesv, Matrix a, Matrix b) {
  if (a.rows() != a.cols() || b.rows() != a.rows())
    return Status::Error("dense solve: the sizes do not agree");
  const int n = static_cast<int>(a.rows()), nrhs = static_cast<int>(b.cols());
  if (n == 0 || nrhs == 0) return b;
  one_blas_thread();
  std::vector<int> pivots(static_cast<std::size_t>(n));
  int info = 0;
  gesv(&n, &nrhs, a.data(), &n, pivots.data(), b.data(), &n, &info);
  if (info != 0) return Status::Error("dense solve: the matrix is singular");
  return b;
}

}  // namespace

StatusOr<Eigen::MatrixXd> dense_solve(Eigen::MatrixXd a, Eigen::MatrixXd b) {
  return solve_with<Eigen::MatrixXd>(dgesv_, std::move(a), std::move(b));
}

StatusOr<Eigen::MatrixXcd> dense_solve(Eigen::MatrixXcd a, Eigen::MatrixXcd b) {
  return solve_with<Eigen::MatrixXcd>(zgesv_, std::move(a), std::move(b));
}

}  // namespace isolink
