// The touchstone fit plot's numbers (reports/touchstone_png.h): the mixed-mode entries of a
// network whose Sdd21 and Sdd11 have a closed form, the file's port mapping, and the model-as-
// simulated error; the PNG is written at its size.
#include "reports/touchstone_png.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fixtures.h"

namespace isolink::reports {
namespace {

// Two equal series resistors R, port 1 -> 3 and 2 -> 4 (tx P -> rx P, tx N -> rx N), as a file
// and as a model (Y constant: D, no poles). Differentially a series 2R between 2 x z0
// references: Sdd21 = 2 (2 z0) / (2 (2 z0) + 2R) = 2 z0 / (2 z0 + R), Sdd11 = R / (2 z0 + R).
link::TouchstoneCable series_pair(double r, double z0, std::vector<int> ports) {
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(4, 4);
  for (auto [a, b] : {std::pair{0, 2}, std::pair{1, 3}}) {
    y(a, a) = y(b, b) = 1 / r;
    y(a, b) = y(b, a) = -1 / r;
  }
  link::TouchstoneCable c;
  c.ports = ports;
  c.data.ports = 4;
  c.data.z0 = z0;
  c.data.source = "series_pair.s4p";
  c.fit.model.ports = 4;
  c.fit.model.d = y;
  // The file in its own port order: file port ports[i] holds the link's port i.
  const Eigen::MatrixXcd s_link = s_from_y(y.cast<std::complex<double>>(), z0);
  Eigen::MatrixXcd s_file(4, 4);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) s_file(ports[i] - 1, ports[j] - 1) = s_link(i, j);
  for (double f : {1e4, 1e6, 1e8}) {
    c.data.freqs.push_back(f);
    c.data.s.push_back(s_file);
  }
  return c;
}

TEST(TouchstonePlot, MixedModeEntriesOfASeriesPairAreClosedForm) {
  for (const std::vector<int>& ports :
       {std::vector<int>{1, 2, 3, 4}, std::vector<int>{3, 1, 4, 2}}) {
    const link::TouchstoneCable c = series_pair(50, 50, ports);
    const TouchstoneCurves k = touchstone_curves(c);
    ASSERT_EQ(k.freqs.size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR(std::abs(k.sdd21_file[i] - 2.0 / 3.0), 0, 1e-12);  // 100 / (100 + 50)
      EXPECT_NEAR(std::abs(k.sdd11_file[i] - 1.0 / 3.0), 0, 1e-12);  // 50 / (100 + 50)
      EXPECT_NEAR(std::abs(k.sdd21_fit[i] - k.sdd21_file[i]), 0, 1e-12);
      EXPECT_NEAR(k.entry_error[i], 0, 1e-12);
    }
    EXPECT_NEAR(k.rms_error, 0, 1e-12);
  }
}

// The error curve is the model's against the file's: a model 10 % off in R shows it at every
// frequency, its largest entry error that of the S entries' closed form.
TEST(TouchstonePlot, ErrorIsThatOfTheModelSimulated) {
  link::TouchstoneCable c = series_pair(50, 50, {1, 2, 3, 4});
  const link::TouchstoneCable off = series_pair(55, 50, {1, 2, 3, 4});
  c.fit.model.d = off.fit.model.d;
  const TouchstoneCurves k = touchstone_curves(c);
  const Eigen::MatrixXcd d = off.data.s[0] - c.data.s[0];
  const double expected = d.cwiseAbs().maxCoeff();
  EXPECT_GT(expected, 0.01);
  for (double e : k.entry_error) EXPECT_NEAR(e, expected, 1e-12);
  EXPECT_NEAR(k.max_error, expected, 1e-12);
  EXPECT_NEAR(k.rms_error, std::sqrt(d.cwiseAbs2().sum() / 16), 1e-12);
  const std::string path = fixtures::temp_dir("touchstone_png") + "/fit.png";
  ASSERT_TRUE(write_touchstone_png(c, path).ok());
  const fixtures::Png img = fixtures::read_png(path);
  EXPECT_EQ(img.width, 1800);
  EXPECT_EQ(img.height, 1500);
}

}  // namespace
}  // namespace isolink::reports
