// The link builder gives the cable behind isolation parts a DC path (expand.h kCableBleed), so the
// examples build with no floating node and no warning, while the solver still warns about a
// floating node when nothing gives it that path (the same link without the bleed resistors).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "netlists/link/cards.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "solver/transient.h"

namespace isolink::link {
namespace {

const std::string kExamples = ISOLINK_EXAMPLES_DIR;

ExpandedLink expand(const std::string& file, Direction d) {
  StatusOr<LinkSpec> spec = read_link_spec_file(kExamples + "/" + file);
  EXPECT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<PartLibrary> parts = PartLibrary::load({});
  EXPECT_TRUE(parts.ok()) << parts.status().message();
  StatusOr<ExpandedLink> link = expand_link(*spec, *parts, d);
  EXPECT_TRUE(link.ok()) << link.status().message();
  return link.ok() ? *link : ExpandedLink{};
}

bool is_bleed(const Card& c) {
  return c.name.find("bleed") != std::string::npos;
}

class Examples : public ::testing::TestWithParam<const char*> {};

TEST_P(Examples, EveryNodeHasADcPathAndNothingWarns) {
  for (Direction d : {Direction::kDown, Direction::kUp}) {
    ExpandedLink link = expand(GetParam(), d);
    Circuit c;
    ASSERT_TRUE(add_cards(c, link.netlist.cards).ok());
    ASSERT_TRUE(c.finalize().ok());
    EXPECT_TRUE(c.floating_nodes().empty()) << GetParam() << " " << direction_name(d);
    EXPECT_TRUE(c.warnings().empty()) << (c.warnings().empty() ? "" : c.warnings()[0]);
  }
}

INSTANTIATE_TEST_SUITE_P(Links, Examples,
                         ::testing::Values("cap_2m.yaml", "capchoke_5m.yaml",
                                           "capdualchoke_10m.yaml", "transformer_15m.yaml",
                                           "hybrid_xfmr_cap_12m.yaml", "same_pcb.yaml",
                                           "bq79606a_cap_2m.yaml", "bq79606a_same_pcb.yaml",
                                           "bq79606a_xfmr_10m.yaml"));

TEST(DcPath, TwoBleedResistorsPerIsolatedEndAtTheConnector) {
  ExpandedLink link = expand("hybrid_xfmr_cap_12m.yaml", Direction::kDown);
  std::vector<std::string> bleeds;
  for (const Card& c : link.netlist.cards)
    if (is_bleed(c)) {
      bleeds.push_back(c.name + " " + c.nodes[0] + " " + c.nodes[1]);
      ASSERT_EQ(c.args.size(), 1u);
      EXPECT_EQ(c.args[0].number, 10e6);
    }
  // tx: transformer (connector after the transformer stage), rx: caps.
  EXPECT_EQ(bleeds, (std::vector<std::string>{"rtxbleedp tx_t1p 0", "rtxbleedn tx_t1n 0",
                                              "rrxbleedp rx_c1p 0", "rrxbleedn rx_c1n 0"}));
  // No isolation at the tx end (bq79606a_same_pcb.yaml), no bleed there: the board network ties
  // the lines to the driving pins.
  std::vector<std::string> names;
  for (const Card& c : expand("bq79606a_same_pcb.yaml", Direction::kDown).netlist.cards)
    if (is_bleed(c)) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"rrxbleedp", "rrxbleedn"}));
}

// Without the bleed resistors the cable between the isolation caps floats: the solver ties it
// with 1e-12 S and says so, naming the nodes (the warning a hand-written netlist gets).
TEST(DcPath, WithoutTheBleedTheCableFloatsAndTheSolverWarns) {
  ExpandedLink link = expand("cap_2m.yaml", Direction::kDown);
  std::vector<Card> cards;
  std::copy_if(link.netlist.cards.begin(), link.netlist.cards.end(), std::back_inserter(cards),
               [](const Card& c) { return !is_bleed(c); });
  ASSERT_EQ(cards.size() + 4, link.netlist.cards.size());
  Circuit c;
  ASSERT_TRUE(add_cards(c, cards).ok());
  ASSERT_TRUE(c.finalize().ok());
  EXPECT_GT(c.floating_nodes().size(), 4u);
  ASSERT_EQ(c.warnings().size(), 1u);
  EXPECT_NE(c.warnings()[0].find("have no DC path to ground"), std::string::npos);
  EXPECT_NE(c.warnings()[0].find("tx_c1p"), std::string::npos) << c.warnings()[0];
}

// The bleed changes nothing the receiver sees: v(rxp,rxn) with and without it (same step grid)
// differ by less than 1 mV, the resolution of every margin the checker reports, over the whole
// 95 us of traffic (measured: 74 uV). Estimate: 5 Mohm per line against the 4.4 nF that holds
// the line's level drifts it by v t / 22 ms, under 13 mV at |v| < 3 V over 95 us, and the
// couplets are DC balanced, so the differential drift cancels to a small part of that.
TEST(DcPath, TheBleedMovesTheReceivedWaveformByMicrovolts) {
  ExpandedLink link = expand("cap_2m.yaml", Direction::kDown);
  auto run = [&](bool bleed) {
    Circuit c;
    std::vector<Card> cards;
    for (const Card& card : link.netlist.cards)
      if (bleed || !is_bleed(card)) cards.push_back(card);
    EXPECT_TRUE(add_cards(c, cards).ok());
    EXPECT_TRUE(c.finalize().ok());
    auto probe = parse_probe(c, "v(rxp,rxn)");
    EXPECT_TRUE(probe.ok());
    TransientOptions opt{.tstep = link.netlist.tran->tstep,
                         .tstop = link.netlist.tran->tstop,
                         .tmax = 1e-9};  // the same step grid for both runs
    auto w = run_transient(c, opt, {*probe});
    EXPECT_TRUE(w.ok()) << w.status().message();
    return w.ok() ? *w : Waveform{};
  };
  const Waveform with = run(true), without = run(false);
  ASSERT_EQ(with.samples(), without.samples());
  ASSERT_GT(with.samples(), 1000u);
  double worst = 0, peak = 0;
  for (size_t i = 0; i < with.samples(); ++i) {
    worst = std::max(worst, std::fabs(with.columns[0][i] - without.columns[0][i]));
    peak = std::max(peak, std::fabs(with.columns[0][i]));
  }
  std::printf("cap_2m down: bleed moves v(rxp,rxn) by at most %.3g uV (peak %.2f V), T = %.1f us\n",
              worst * 1e6, peak, link.netlist.tran->tstop * 1e6);
  EXPECT_GT(peak, 1.0);
  EXPECT_LT(worst, 1e-3);
}

}  // namespace
}  // namespace isolink::link
