#include "netlists/spice_writer.h"

#include <gtest/gtest.h>

namespace isolink {
namespace {

void expect_same_cards(const Netlist& a, const Netlist& b) {
  EXPECT_EQ(a.title, b.title);
  ASSERT_EQ(a.cards.size(), b.cards.size());
  for (std::size_t i = 0; i < a.cards.size(); ++i) {
    const Card& x = a.cards[i];
    const Card& y = b.cards[i];
    SCOPED_TRACE(x.name);
    EXPECT_EQ(x.letter, y.letter);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.nodes, y.nodes);
    EXPECT_EQ(x.refs, y.refs);
    ASSERT_EQ(x.args.size(), y.args.size());
    for (std::size_t k = 0; k < x.args.size(); ++k) {
      EXPECT_EQ(x.args[k].kind, y.args[k].kind);
      EXPECT_EQ(x.args[k].number, y.args[k].number);
      EXPECT_EQ(x.args[k].word, y.args[k].word);
      EXPECT_EQ(x.args[k].call, y.args[k].call);
    }
    ASSERT_EQ(x.params.size(), y.params.size());
    for (std::size_t k = 0; k < x.params.size(); ++k) {
      EXPECT_EQ(x.params[k].first, y.params[k].first);
      EXPECT_EQ(x.params[k].second.number, y.params[k].second.number);
    }
  }
}

TEST(SpiceWriter, WritesNgspiceText) {
  auto n = read_spice_text(
      "Writer test\n"
      "R1 a b 1k\n"
      "V1 a 0 DC 2.5\n"
      "V2 b 0 PULSE(0 5 1n 2n 2n 100n 250n)\n"
      "C1 b 0 2.2n ic=0.5\n"
      ".options reltol=1e-4 noacct method=gear\n"
      ".tran 1n 10u\n");
  ASSERT_TRUE(n) << n.status().message();
  EXPECT_EQ(write_spice(*n),
            "Writer test\n"
            "r1 a b 1000\n"
            "v1 a 0 dc 2.5\n"
            "v2 b 0 pulse(0 5 1e-09 2e-09 2e-09 1e-07 2.5e-07)\n"
            "c1 b 0 2.2e-09 ic=0.5\n"
            ".options reltol=0.0001\n"
            ".options noacct\n"
            ".options method=gear\n"
            ".tran 1e-09 1e-05\n"
            ".end\n");
}

TEST(SpiceWriter, RoundTripFlattenedHierarchyAndLongPwl) {
  std::string text =
      "Round trip: hierarchy, coupling, sources\n"
      ".param rt=120.5\n"
      ".subckt xfmr p1 p2 s1 s2 params: lm=150u k=0.995\n"
      "L1 p1 p2 {lm}\n"
      "L2 s1 s2 {lm}\n"
      "K1 L1 L2 {k}\n"
      "R1 s2 mid 1meg\n"
      ".ends\n"
      "X1 txp txn rxp rxn xfmr k=0.98\n"
      "R1 rxp rxn {rt}\n"
      "I1 0 rxp SIN(0 1m 1meg 0 0 90)\n"
      "V1 txp txn PWL(";
  for (int i = 0; i < 50; ++i)
    text += std::to_string(i * 12.5) + "n " + std::to_string(i % 3) + " ";
  text += ")\n.tran 0.1n 2u 0 1n uic\n.options abstol=1e-12\n";
  auto first = read_spice_text(text);
  ASSERT_TRUE(first) << first.status().message();
  ASSERT_EQ(first->cards.size(), 7u);
  const std::string written = write_spice(*first);
  // Hierarchical elements use ngspice's flattened names; long PWLs use continuation lines.
  EXPECT_NE(written.find("\nl.x1.l1 txp txn 0.00015\n"), std::string::npos) << written;
  // K names the inductors by their flattened names too, as ngspice needs.
  EXPECT_NE(written.find("\nk.x1.k1 l.x1.l1 l.x1.l2 0.98\n"), std::string::npos) << written;
  EXPECT_NE(written.find("\nr.x1.r1 rxn x1.mid 1000000\n"), std::string::npos) << written;
  EXPECT_NE(written.find("\n+ "), std::string::npos);
  auto second = read_spice_text(written);
  ASSERT_TRUE(second) << second.status().message() << "\n" << written;
  expect_same_cards(*first, *second);
  ASSERT_TRUE(second->tran);
  EXPECT_EQ(second->tran->tstep, 0.1e-9);
  EXPECT_EQ(second->tran->tstop, 2e-6);
  EXPECT_EQ(second->tran->tmax, 1e-9);
  EXPECT_TRUE(second->tran->uic);
  ASSERT_EQ(second->options.size(), 1u);
  EXPECT_EQ(second->options[0].key, "abstol");
  EXPECT_EQ(second->options[0].value.number, 1e-12);
  EXPECT_EQ(write_spice(*second), written);  // a fixed point
}

// Issue 13: what the reader resolves (.ic, .global, .temp, .lib, .if) comes back the same.
TEST(SpiceWriter, RoundTripInitialConditionsAndResolvedDialect) {
  auto n = read_spice_text(
      "dialect\n.global vcc\n.temp 50\n.param sel=1\n.subckt s a\nR1 vcc a 1k tc1=1m\n.ends\n"
      ".if (sel == 1)\nX1 p s\n.else\nX2 p s\n.endif\nV1 vcc 0 dc=2 ac=1\n"
      "V2 p 0 PWL(0 0 1u 1) td=1u r=0\n.ic v(p)=0.25\n.tran 1n 1u uic\n",
      "t.cir");
  ASSERT_TRUE(n) << n.status().message();
  const std::string text = write_spice(*n);
  EXPECT_NE(text.find(".ic v(p)=0.25\n"), std::string::npos) << text;
  EXPECT_NE(text.find("r.x1.r1 vcc p 1000 tc1=0.001 temp=50\n"), std::string::npos) << text;
  auto back = read_spice_text(text, "back.cir");
  ASSERT_TRUE(back) << back.status().message() << "\n" << text;
  expect_same_cards(*n, *back);
  ASSERT_EQ(back->initial_voltages.size(), 1u);
  EXPECT_EQ(back->initial_voltages[0].node, "p");
  EXPECT_EQ(back->initial_voltages[0].value, 0.25);
}

}  // namespace
}  // namespace isolink
