// Dense linear algebra through LAPACK and BLAS (Debian's OpenBLAS build, which carries both): the
// reduced model's modal form and basis (solver/reduced_model.cpp) and the Hessenberg transfer of
// its intermediate models (solver/hessenberg_transfer.cpp).
//
// Why not Eigen's EigenSolver / HessenbergDecomposition / products: LAPACK reduces to Hessenberg
// form in blocks (dgehrd: most of the work as matrix products) and finds the Schur form with
// multishift QR and aggressive early deflation (dhseqr); Eigen does both a reflection at a time
// and with the double-shift QR. And OpenBLAS picks its kernels for the machine it runs on (AVX-512
// or AVX2 with FMA), where Eigen's products are compiled for the x86-64 baseline (SSE2). On one
// core of the development machine (bench/dense_lapack_bench, bench/README.md "Dense linear
// algebra"), on matrices shaped like a long link's model: the modal form (eigen-decomposition and
// the inputs' solve) at order 667 in 98 ms against Eigen's 468, at order 970 in 273 against
// 1,465; the Hessenberg form at order 667 in 29 ms against 75, at 970 in 79 against 218; one
// pass of 96 Krylov vectors against a basis of 600 in 7.7 ms against 19.6: 2.5-5.4x.
//
// Threads: OpenBLAS runs on one thread here (set once, at the first call, for the whole process):
// the callers already run on every core (a sweep's points, the basis's column slices, the check's
// frequencies), OpenBLAS's own threads spin for a while after each call (taking a core from the
// callers' threads on a small machine), and one thread gives the same rounding whatever the
// machine's core count. A Python process whose numpy loads the same OpenBLAS shares the setting.
// Every function is safe to call from several threads at once.
//
//   StatusOr<ModalSplit> e = modal_split(m, b, l, 1e-14, 0);   // l (I + z m)^-1 b by modes
//   StatusOr<DenseHessenberg> h = dense_hessenberg(m);
//   h->apply_q(&x);                               // x Q
//   h->apply_q_transposed(&y);                    // Q' y
//   StatusOr<Eigen::MatrixXd> x = dense_solve(a, b);   // a^-1 b
//   dense_multiply(true, -1.0, a, b, 1.0, c);     // c <- c - a' b
#pragma once

#include <Eigen/Dense>
#include <complex>

#include "base/status.h"

namespace isolink {

// OpenBLAS on one thread from here on and its idle worker threads stopped, which otherwise spin
// for their first 0.1 s, taking a core from the program's own threads. For a program, first
// thing in main(), while no other thread uses BLAS (not from a module loaded into someone else's
// process: Python's numpy may be using those threads).
void stop_blas_worker_threads();

// The transfer l (I + z m)^-1 b of a real q x q matrix m split by m's eigenvalues: the modes
// (eigenvalues over bound = max(relative x the largest |eigenvalue|, absolute) in magnitude), each
// a term outputs.col(i) inputs.row(i) / (1 + z values[i]), and the rest (eigenvalues of at most
// `bound`), l P b with P the projector on their invariant subspace along the modes': what those add
// where |z| bound is small.
//
// Method: the real Schur form m = Z S Z' (dgees; dhseqr for a Hessenberg m), the rest's eigenvalues
// moved to its leading block (dtrsen), the two blocks decoupled by the Sylvester equation S11 X - X
// S22 = -S12 (dtrsyl), and the eigenvectors of the modes' block alone (dtrevc3). A cluster of equal
// eigenvalues has no well-conditioned eigenvectors (LAPACK's come out parallel: on a 3-unknown
// RC with a probe on the source's current, the two zero eigenvalues' vectors agreed to 1e-266 and
// the model was 1 off), so the rest, where such clusters sit (a singular C: nodes without
// capacitance), needs none: only its invariant subspace, which is well-conditioned while its
// eigenvalues are apart from the modes'.
struct ModalSplit {
  // The modes' eigenvalues of m: a complex pair at neighbouring positions, the one with positive
  // imaginary part first, their columns of `outputs` exact conjugates (their rows of `inputs`
  // conjugates within rounding).
  Eigen::VectorXcd values;
  Eigen::MatrixXcd inputs;   // modes x cols(b): V^-1 b, V the modes' eigenvectors
  Eigen::MatrixXcd outputs;  // rows(l) x modes: l V
  Eigen::MatrixXd rest;      // rows(l) x cols(b): l P b
  int rest_count = 0;        // eigenvalues in the rest
};

// Error: m not square or not finite, the sizes not agreeing, the QR iteration not converging, the
// reordering failing (eigenvalues too close to swap) or the modes' eigenvectors singular.
// m's shape: General, or Hessenberg (its entries under the subdiagonal taken as zero; the Schur
// form then starts from m itself: no second reduction, a fifth of the work at order 970).
enum class MatrixShape { General, Hessenberg };
StatusOr<ModalSplit> modal_split(const Eigen::MatrixXd& m, const Eigen::MatrixXd& b,
                                 const Eigen::MatrixXd& l, double relative, double absolute,
                                 MatrixShape shape = MatrixShape::General);

// m = Q H Q' with H upper Hessenberg and Q orthogonal, Q kept as LAPACK's reflections.
class DenseHessenberg {
 public:
  const Eigen::MatrixXd& h() const { return h_; }
  // x <- x Q (x has q columns) and y <- Q' y (y has q rows).
  void apply_q(Eigen::MatrixXd* x) const;
  void apply_q_transposed(Eigen::MatrixXd* y) const;

 private:
  friend StatusOr<DenseHessenberg> dense_hessenberg(const Eigen::MatrixXd& m);
  Eigen::MatrixXd h_;           // upper Hessenberg
  Eigen::MatrixXd reflectors_;  // dgehrd's output: the reflections below the subdiagonal
  Eigen::VectorXd tau_;
};

// Error: m not square or not finite.
StatusOr<DenseHessenberg> dense_hessenberg(const Eigen::MatrixXd& m);

// x = a^-1 b by LU with partial pivoting (LAPACK dgesv, zgesv). Error: a not square, the sizes
// not agreeing, or an exact zero pivot (a singular); a nearly singular a gives a large x.
StatusOr<Eigen::MatrixXd> dense_solve(Eigen::MatrixXd a, Eigen::MatrixXd b);
StatusOr<Eigen::MatrixXcd> dense_solve(Eigen::MatrixXcd a, Eigen::MatrixXcd b);

// c <- alpha op(a) b + beta c, op(a) = a' when transpose_a, else a (BLAS dgemm). The sizes must
// agree (op(a): rows(c) x k, b: k x cols(c)); c must not overlap a or b.
void dense_multiply(bool transpose_a, double alpha, const Eigen::Ref<const Eigen::MatrixXd>& a,
                    const Eigen::Ref<const Eigen::MatrixXd>& b, double beta,
                    Eigen::Ref<Eigen::MatrixXd> c);
// The same for complex matrices (BLAS zgemm; op(a) = a', not conjugated, when transpose_a).
void dense_multiply(bool transpose_a, std::complex<double> alpha,
                    const Eigen::Ref<const Eigen::MatrixXcd>& a,
                    const Eigen::Ref<const Eigen::MatrixXcd>& b, std::complex<double> beta,
                    Eigen::Ref<Eigen::MatrixXcd> c);

}  // namespace isolink
