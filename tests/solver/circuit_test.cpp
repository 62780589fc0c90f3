// Circuit: connection, element value checks, DC topology errors.
#include "solver/circuit.h"

#include <gtest/gtest.h>

#include "solver/transient.h"
#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

TEST(Circuit, NumbersNodesThenBranches) {
  Circuit c;
  ASSERT_EQ(build(c, {card("v1", {"a", "0"}, {num(1)}), card("r1", {"a", "b"}, {num(1)}),
                      card("l1", {"b", "gnd"}, {num(1e-6)})}),
            "");
  EXPECT_EQ(c.node_count(), 3);     // 0, a, b
  EXPECT_EQ(c.unknown_count(), 4);  // a, b, i(v1), i(l1)
  EXPECT_EQ(c.find_node("gnd"), 0);
  EXPECT_EQ(c.unknown_name(c.find_node("b")), "node b");
  EXPECT_EQ(c.unknown_name(4), "current of l1");
  EXPECT_TRUE(c.unknown_is_state(4));
  EXPECT_FALSE(c.unknown_is_state(3));
}

TEST(Circuit, DuplicateNameIsAnError) {
  Circuit c;
  EXPECT_NE(build(c, {card("r1", {"a", "0"}, {num(1)}), card("r1", {"a", "b"}, {num(2)})})
                .find("duplicate element name 'r1'"),
            std::string::npos);
}

