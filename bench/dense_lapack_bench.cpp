// The reduced model's dense algebra (solver/dense_lapack.h, LAPACK and BLAS from OpenBLAS on one
// thread) against Eigen's at the orders a long link's model reaches (600-970), on matrices shaped
// like the model's: m = (G + sigma C)^-1 C of a random pencil, C of rank 3/4 of the order.
//   - BM_EigenSolver / BM_ModalSplit: the modal form's eigen-decomposition (Eigen: eigenvalues,
//     eigenvectors, and the LU of the eigenvectors the inputs need; LAPACK: modal_split whole);
//   - BM_EigenHessenberg / BM_DenseHessenberg: the Hessenberg form of each intermediate model,
//     Q applied to the ports' rows and columns;
//   - BM_EigenProduct / BM_DenseMultiply: one pass of an expansion point's 96 Krylov vectors
//     against a basis of 600 (h = V' x, x -= V h; 1,975 unknowns, the 28 m link).
// Run from the repository root: build/bench/dense_lapack_bench
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <random>

#include "solver/dense_lapack.h"

namespace {

using namespace isolink;

Eigen::MatrixXd random_matrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = n01(rng);
  return m;
}

Eigen::MatrixXd shift_inverted(int q) {
  const int rank = 3 * q / 4;
  const Eigen::MatrixXd g =
      random_matrix(q, q, 1) + 3.0 * std::sqrt(q) * Eigen::MatrixXd::Identity(q, q);
  const Eigen::MatrixXd f = random_matrix(rank, rank, 2);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(q, q);
  c.topLeftCorner(rank, rank) = 1e-9 * f * f.transpose();
  return (g + 1e6 * c).partialPivLu().solve(c);
}

void BM_EigenSolver(benchmark::State& state) {
  const int q = static_cast<int>(state.range(0));
  const Eigen::MatrixXd m = shift_inverted(q), b = random_matrix(q, 16, 3);
  for (auto _ : state) {
    Eigen::EigenSolver<Eigen::MatrixXd> es(m);
    const Eigen::MatrixXcd d =
        es.eigenvectors().partialPivLu().solve(b.cast<std::complex<double>>());
    benchmark::DoNotOptimize(d.data());
  }
}

void BM_ModalSplit(benchmark::State& state) {
  const int q = static_cast<int>(state.range(0));
  const Eigen::MatrixXd m = shift_inverted(q), b = random_matrix(q, 16, 3),
                        l = random_matrix(15, q, 4);
  for (auto _ : state) {
    StatusOr<ModalSplit> split = modal_split(m, b, l, 1e-14, 0.0);
    if (!split) state.SkipWithError(split.status().message().c_str());
    benchmark::DoNotOptimize(split->inputs.data());
  }
}

void BM_EigenHessenberg(benchmark::State& state) {
  const int q = static_cast<int>(state.range(0));
  const Eigen::MatrixXd m = shift_inverted(q), b = random_matrix(q, 16, 3),
                        l = random_matrix(15, q, 4);
  for (auto _ : state) {
    Eigen::HessenbergDecomposition<Eigen::MatrixXd> hd(m);
    const Eigen::MatrixXd h = hd.matrixH();
    const Eigen::MatrixXd lq = l * hd.matrixQ();
    const Eigen::MatrixXd qb = hd.matrixQ().adjoint() * b;
    benchmark::DoNotOptimize(qb.data());
  }
}

void BM_DenseHessenberg(benchmark::State& state) {
  const int q = static_cast<int>(state.range(0));
  const Eigen::MatrixXd m = shift_inverted(q), b = random_matrix(q, 16, 3),
                        l = random_matrix(15, q, 4);
  for (auto _ : state) {
    StatusOr<DenseHessenberg> hd = dense_hessenberg(m);
    Eigen::MatrixXd lq = l, qb = b;
    hd->apply_q(&lq);
    hd->apply_q_transposed(&qb);
    benchmark::DoNotOptimize(qb.data());
  }
}

void BM_EigenProduct(benchmark::State& state) {
  const Eigen::MatrixXd v = random_matrix(1975, 600, 5);
  Eigen::MatrixXd x = random_matrix(1975, 96, 6);
  for (auto _ : state) {
    const Eigen::MatrixXd h = v.transpose() * x;
    x.noalias() -= v * h;
    benchmark::DoNotOptimize(x.data());
  }
}

void BM_DenseMultiply(benchmark::State& state) {
  const Eigen::MatrixXd v = random_matrix(1975, 600, 5);
  Eigen::MatrixXd x = random_matrix(1975, 96, 6), h(600, 96);
  for (auto _ : state) {
    dense_multiply(true, 1.0, v, x, 0.0, h);
    dense_multiply(false, -1.0, v, h, 1.0, x);
    benchmark::DoNotOptimize(x.data());
  }
}

BENCHMARK(BM_EigenSolver)->Arg(667)->Arg(970)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ModalSplit)->Arg(667)->Arg(970)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EigenHessenberg)->Arg(667)->Arg(970)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DenseHessenberg)->Arg(667)->Arg(970)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EigenProduct)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DenseMultiply)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
