// G (VCCS): the stamp against closed forms (an inverting transconductance stage, a gyrator's
// inductance), and the parser's refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/ac.h"
#include "test_cards.h"

namespace isolink {
namespace {

using testing::card;
using testing::num;
using cd = std::complex<double>;

TEST(Vccs, TransconductanceIntoResistor) {
  // gm V(in) flows from out through the source to ground: V(out) = -gm R V(in) = -2 at gm 1 mS,
  // R 2 kohm, with a second G controlled the other way round adding nothing (V(0, in) * 0).
  Circuit c;
  for (const Card& k :
       {card("vin", {"in", "0"}, {num(0)}), card("g1", {"out", "0", "in", "0"}, {num(1e-3)}),
        card("r1", {"out", "0"}, {num(2e3)})})
    ASSERT_TRUE(c.add(k).ok()) << k.name;
  ASSERT_TRUE(c.finalize().ok());
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok()) << ac.status().message();
  auto p = parse_probe(c, "v(out)");
  ASSERT_TRUE(p.ok());
  auto x = ac->solve("vin", 1e3);
  ASSERT_TRUE(x.ok()) << x.status().message();
  EXPECT_NEAR(std::abs(x->voltage(*p) - cd(-2, 0)), 0, 1e-12);
}

TEST(Vccs, GyratorMakesAnInductor) {
  // Two Gs of gm g in a gyrator loaded by C: the input is an inductor L = C / g^2. Driven through
  // R, V(a) / V(in) = j w L / (R + j w L).
  const double g = 1e-3, cap = 1e-9, r = 100, l = cap / (g * g);
  Circuit c;
  for (const Card& k :
       {card("vin", {"in", "0"}, {num(0)}), card("r1", {"in", "a"}, {num(r)}),
        card("g1", {"a", "0", "b", "0"}, {num(g)}), card("g2", {"b", "0", "0", "a"}, {num(g)}),
        card("c1", {"b", "0"}, {num(cap)})})
    ASSERT_TRUE(c.add(k).ok()) << k.name;
  ASSERT_TRUE(c.finalize().ok());
  auto ac = AcAnalysis::create(c);
  ASSERT_TRUE(ac.ok());
  auto p = parse_probe(c, "v(a)");
  ASSERT_TRUE(p.ok());
  for (double f : {1e3, 1e4, 1e5}) {
    const cd jwl(0, 2 * std::numbers::pi * f * l);
    auto x = ac->solve("vin", f);
    ASSERT_TRUE(x.ok());
    // Node b has no DC path: its 1e-12 S tie (Circuit) against w C (6e-6 S at 1 kHz) is the
    // 1e-7 allowed.
    EXPECT_NEAR(std::abs(x->voltage(*p) - jwl / (r + jwl)), 0, 1e-7) << f;
  }
}

TEST(Vccs, RefusesNonFiniteAndWrongNodeCount) {
  Circuit c;
  EXPECT_FALSE(c.add(card("g1", {"a", "0", "b"}, {num(1)})).ok());
  EXPECT_FALSE(c.add(card("g2", {"a", "0", "b", "0"}, {num(INFINITY)})).ok());
}

}  // namespace
}  // namespace isolink
