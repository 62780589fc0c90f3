#include "solver/ac.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "test_cards.h"

namespace isolink {
namespace {

using testing::card;
using testing::num;
constexpr double kPi = std::numbers::pi;

Circuit build(const std::vector<Card>& cards) {
  Circuit c;
  for (const Card& k : cards) EXPECT_TRUE(c.add(k).ok()) << k.name;
  EXPECT_TRUE(c.finalize().ok());
  return c;
}

TEST(Ac, RcLowPassMatchesClosedForm) {
  // H(f) = 1 / (1 + j 2 pi f R C); corner at 1/(2 pi R C) = 159.15 kHz.
  const double r = 1e3, cap = 1e-9;
  Circuit c = build({card("vin", {"in", "0"}, {num(0)}), card("r1", {"in", "out"}, {num(r)}),
                     card("c1", {"out", "0"}, {num(cap)})});
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok()) << ac.status().message();
  auto p = parse_probe(c, "v(out)");
  ASSERT_TRUE(p.ok());
  for (double f : {0.0, 1e3, 159.155e3, 1e6, 1e8}) {
    auto x = ac->solve("vin", f);
    ASSERT_TRUE(x.ok()) << x.status().message();
    const std::complex<double> want = 1.0 / std::complex<double>(1.0, 2 * kPi * f * r * cap);
    EXPECT_NEAR(std::abs(x->voltage(*p) - want), 0.0, 1e-12 * (1 + std::abs(want))) << f;
  }
  // At the corner: |H| = 1/sqrt(2), phase -45 degrees.
  auto x = ac->solve("vin", 1 / (2 * kPi * r * cap));
  EXPECT_NEAR(std::abs(x->voltage(*p)), 1 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(std::arg(x->voltage(*p)), -kPi / 4, 1e-12);
}

TEST(Ac, SeriesRlcImpedanceFromSourceCurrent) {
  // Z = R + j(wL - 1/(wC)): at resonance 1/(2 pi sqrt(LC)) the source current is 1/R.
  const double r = 10, l = 1e-6, cap = 1e-9;
  Circuit c = build({card("vin", {"a", "0"}, {num(0)}), card("r1", {"a", "b"}, {num(r)}),
                     card("l1", {"b", "m"}, {num(l)}), card("c1", {"m", "0"}, {num(cap)})});
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok());
  const Element* v = c.find_element("vin");
  for (double f : {1e5, 1 / (2 * kPi * std::sqrt(l * cap)), 2e7}) {
    auto x = ac->solve("vin", f);
    ASSERT_TRUE(x.ok());
    const double w = 2 * kPi * f;
    const std::complex<double> z(r, w * l - 1 / (w * cap));
    // Branch current flows from n+ through the source: the current into the circuit is -i.
    const std::complex<double> i = -x->x[v->branches()[0]];
    EXPECT_NEAR(std::abs(1.0 / i - z), 0.0, 1e-9 * std::abs(z)) << f;
  }
}

// Refactorization reuses the pivots of the first factorization; where one of them has become
// zero, the refactorization fails and the matrix is factored afresh. Here the inductor's branch
// row (-j w L on its diagonal, 6.3 kOhm at 1 GHz, so a natural pivot) has a zero there at DC:
// the divider's exact 2/3 must still come out, and 1 GHz again afterwards. (A pivot that is
// tiny but not zero, 1e-9 Hz here, still solves this small circuit accurately; the 1e-13 pivot
// ratio test guards the large ones.)
TEST(Ac, PivotThatVanishesIsFactoredAfresh) {
  const double r1 = 1e3, r2 = 2e3, l = 1e-6;
  Circuit c = build({card("vin", {"a", "0"}, {num(0)}), card("r1", {"a", "b"}, {num(r1)}),
                     card("l1", {"b", "m"}, {num(l)}), card("r2", {"m", "0"}, {num(r2)})});
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok());
  auto p = parse_probe(c, "v(m)");
  ASSERT_TRUE(p.ok());
  for (double f : {1e9, 0.0, 1e9, 0.0}) {
    auto x = ac->solve("vin", f);
    ASSERT_TRUE(x.ok()) << x.status().message();
    const std::complex<double> want = r2 / std::complex<double>(r1 + r2, 2 * kPi * f * l);
    EXPECT_NEAR(std::abs(x->voltage(*p) - want), 0.0, 1e-12) << f;
  }
}

TEST(Ac, CurrentSourceIntoParallelRc) {
  // 1 A into R || C: V = R / (1 + j w R C). The source pushes current out of its n- node.
  const double r = 50, cap = 1e-9;
  Circuit c = build({card("i1", {"0", "a"}, {num(0)}), card("r1", {"a", "0"}, {num(r)}),
                     card("c1", {"a", "0"}, {num(cap)})});
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok());
  auto p = parse_probe(c, "v(a)");
  const double f = 3e6;
  auto x = ac->solve("i1", f);
  ASSERT_TRUE(x.ok());
  const std::complex<double> want = r / std::complex<double>(1, 2 * kPi * f * r * cap);
  EXPECT_NEAR(std::abs(x->voltage(*p) - want), 0.0, 1e-9);
}

TEST(Ac, ErrorsNameTheSourceAndFrequency) {
  Circuit c = build({card("vin", {"a", "0"}, {num(1)}), card("r1", {"a", "0"}, {num(1)})});
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok());
  auto missing = ac->solve("vx", 1e3);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("'vx'"), std::string::npos);
  auto resistor = ac->solve("r1", 1e3);
  ASSERT_FALSE(resistor.ok());
  EXPECT_NE(resistor.status().message().find("not a V or I source"), std::string::npos);
  auto negative = ac->solve("vin", -1);
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.status().message().find("-1 Hz"), std::string::npos);
}

}  // namespace
}  // namespace isolink
