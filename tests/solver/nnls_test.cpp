// Non-negative least squares (solver/nnls.h): a hand-worked case, and on seeded random problems
// the Karush-Kuhn-Tucker conditions for both forms (the tall matrix and its normal equations),
// which must agree.
#include "solver/nnls.h"

#include <gtest/gtest.h>

#include <random>

namespace isolink {
namespace {

// min |x - b| over x >= 0 is b with its negative entries set to zero.
TEST(Nnls, IdentityClipsTheNegativeEntries) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::Vector3d b(1.5, -2, 0.25);
  const Eigen::Vector3d want(1.5, 0, 0.25);
  EXPECT_LT((nnls(a, b) - want).norm(), 1e-14);
  EXPECT_LT((nnls_gram(a, b) - want).norm(), 1e-12);  // its ridge of 1e-13
}

// KKT at x: x >= 0, the gradient a^T (a x - b) >= 0, and zero where x > 0.
void expect_kkt(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
  const Eigen::VectorXd g = a.transpose() * (a * x - b);
  const double tol = 1e-9 * (a.norm() * b.norm() + 1);
  for (int j = 0; j < x.size(); ++j) {
    EXPECT_GE(x[j], 0);
    EXPECT_GE(g[j], -tol) << j;
    if (x[j] > 0) {
      EXPECT_NEAR(g[j], 0, tol) << j;
    }
  }
}

TEST(Nnls, SeededRandomProblemsMeetKktInBothForms) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  std::uniform_int_distribution<int> size(2, 40);
  int some_bound = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const int rows = size(rng) + 40, cols = size(rng);
    Eigen::MatrixXd a(rows, cols);
    Eigen::VectorXd b(rows);
    for (int i = 0; i < rows; ++i) {
      b[i] = n(rng);
      for (int j = 0; j < cols; ++j) a(i, j) = n(rng) * (1 + j);  // columns of unequal scale
    }
    const Eigen::VectorXd x = nnls(a, b);
    const Eigen::VectorXd y = nnls_gram(a.transpose() * a, a.transpose() * b);
    expect_kkt(a, b, x);
    expect_kkt(a, b, y);
    EXPECT_LT((x - y).norm(), 1e-8 * (1 + x.norm())) << trial;
    some_bound += (x.array() == 0).any() && (x.array() > 0).any();
  }
  EXPECT_GT(some_bound, 25);  // most problems have both bound and free unknowns
}

}  // namespace
}  // namespace isolink
