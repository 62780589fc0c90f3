// The dense LAPACK / BLAS layer (solver/dense_lapack.h) against Eigen's own dense algebra: the
// modal split's transfer against a dense LU solve of l (I + z m)^-1 b, with and without a cluster
// of zero eigenvalues, and from the Hessenberg form; the Hessenberg form's Q H Q' against m; the
// product on blocks; the solve.
#include "solver/dense_lapack.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <complex>
#include <filesystem>
#include <random>
#include <thread>
#include <vector>

namespace isolink {
namespace {

using Cplx = std::complex<double>;

Eigen::MatrixXd random_matrix(int rows, int cols, std::mt19937* rng) {
  std::normal_distribution<double> n01;
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = n01(*rng);
  return m;
}

// m = (G + sigma C)^-1 C as the reduced model forms it: G with a dominant diagonal, C symmetric
// positive semi-definite and non-zero on the first c_rank unknowns only (the other q - c_rank
// have no capacitance, as a circuit's nodes and branches: m's columns there are exactly 0, and
// so are q - c_rank of its eigenvalues).
Eigen::MatrixXd shift_inverted(int q, int c_rank, std::mt19937* rng) {
  const Eigen::MatrixXd g =
      random_matrix(q, q, rng) + 3.0 * std::sqrt(q) * Eigen::MatrixXd::Identity(q, q);
  const Eigen::MatrixXd f = random_matrix(c_rank, c_rank, rng);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(q, q);
  c.topLeftCorner(c_rank, c_rank) = 1e-9 * f * f.transpose();
  const double sigma = 2 * 3.141592653589793 * 1e6;
  return (g + sigma * c).partialPivLu().solve(c);
}

// The worst |split - exact| over max |exact| of l (I + z m)^-1 b at 40 values of z = j w from
// 1e3 to 1e10 (the modes summed, the rest added as a constant).
double worst_split_error(const Eigen::MatrixXd& m, const Eigen::MatrixXd& b,
                         const Eigen::MatrixXd& l, const ModalSplit& split) {
  double worst = 0;
  const int q = static_cast<int>(m.rows());
  for (int i = 0; i < 40; ++i) {
    const Cplx z(0, 2 * 3.141592653589793 * 1e3 * std::pow(1e7, i / 39.0));
    const Eigen::MatrixXcd a = Eigen::MatrixXcd::Identity(q, q) + z * m.cast<Cplx>();
    const Eigen::MatrixXcd exact = l.cast<Cplx>() * a.partialPivLu().solve(b.cast<Cplx>());
    Eigen::MatrixXcd got = split.rest.cast<Cplx>();
    for (Eigen::Index k = 0; k < split.values.size(); ++k)
      got += split.outputs.col(k) * split.inputs.row(k) / (1.0 + z * split.values[k]);
    worst = std::max(worst, (got - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff());
  }
  return worst;
}

TEST(ModalSplit, FullRankMatrixIsAllModes) {
  std::mt19937 rng(11);
  const Eigen::MatrixXd m = shift_inverted(30, 30, &rng);
  const Eigen::MatrixXd b = random_matrix(30, 3, &rng), l = random_matrix(4, 30, &rng);
  StatusOr<ModalSplit> split = modal_split(m, b, l, 1e-14, 0.0);
  ASSERT_TRUE(split.ok()) << split.status().message();
  EXPECT_EQ(split->rest_count, 0);
  EXPECT_EQ(split->values.size(), 30);
  EXPECT_EQ(split->rest.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(worst_split_error(m, b, l, *split), 1e-10);
  // Complex pairs sit side by side, the positive imaginary part first, their terms conjugate.
  for (Eigen::Index k = 0; k + 1 < split->values.size(); ++k)
    if (split->values[k].imag() > 0) {
      EXPECT_EQ(split->values[k + 1], std::conj(split->values[k]));
      EXPECT_EQ(split->outputs(0, k + 1), std::conj(split->outputs(0, k)));
      EXPECT_LT(std::abs(split->inputs(k + 1, 0) - std::conj(split->inputs(k, 0))),
                1e-12 * std::abs(split->inputs(k, 0)));
      ++k;
    }
}

// 34 zero eigenvalues of 40: their eigenvectors from LAPACK's back substitution come out nearly
// parallel, so a split by eigenvectors alone is off; the rest's invariant subspace is not.
TEST(ModalSplit, ClusterOfZeroEigenvaluesGoesToTheRestExactly) {
  std::mt19937 rng(5);
  const Eigen::MatrixXd m = shift_inverted(40, 6, &rng);
  const Eigen::MatrixXd b = random_matrix(40, 3, &rng), l = random_matrix(5, 40, &rng);
  StatusOr<ModalSplit> split = modal_split(m, b, l, 1e-14, 0.0);
  ASSERT_TRUE(split.ok()) << split.status().message();
  EXPECT_EQ(split->rest_count, 34);
  EXPECT_EQ(split->values.size(), 6);
  EXPECT_GT(split->rest.cwiseAbs().maxCoeff(), 0.1);  // what the zero eigenvalues carry
  EXPECT_LT(worst_split_error(m, b, l, *split), 1e-10);
}

// The full-order model of a 1 V source through 100 ohm into 1 nF with the source's current
// probed (the reduced model's orthonormal basis: the DC solution first, then the unit vectors):
// m = [a 0 -a; b 0 -b; -a 0 a], a double zero eigenvalue (null space e2 and e1 + e3) and 2 a.
// LAPACK's back substitution returns the zero eigenvalue's two eigenvectors parallel (agreeing
// to 1e-266), and the model split by eigenvectors alone was off by 1.
TEST(ModalSplit, DoubleZeroEigenvalueOfAnRcIsExact) {
  const double a = 2.39432e-08, b = 3.38607e-10;
  Eigen::MatrixXd m(3, 3);
  m << a, 0, -a, b, 0, -b, -a, 0, a;
  std::mt19937 rng(9);
  const Eigen::MatrixXd in = random_matrix(3, 2, &rng), out = random_matrix(2, 3, &rng);
  StatusOr<ModalSplit> split = modal_split(m, in, out, 1e-14, 0.0);
  ASSERT_TRUE(split.ok()) << split.status().message();
  EXPECT_EQ(split->rest_count, 2);
  ASSERT_EQ(split->values.size(), 1);
  EXPECT_NEAR(split->values[0].real(), 2 * a, 1e-12 * a);
  EXPECT_LT(worst_split_error(m, in, out, *split), 1e-12);
}

// The split of m's Hessenberg form H = Q' m Q with Q'b and lQ (what the reduced model's search
// holds when a model passes) is the split of m: the same transfer, the same rest. Its entries
// under the subdiagonal are garbage here (dgehrd's reflections), which the split must not read.
TEST(ModalSplit, FromTheHessenbergFormIsTheSplitOfTheMatrix) {
  for (const int c_rank : {40, 6}) {
    std::mt19937 rng(17 + c_rank);
    const Eigen::MatrixXd m = shift_inverted(40, c_rank, &rng);
    const Eigen::MatrixXd b = random_matrix(40, 3, &rng), l = random_matrix(5, 40, &rng);
    StatusOr<DenseHessenberg> h = dense_hessenberg(m);
    ASSERT_TRUE(h.ok());
    Eigen::MatrixXd qb = b, lq = l;
    h->apply_q_transposed(&qb);
    h->apply_q(&lq);
    Eigen::MatrixXd t = h->h();
    for (int j = 0; j < 40; ++j)
      for (int i = j + 2; i < 40; ++i) t(i, j) = 1e3 * (i + j);
    StatusOr<ModalSplit> split = modal_split(t, qb, lq, 1e-14, 0.0, MatrixShape::Hessenberg);
    ASSERT_TRUE(split.ok()) << split.status().message();
    EXPECT_EQ(split->rest_count, 40 - c_rank);
    EXPECT_EQ(split->values.size(), c_rank);
    EXPECT_LT(worst_split_error(m, b, l, *split), 1e-10) << "rank of C " << c_rank;
  }
}

TEST(ModalSplit, AbsoluteBoundMovesSmallEigenvaluesToTheRest) {
  std::mt19937 rng(8);
  const Eigen::MatrixXd m = shift_inverted(20, 20, &rng);
  const Eigen::MatrixXd b = random_matrix(20, 2, &rng), l = random_matrix(2, 20, &rng);
  StatusOr<ModalSplit> all = modal_split(m, b, l, 0.0, 0.0);
  ASSERT_TRUE(all.ok());
  // The bound in the first gap between |eigenvalues| from the 5th smallest on (a complex pair
  // shares its modulus): the `below` smallest go to the rest.
  std::vector<double> mags;
  for (Eigen::Index k = 0; k < all->values.size(); ++k) mags.push_back(std::abs(all->values[k]));
  std::sort(mags.begin(), mags.end());
  size_t below = 5;
  while (below < mags.size() && mags[below] <= mags[below - 1] * (1 + 1e-9)) ++below;
  ASSERT_LT(below, mags.size());
  StatusOr<ModalSplit> split = modal_split(m, b, l, 0.0, 0.5 * (mags[below - 1] + mags[below]));
  ASSERT_TRUE(split.ok()) << split.status().message();
  EXPECT_EQ(split->rest_count, static_cast<int>(below));
  // At z = 0 every term is whole: the split sums to l b at any bound.
  Eigen::MatrixXcd at0 = split->rest.cast<Cplx>();
  for (Eigen::Index k = 0; k < split->values.size(); ++k)
    at0 += split->outputs.col(k) * split->inputs.row(k);
  EXPECT_LT((at0 - (l * b).cast<Cplx>()).cwiseAbs().maxCoeff(), 1e-10 * (l * b).norm());
}

TEST(ModalSplit, RefusesWhatItCannotSplit) {
  EXPECT_FALSE(modal_split(Eigen::MatrixXd::Zero(3, 2), Eigen::MatrixXd::Zero(3, 1),
                           Eigen::MatrixXd::Zero(1, 3), 0, 0)
                   .ok());
  Eigen::MatrixXd m = Eigen::MatrixXd::Identity(3, 3);
  m(1, 1) = std::nan("");
  EXPECT_FALSE(modal_split(m, Eigen::MatrixXd::Zero(3, 1), Eigen::MatrixXd::Zero(1, 3), 0, 0).ok());
  EXPECT_FALSE(modal_split(Eigen::MatrixXd::Identity(3, 3), Eigen::MatrixXd::Zero(2, 1),
                           Eigen::MatrixXd::Zero(1, 3), 0, 0)
                   .ok());
  StatusOr<ModalSplit> empty =
      modal_split(Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 2), Eigen::MatrixXd(1, 0), 0, 0);
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->rest.rows(), 1);
  EXPECT_EQ(empty->rest.cols(), 2);
}

TEST(DenseHessenberg, QHQtIsTheMatrix) {
  std::mt19937 rng(2);
  const Eigen::MatrixXd m = random_matrix(50, 50, &rng);
  StatusOr<DenseHessenberg> h = dense_hessenberg(m);
  ASSERT_TRUE(h.ok());
  for (int j = 0; j < 50; ++j)
    for (int i = j + 2; i < 50; ++i) EXPECT_EQ(h->h()(i, j), 0.0);
  Eigen::MatrixXd q = Eigen::MatrixXd::Identity(50, 50);
  h->apply_q(&q);  // I Q
  EXPECT_LT((q.transpose() * q - Eigen::MatrixXd::Identity(50, 50)).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_LT((q * h->h() * q.transpose() - m).cwiseAbs().maxCoeff(), 1e-12 * m.norm());
  Eigen::MatrixXd y = m.leftCols(3);
  h->apply_q_transposed(&y);
  EXPECT_LT((y - q.transpose() * m.leftCols(3)).cwiseAbs().maxCoeff(), 1e-12 * m.norm());
}

TEST(DenseMultiply, MatchesEigenOnBlocksAndTransposes) {
  std::mt19937 rng(4);
  const Eigen::MatrixXd a = random_matrix(30, 20, &rng), b = random_matrix(30, 9, &rng);
  Eigen::MatrixXd c = random_matrix(25, 12, &rng);
  const Eigen::MatrixXd before = c;
  // c(2:22, 3:12) <- 2 a' b + 0.5 c(...), on blocks with their strides.
  dense_multiply(true, 2.0, a, b, 0.5, c.block(2, 3, 20, 9));
  Eigen::MatrixXd want = before;
  want.block(2, 3, 20, 9) = 2.0 * a.transpose() * b + 0.5 * before.block(2, 3, 20, 9);
  EXPECT_LT((c - want).cwiseAbs().maxCoeff(), 1e-12);
  // c(:, 0:8) <- -a(0:24, :) b(0:19, :) + c, untransposed.
  c = before;
  dense_multiply(false, -1.0, a.topRows(25), b.topRows(20), 1.0, c.leftCols(9));
  want = before;
  want.leftCols(9) -= a.topRows(25) * b.topRows(20);
  EXPECT_LT((c - want).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(DenseSolve, SolvesAndRefusesASingularMatrix) {
  std::mt19937 rng(6);
  const Eigen::MatrixXd a = random_matrix(12, 12, &rng), b = random_matrix(12, 3, &rng);
  StatusOr<Eigen::MatrixXd> x = dense_solve(a, b);
  ASSERT_TRUE(x.ok());
  EXPECT_LT((a * *x - b).cwiseAbs().maxCoeff(), 1e-10);
  const Eigen::MatrixXcd ac = a.cast<Cplx>() * Cplx(1, 2);
  StatusOr<Eigen::MatrixXcd> xc = dense_solve(ac, b.cast<Cplx>());
  ASSERT_TRUE(xc.ok());
  EXPECT_LT((ac * *xc - b.cast<Cplx>()).cwiseAbs().maxCoeff(), 1e-10);
  Eigen::MatrixXd singular = a;
  singular.row(4).setZero();
  EXPECT_FALSE(dense_solve(singular, b).ok());
  EXPECT_FALSE(dense_solve(a, b.topRows(5)).ok());
}

// The threads of this process, from /proc.
int thread_count() {
  int n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/task")) ++n;
  return n;
}

// OpenBLAS's threaded build starts one worker per further core when it loads; stopped, the
// process has fewer threads, and BLAS and LAPACK still answer (on one thread), the second stop
// harmless.
TEST(BlasThreads, StoppedWorkersLeaveBlasWorking) {
  const int before = thread_count();
  stop_blas_worker_threads();
  const int after = thread_count();
  if (std::thread::hardware_concurrency() > 1 && dlsym(RTLD_DEFAULT, "blas_thread_shutdown_"))
    EXPECT_LT(after, before);
  else
    EXPECT_EQ(after, before);
  stop_blas_worker_threads();
  EXPECT_EQ(thread_count(), after);
  std::mt19937 rng(8);
  const Eigen::MatrixXd a = random_matrix(300, 200, &rng), b = random_matrix(300, 90, &rng);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(200, 90);
  dense_multiply(true, 1.0, a, b, 0.0, c);
  EXPECT_LT((c - a.transpose() * b).cwiseAbs().maxCoeff(), 1e-11);
  const Eigen::MatrixXd m = random_matrix(40, 40, &rng);
  StatusOr<Eigen::MatrixXd> x = dense_solve(m, b.topRows(40));
  ASSERT_TRUE(x.ok());
  EXPECT_LT((m * *x - b.topRows(40)).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace isolink
