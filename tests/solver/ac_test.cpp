#include "solver/ac.h"

#include <gtest/gtest.h>

#include <array>
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

// A twisted pair as the link expander builds its cable: 150 sections (a 15 m line's R, L and C
// per 10 cm) of two lines whose inductors are coupled (k = 0.74), with capacitance between the
// lines and to ground; 50 ohm from a source on line p (line n's end grounded through 50 ohm) to
// 100 ohm per line at the far end. Reference: the product of the sections' 4 x 4 chain matrices
// (up to 300 MHz: above the ladder's cutoff, 600 MHz, its entries overflow). Each inductor's
// branch row has j w L on its diagonal, under the 0.02 ohm beside it below 64 kHz; the paired
// ordering (solver/ac.h) must stay exact from 1 kHz to 300 MHz and back with the pivots of the
// first frequency reused, as the reduced model's check reuses them.
TEST(Ac, CoupledLadderMatchesItsChainMatricesWithPairedOrdering) {
  using Cplx = std::complex<double>;
  using M2 = std::array<Cplx, 4>;  // row-major 2 x 2
  const int sections = 150;
  const double rs = 50, rl = 100, r = 0.02, l = 50e-9, k = 0.74, cg = 3e-12, cx = 2e-12;
  std::vector<Card> cards = {card("vin", {"in", "0"}, {num(0)}),
                             card("rsp", {"in", "p0"}, {num(rs)}),
                             card("rsn", {"n0", "0"}, {num(rs)})};
  for (int s = 1; s <= sections; ++s) {
    const std::string i = std::to_string(s), h = std::to_string(s - 1);
    for (const std::string line : {"p", "n"}) {
      cards.push_back(card("r" + line + i, {line + h, line + "m" + i}, {num(r)}));
      cards.push_back(card("l" + line + i, {line + "m" + i, line + i}, {num(l)}));
      cards.push_back(card("c" + line + i, {line + i, "0"}, {num(cg)}));
    }
    cards.push_back(card("k" + i, {}, {num(k)}, {"lp" + i, "ln" + i}));
    cards.push_back(card("cx" + i, {"p" + i, "n" + i}, {num(cx)}));
  }
  const std::string end = std::to_string(sections);
  cards.push_back(card("rlp", {"p" + end, "0"}, {num(rl)}));
  cards.push_back(card("rln", {"n" + end, "0"}, {num(rl)}));
  Circuit c = build(cards);
  auto ac = AcAnalysis::create(c, AcOrdering::kPaired);
  ASSERT_TRUE(ac.ok());
  auto pp = parse_probe(c, "v(p" + end + ")");
  auto pn = parse_probe(c, "v(n" + end + ")");
  ASSERT_TRUE(pp.ok() && pn.ok());
  auto mul = [](const M2& a, const M2& b) {
    return M2{a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2],
              a[2] * b[1] + a[3] * b[3]};
  };
  auto add = [](const M2& a, const M2& b) {
    return M2{a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]};
  };
  auto scale = [](Cplx x, const M2& a) { return M2{x * a[0], x * a[1], x * a[2], x * a[3]}; };
  const M2 eye{1.0, 0.0, 0.0, 1.0};
  for (double f : {1e6, 1e3, 64e3, 3e7, 3e8, 1e3}) {
    const double w = 2 * kPi * f;
    // Section: [v; i] <- [I z; 0 I] [I 0; y I] [v'; i'], z the series and y the shunt matrix.
    const M2 z{Cplx(r, w * l), Cplx(0, w * k * l), Cplx(0, w * k * l), Cplx(r, w * l)};
    const M2 y{Cplx(0, w * (cg + cx)), Cplx(0, -w * cx), Cplx(0, -w * cx), Cplx(0, w * (cg + cx))};
    M2 a = eye, b{}, cc{}, d = eye;                        // the chain so far, [a b; cc d]
    const M2 a_s = add(eye, mul(z, y)), b_s = z, c_s = y;  // the section's blocks (d_s = I)
    for (int s = 0; s < sections; ++s) {
      const M2 a2 = add(mul(a, a_s), mul(b, c_s)), b2 = add(mul(a, b_s), b);
      const M2 c2 = add(mul(cc, a_s), mul(d, c_s)), d2 = add(mul(cc, b_s), d);
      a = a2, b = b2, cc = c2, d = d2;
    }
    // Source end: [1; 0] = v0 + rs i0; far end: i = v / rl. So [1; 0] = m v_end with
    // m = a + b / rl + rs (cc + d / rl).
    const M2 m = add(add(a, scale(1 / rl, b)), scale(rs, add(cc, scale(1 / rl, d))));
    const Cplx det = m[0] * m[3] - m[1] * m[2];
    const Cplx want_p = m[3] / det, want_n = -m[2] / det;
    auto x = ac->solve("vin", f);
    ASSERT_TRUE(x.ok()) << x.status().message();
    EXPECT_NEAR(std::abs(x->voltage(*pp) - want_p), 0.0, 1e-10) << f << " Hz";
    EXPECT_NEAR(std::abs(x->voltage(*pn) - want_n), 0.0, 1e-10) << f << " Hz";
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
