// Vector fitting against rational functions whose poles and residues are known, the S <-> Y
// conversions against a hand-worked resistor, and the passivity check and its enforcement.
#include "solver/vector_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace isolink {
namespace {

using cd = std::complex<double>;
constexpr double kTwoPi = 2 * std::numbers::pi;

// A passive 2-port: D plus a real pole and a resonant pair, residues positive semidefinite.
RationalModel known_model() {
  RationalModel m;
  m.ports = 2;
  m.d = (Eigen::MatrixXd(2, 2) << 0.02, -0.01, -0.01, 0.02).finished();
  Eigen::MatrixXcd r1(2, 2), r2(2, 2);
  r1 << 1e5, 5e4, 5e4, 1e5;  // at p = -2 pi 1 MHz
  r2 << cd(2e6, 1e5), cd(-1e6, 0), cd(-1e6, 0), cd(2e6, 1e5);
  m.poles = {cd(-kTwoPi * 1e6, 0), cd(-kTwoPi * 2e6, kTwoPi * 40e6)};
  m.residues = {r1, r2};
  return m;
}

TEST(VectorFit, RecoversKnownPolesAndResponse) {
  const RationalModel truth = known_model();
  std::vector<double> f;
  std::vector<Eigen::MatrixXcd> y;
  for (int i = 0; i < 300; ++i) {
    f.push_back(1e5 + i * (200e6 - 1e5) / 299);
    y.push_back(truth.eval(cd(0, kTwoPi * f.back())));
  }
  FitOptions o;
  o.min_order = 4;
  o.order_step = 2;
  StatusOr<FitResult> fit = vector_fit(f, y, o);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit->converged);
  EXPECT_LT(fit->rms_error, 1e-7);
  // The resonant pair is found to 1e-6 of its frequency.
  bool found = false;
  for (const cd& p : fit->model.poles)
    if (std::abs(p - truth.poles[1]) < 1e-6 * std::abs(truth.poles[1])) found = true;
  EXPECT_TRUE(found);
  // Between the samples and at DC (inside the band's rational continuation) the response holds.
  for (double x : {0.0, 3.3e6, 40e6, 123.4e6}) {
    const cd s(0, kTwoPi * x);
    EXPECT_LT((fit->model.eval(s) - truth.eval(s)).cwiseAbs().maxCoeff(),
              1e-6 * truth.eval(s).cwiseAbs().maxCoeff())
        << x;
  }
}

TEST(VectorFit, SFromYOfASeriesResistor) {
  // A 50 ohm series resistor between two 50 ohm ports: S11 = 1/3, S21 = 2/3.
  Eigen::MatrixXcd y(2, 2);
  y << 0.02, -0.02, -0.02, 0.02;
  const Eigen::MatrixXcd s = s_from_y(y, 50);
  EXPECT_NEAR(std::abs(s(0, 0) - 1.0 / 3), 0, 1e-15);
  EXPECT_NEAR(std::abs(s(1, 0) - 2.0 / 3), 0, 1e-15);
  EXPECT_NEAR((y_from_s(s, 50) - y).cwiseAbs().maxCoeff(), 0, 1e-15);
}

TEST(VectorFit, PassivityCheckAndEnforcement) {
  RationalModel m = known_model();
  EXPECT_TRUE(check_passivity(m, 200e6).passive);
  // A negative shunt at high frequency: D's eigenvalue 0.01 - 0.03 < 0 shows at infinity.
  m.d(0, 0) = m.d(1, 1) = -0.02;
  const PassivityReport before = check_passivity(m, 200e6);
  EXPECT_FALSE(before.passive);
  EXPECT_LT(before.min_eigenvalue, -1e-3);
  std::vector<double> f;
  for (int i = 0; i < 200; ++i) f.push_back(1e5 + i * 1e6);
  const PassivityReport r = enforce_passivity(m, f);
  EXPECT_FALSE(r.passive);
  EXPECT_GE(r.enforced_min_eigenvalue, 0);
  EXPECT_TRUE(check_passivity(m, 200e6).passive);
}

}  // namespace
}  // namespace isolink
