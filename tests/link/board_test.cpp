#include "netlists/link/board.h"

#include <gtest/gtest.h>

#include "netlists/link/cards.h"
#include "solver/transient.h"

namespace isolink::link {
namespace {

TEST(Board, PresetsFollowTheApplicationNotes) {
  auto b = board_preset("bq7961x");
  ASSERT_TRUE(b.ok());
  EXPECT_DOUBLE_EQ(b->bypass_c, 220e-12);
  EXPECT_DOUBLE_EQ(b->r_line, 49.0);
  EXPECT_DOUBLE_EQ(board_preset("bq79600")->bypass_c, 100e-12);
  auto a = board_preset("bq79606a");
  EXPECT_DOUBLE_EQ(a->bypass_c, 51e-12);
  EXPECT_DOUBLE_EQ(a->r_line, 43.0);
  EXPECT_DOUBLE_EQ(a->r_pin, 10.0);
  EXPECT_DOUBLE_EQ(a->termination, 10e3);
  EXPECT_EQ(board_preset("bq1234").status().message(),
            "unknown device 'bq1234' (known: bq7961x, bq79600, bq79606a)");
}

TEST(Board, DcThroughTheNetworkIsTheSeriesDivider) {
  // 1 V across the pins of a bq79606a network: the line nodes see the termination's share.
  std::vector<Card> cards{make_card('v', "v1", {"pp", "pn"}, {number_arg(1.0)})};
  ASSERT_TRUE(
      add_board_network(cards, "b", "pp", "pn", "lp", "ln", *board_preset("bq79606a")).ok());
  Circuit c;
  ASSERT_TRUE(add_cards(c, cards).ok());
  ASSERT_TRUE(c.finalize().ok());
  auto x = dc_operating_point(c);
  ASSERT_TRUE(x.ok()) << x.status().message();
  const double share = 10e3 / (10e3 + 2 * (10.0 + 43.0));
  EXPECT_NEAR((*x)[c.find_node("lp")] - (*x)[c.find_node("ln")], share, 1e-9);
}

TEST(Board, NegativeValuesAreRejected) {
  BoardNetwork b;
  b.bypass_c = -1e-12;
  EXPECT_EQ(b.validate().message(), "board.bypass_c = -1e-12: must not be negative");
}

}  // namespace
}  // namespace isolink::link