TEST(Circuit, NonPositiveValuesAreErrors) {
  for (auto [name, v, what] :
       {std::tuple{"r1", 0.0, "resistance of r1 must be positive, got 0"},
        std::tuple{"c1", -1e-9, "capacitance of c1 must be positive, got -1e-09"},
        std::tuple{"l1", 0.0, "inductance of l1 must be positive, got 0"}}) {
    Circuit c;
    std::string msg = build(c, {card(name, {"a", "0"}, {num(v)})});
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

TEST(Circuit, MutualInductanceChecksItsTargetsAndK) {
  {
    Circuit c;
    std::string msg =
        build(c, {card("l1", {"a", "0"}, {num(1e-6)}), card("r1", {"a", "0"}, {num(1)}),
                  card("k1", {}, {num(0.5)}, {"l1", "r1"})});
    EXPECT_NE(msg.find("k1 couples inductors, but 'r1' is not an inductor"), std::string::npos)
        << msg;
  }
  for (double k : {-1.2, 1.0001}) {
    Circuit c;
    std::string msg =
        build(c, {card("l1", {"a", "0"}, {num(1e-6)}), card("l2", {"b", "0"}, {num(1e-6)}),
                  card("k1", {}, {num(k)}, {"l1", "l2"})});
    EXPECT_NE(msg.find("must satisfy |k| <= 1"), std::string::npos) << msg;
  }
  for (double k : {0.0, 1.0, -1.0}) {  // no coupling; the ideal-transformer idiom
    Circuit c;
    EXPECT_EQ(build(c, {card("l1", {"a", "0"}, {num(1e-6)}), card("l2", {"b", "0"}, {num(4e-6)}),
                        card("k1", {}, {num(k)}, {"l1", "l2"}), card("r1", {"a", "0"}, {num(1)}),
                        card("r2", {"b", "0"}, {num(1)})}),
              "")
        << "k=" << k;
  }
  Circuit c;
  std::string msg =
      build(c, {card("l1", {"a", "0"}, {num(1e-6)}), card("k1", {}, {num(0.5)}, {"l1", "l9"})});
  EXPECT_NE(msg.find("'l9' named by k1 not found"), std::string::npos) << msg;
}

// Three windings with k12 = k23 = 0.9 and k13 = -0.9: v = (1, -1, 1) gives v'Lv = 3 - 5.4 < 0.
TEST(Circuit, InconsistentCouplingsAreRefusedWhenBuilt) {
  Circuit c;
  std::string msg = build(
      c, {card("l1", {"a", "0"}, {num(1e-6)}), card("l2", {"b", "0"}, {num(1e-6)}),
          card("l3", {"c", "0"}, {num(1e-6)}), card("k12", {}, {num(0.9)}, {"l1", "l2"}),
          card("k23", {}, {num(0.9)}, {"l2", "l3"}), card("k13", {}, {num(-0.9)}, {"l1", "l3"})});
  // Eigenvalues of [[1,.9,-.9],[.9,1,.9],[-.9,.9,1]] uH: 1.9, 1.9, -0.8.
  EXPECT_NE(msg.find("the couplings k12, k23, k13 make the inductance matrix of l1, l2, l3 not "
                     "positive semi-definite (smallest eigenvalue -8e-07 H)"),
            std::string::npos)
      << msg;
  Circuit ok;  // the same with k13 = +0.9 is a valid three-winding transformer
  EXPECT_EQ(
      build(ok,
            {card("l1", {"a", "0"}, {num(1e-6)}), card("l2", {"b", "0"}, {num(1e-6)}),
             card("l3", {"c", "0"}, {num(1e-6)}), card("k12", {}, {num(0.9)}, {"l1", "l2"}),
             card("k23", {}, {num(0.9)}, {"l2", "l3"}), card("k13", {}, {num(0.9)}, {"l1", "l3"})}),
      "");
}

// In MNA an inductor carries a branch current, so a source across it is not a loop in the
// transient; at DC the inductor is opened (0 A) with a warning, as ngspice's operating point.
TEST(Circuit, VoltageSourceAcrossAnInductorIsOpenedAtDc) {
  Circuit c;
  ASSERT_EQ(build(c, {card("v1", {"a", "0"}, {num(0)}), card("l1", {"a", "0"}, {num(1e-3)}),
                      card("r1", {"a", "0"}, {num(1)})}),
            "");
  ASSERT_EQ(c.dc_open_branches().size(), 1u);
  EXPECT_EQ(c.unknown_name(c.dc_open_branches()[0]), "current of l1");
  ASSERT_EQ(c.warnings().size(), 1u);
  EXPECT_NE(c.warnings()[0].find("start at 0 A (as in ngspice): l1"), std::string::npos)
      << c.warnings()[0];
}

TEST(Circuit, VoltageSourceLoopIsSingular) {
  Circuit c;
  std::string msg = build(c, {card("v1", {"a", "0"}, {num(1)}), card("v2", {"a", "0"}, {num(2)}),
                              card("r1", {"a", "0"}, {num(1)})});
  EXPECT_NE(msg.find("singular circuit: voltage sources / inductors form a loop (v1, v2) through "
                     "nodes a and 0"),
            std::string::npos)
      << msg;
}

TEST(Circuit, FloatingCurrentSourceIsSingular) {
  Circuit c;
  std::string msg =
      build(c, {card("i1", {"a", "b"}, {num(1e-3)}), card("c1", {"a", "0"}, {num(1e-9)}),
                card("r1", {"b", "0"}, {num(1)})});
  EXPECT_NE(msg.find("current source i1 drives node a, which has no DC path to ground"),
            std::string::npos)
      << msg;
}

TEST(Circuit, PwlWithDecreasingTimesIsAnError) {
  Circuit c;
  std::string msg = build(c, {card("v1", {"a", "0"}, {call("pwl", {0, 0, 2e-9, 1, 1e-9, 0})})});
  EXPECT_NE(msg.find("PWL times must increase: point 3 has t=1e-09 s after t=2e-09 s"),
            std::string::npos)
      << msg;
}

TEST(Circuit, UnknownParameterIsNamed) {
  Circuit c;
  Card r = card("r1", {"a", "0"}, {num(1)});
  r.params.push_back({"tc9", num(1)});
  std::string msg = build(c, {r});
  EXPECT_NE(msg.find("unknown parameter 'tc9' for r1 (known: r, m, tc1, tc2, temp, tnom)"),
            std::string::npos)
      << msg;
}

TEST(Circuit, ProbesNameWhatIsMissing) {
  Circuit c;
  ASSERT_EQ(build(c, {card("v1", {"a", "0"}, {num(1)}), card("r1", {"a", "b"}, {num(1)}),
                      card("r2", {"b", "0"}, {num(1)})}),
            "");
  auto p = parse_probe(c, "V( a , b )");
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->label, "v(a,b)");
  EXPECT_EQ(parse_probe(c, "v(zz)").status().message(), "probe 'v(zz)': no node named 'zz'");
  EXPECT_NE(parse_probe(c, "i(r1)").status().message().find("has no branch current"),
            std::string::npos);
  EXPECT_NE(parse_probe(c, "x(a)").status().message().find("expected v(node)"), std::string::npos);
}

}  // namespace
}  // namespace isolink
