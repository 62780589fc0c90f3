#include "netlists/link/pins.h"

#include <gtest/gtest.h>

#include "netlists/link/cards.h"
#include "solver/transient.h"

namespace isolink::link {
namespace {

traffic::Drive couplet_drive() {  // idle 1 us, + 250 ns, - 250 ns, idle 1 us
  traffic::Drive d;
  d.segments = {{0, 1e-6, 0}, {1e-6, 1.25e-6, +1}, {1.25e-6, 1.5e-6, -1}, {1.5e-6, 2.5e-6, 0}};
  return d;
}

TEST(Pins, TooLongAnEdgeIsAnError) {
  std::vector<Card> cards;
  Status s = add_tx_driver(cards, "tx", "p", "n", couplet_drive(), TxDriverModel{.edge = 300e-9});
  EXPECT_NE(s.message().find("edge time 3e-07 s is too long"), std::string::npos) << s.message();
}

TEST(Pins, DriverIntoTerminatedReceiverGivesTheResistiveDivider) {
  std::vector<Card> cards;
  ASSERT_TRUE(add_tx_driver(cards, "tx", "p", "n", couplet_drive(), TxDriverModel{}).ok());
  ASSERT_TRUE(add_rx_load(cards, "rx", "p", "n", RxLoadModel{}).ok());
  cards.push_back(make_card('r', "rterm", {"p", "n"}, {number_arg(1e3)}));
  Circuit c;
  ASSERT_TRUE(add_cards(c, cards).ok());
  ASSERT_TRUE(c.finalize().ok());
  auto probe = parse_probe(c, "v(p,n)");
  ASSERT_TRUE(probe.ok());
  auto w = run_transient(c, {.tstep = 1e-9, .tstop = 2.5e-6}, {*probe});
  ASSERT_TRUE(w.ok()) << w.status().message();
  const double rload = 1.0 / (1.0 / 1e3 + 1.0 / 20e3);  // termination || two 10 k pins
  const double vplus = 5.0 * rload / (rload + 20.0);    // 4.8972 V
  EXPECT_NEAR(w->value_at(0, 1.24e-6), vplus, 1e-3);
  EXPECT_NEAR(w->value_at(0, 1.49e-6), -vplus, 1e-3);
  EXPECT_NEAR(w->value_at(0, 1.25e-6), 0.0, 0.05);  // edges centred on the corners
  EXPECT_NEAR(w->value_at(0, 2.4e-6), 0.0, 1e-6);   // idle: both lines at 2.5 V
  EXPECT_NEAR(w->value_at(0, 0.5e-6), 0.0, 1e-9);
}

TEST(Pins, ModelsValidateTheirFields) {
  EXPECT_EQ((TxDriverModel{.edge = 0}).validate().message(),
            "tx_driver.edge = 0: must be positive");
  EXPECT_EQ((RxLoadModel{.r_in = -1}).validate().message(), "rx_load.r_in = -1: must be positive");
}

}  // namespace
}  // namespace isolink::link
