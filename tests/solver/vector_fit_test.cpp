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

// A line as its pi section, one conductor, ports tx and rx: a series R + s L between them and at
// each end a shunt C (with 1 ohm in series, so that Y is proper and exactly rational). Its Y has
// a large block (tx - rx: the series path, 1/R at DC) and a small one (tx + rx: the shunt,
// j w C): the fit in the ends' sum and difference (FitOptions::transform) must return the model
// of Y itself, the shunt at 10 kHz (3 uS beside 5.9 S) to 1e-6 of itself.
TEST(VectorFit, TransformedFitReturnsTheModelOfY) {
  const double r = 0.17, l = 0.5e-6, c = 50e-12, rs = 1;
  auto line = [&](double f) {
    const cd s(0, kTwoPi * f);
    const cd series = 1.0 / (r + s * l), shunt = s * c / (1.0 + s * rs * c);
    Eigen::MatrixXcd y(2, 2);
    y << series + shunt, -series, -series, series + shunt;
    return y;
  };
  std::vector<double> f;
  std::vector<Eigen::MatrixXcd> y;
  for (int i = 0; i < 200; ++i) {
    f.push_back(1e4 * std::pow(5e4, i / 199.0));  // 10 kHz .. 500 MHz
    y.push_back(line(f.back()));
  }
  FitOptions o;
  const double k = 1 / std::sqrt(2.0);
  o.transform = (Eigen::MatrixXd(2, 2) << k, k, k, -k).finished();
  StatusOr<FitResult> fit = vector_fit(f, y, o);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit->converged);
  for (double x : {1e4, 3.3e5, 12e6, 480e6}) {
    const Eigen::MatrixXcd want = line(x), got = fit->model.eval(cd(0, kTwoPi * x));
    EXPECT_LT((got - want).cwiseAbs().maxCoeff(), 1e-6 * want.cwiseAbs().maxCoeff()) << x;
    const cd shunt_want = want(0, 0) + want(0, 1), shunt_got = got(0, 0) + got(0, 1);
    EXPECT_LT(std::abs(shunt_got - shunt_want), 1e-6 * std::abs(shunt_want)) << x;
  }
  // Not orthogonal: refused.
  o.transform(1, 1) = k;
  StatusOr<FitResult> bad = vector_fit(f, y, o);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("orthogonal"), std::string::npos);
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
