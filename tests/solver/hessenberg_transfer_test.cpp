// The Hessenberg frequency response (solver/hessenberg_transfer.h) against a dense LU solve of
// L (G + s C)^-1 B at the same frequencies: both of its paths (by probes, by sources), a
// singular C, and the errors it reports.
#include "solver/hessenberg_transfer.h"

#include <gtest/gtest.h>

#include <array>
#include <complex>
#include <random>
#include <thread>
#include <vector>

namespace isolink {
namespace {

using Cplx = std::complex<double>;

struct System {
  Eigen::MatrixXd g, c, b, l;
};

// A random stable-ish pencil: G with a dominant positive diagonal, C symmetric positive
// semi-definite of rank `c_rank` (rank < q: instantaneous modes, as a reduced circuit has).
System random_system(int q, int nk, int np, int c_rank, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  auto random = [&](int r, int c) {
    Eigen::MatrixXd m(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) m(i, j) = n01(rng);
    return m;
  };
  System s;
  s.g = random(q, q) + 3.0 * std::sqrt(q) * Eigen::MatrixXd::Identity(q, q);
  const Eigen::MatrixXd f = random(q, c_rank);
  s.c = 1e-9 * f * f.transpose();
  s.b = random(q, nk);
  s.l = random(np, q);
  return s;
}

// The worst |H_hess - H_dense| / max |H_dense| over 40 frequencies from 1 kHz to 10 GHz.
double worst_relative_error(const System& s, double sigma) {
  HessenbergTransfer h;
  EXPECT_TRUE(h.set(s.g, s.c, s.b, s.l, sigma).ok());
  double worst = 0;
  for (int i = 0; i < 40; ++i) {
    const Cplx jw(0, 2 * 3.141592653589793 * 1e3 * std::pow(1e7, i / 39.0));
    const Eigen::MatrixXcd a = s.g.cast<Cplx>() + jw * s.c.cast<Cplx>();
    const Eigen::MatrixXcd exact =
        (s.l.cast<Cplx>() * a.partialPivLu().solve(s.b.cast<Cplx>())).transpose();  // nk x np
    const Eigen::MatrixXcd got = h.at(jw);
    EXPECT_EQ(got.rows(), s.b.cols());
    EXPECT_EQ(got.cols(), s.l.rows());
    worst = std::max(worst, (got - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff());
  }
  return worst;
}

TEST(HessenbergTransfer, FewerProbesThanSourcesMatchesTheDenseSolve) {
  // One probe, two sources: the transposed path (by probes).
  for (unsigned seed = 1; seed <= 5; ++seed)
    EXPECT_LT(worst_relative_error(random_system(60, 2, 1, 60, seed), 2e6), 1e-10) << seed;
}

TEST(HessenbergTransfer, FewerSourcesThanProbesMatchesTheDenseSolve) {
  // Three probes, one source: the direct path (by sources).
  for (unsigned seed = 1; seed <= 5; ++seed)
    EXPECT_LT(worst_relative_error(random_system(60, 1, 3, 60, seed), 2e6), 1e-10) << seed;
}

TEST(HessenbergTransfer, SingularCapacitanceMatrixIsFine) {
  // C of rank 20 in 50 unknowns: 30 instantaneous modes (M's eigenvalue 0), both paths.
  EXPECT_LT(worst_relative_error(random_system(50, 2, 1, 20, 7), 1e5), 1e-10);
  EXPECT_LT(worst_relative_error(random_system(50, 1, 2, 20, 8), 1e5), 1e-10);
}

TEST(HessenbergTransfer, OneByOneIsTheClosedForm) {
  // q = 1: H(s) = l b / (g + s c).
  HessenbergTransfer h;
  ASSERT_TRUE(h.set(Eigen::MatrixXd::Constant(1, 1, 2.0), Eigen::MatrixXd::Constant(1, 1, 1e-6),
                    Eigen::MatrixXd::Constant(1, 1, 3.0), Eigen::MatrixXd::Constant(1, 1, 0.5), 1e5)
                  .ok());
  const Cplx s(0, 1e6);
  EXPECT_NEAR(std::abs(h.at(s)(0, 0) - 1.5 / (2.0 + s * 1e-6)), 0.0, 1e-14);
}

TEST(HessenbergTransfer, EmptySystemIsZeroAndSingularShiftIsAnError) {
  HessenbergTransfer h;
  ASSERT_TRUE(h.set(Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 2),
                    Eigen::MatrixXd(1, 0), 1.0)
                  .ok());
  const Eigen::MatrixXcd z = h.at({0, 1e6});
  ASSERT_EQ(z.rows(), 2);
  ASSERT_EQ(z.cols(), 1);
  EXPECT_EQ(z.cwiseAbs().maxCoeff(), 0.0);
  // G + sigma C singular: G = -sigma C.
  const Eigen::MatrixXd c = Eigen::MatrixXd::Identity(3, 3);
  const Status s =
      h.set(-2.0 * c, c, Eigen::MatrixXd::Ones(3, 1), Eigen::MatrixXd::Ones(1, 3), 2.0);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("singular"), std::string::npos) << s.message();
}

TEST(HessenbergTransfer, AtFromTwoThreadsAtOnceGivesTheOneThreadAnswer) {
  // The reduced model's check measures its frequencies on every core through one transfer: each
  // thread must have its own work arrays. Both paths; each thread walks the frequencies in its
  // own order, so that calls of different sizes of work overlap.
  for (const System& sys : {random_system(80, 3, 1, 80, 11), random_system(80, 1, 3, 80, 12)}) {
    HessenbergTransfer h;
    ASSERT_TRUE(h.set(sys.g, sys.c, sys.b, sys.l, 1e6).ok());
    constexpr int kFreqs = 400;
    auto jw = [](int i) { return Cplx(0, 2 * 3.141592653589793 * 1e3 * std::pow(1e7, i / 399.0)); };
    std::vector<Eigen::MatrixXcd> serial(kFreqs);
    for (int i = 0; i < kFreqs; ++i) serial[i] = h.at(jw(i));
    std::array<std::vector<Eigen::MatrixXcd>, 2> threaded;
    std::array<std::thread, 2> threads;
    for (int t = 0; t < 2; ++t)
      threads[t] = std::thread([&, t] {
        threaded[t].resize(kFreqs);
        for (int k = 0; k < kFreqs; ++k) {
          const int i = t == 0 ? k : kFreqs - 1 - k;
          threaded[t][i] = h.at(jw(i));
        }
      });
    for (std::thread& th : threads) th.join();
    for (int t = 0; t < 2; ++t)
      for (int i = 0; i < kFreqs; ++i)
        ASSERT_EQ((threaded[t][i] - serial[i]).cwiseAbs().maxCoeff(), 0.0) << t << " " << i;
  }
}

}  // namespace
}  // namespace isolink
