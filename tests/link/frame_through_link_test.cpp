// End to end: a command frame driven through a short link is decoded back to its bytes.
#include <gtest/gtest.h>

#include "base/hex.h"
#include "eye/check.h"
#include "netlists/link/board.h"
#include "netlists/link/cards.h"
#include "netlists/link/pins.h"
#include "netlists/traffic/command.h"
#include "solver/transient.h"

namespace isolink::link {
namespace {

TEST(FrameThroughLink, StackWriteDecodesToTheSameBytes) {
  auto bytes = traffic::command_bytes("stack-write reg=0x0100 data=02B778BC");
  ASSERT_TRUE(bytes.ok());
  traffic::DriveBuilder builder;
  ASSERT_TRUE(builder.add_frame(*bytes, "stack-write").ok());
  const traffic::Drive drive = builder.finish();

  // BQ79600 pins and board -> direct short connection -> BQ7961x board and pins.
  std::vector<Card> cards;
  ASSERT_TRUE(add_tx_driver(cards, "tx", "txp", "txn", drive, TxDriverModel{}).ok());
  ASSERT_TRUE(
      add_board_network(cards, "txb", "txp", "txn", "lp", "ln", *board_preset("bq79600")).ok());
  ASSERT_TRUE(
      add_board_network(cards, "rxb", "rxp", "rxn", "lp", "ln", *board_preset("bq7961x")).ok());
  ASSERT_TRUE(add_rx_load(cards, "rx", "rxp", "rxn", RxLoadModel{}).ok());
  Circuit c;
  ASSERT_TRUE(add_cards(c, cards).ok());
  ASSERT_TRUE(c.finalize().ok());
  auto probe = parse_probe(c, "v(rxp,rxn)");
  ASSERT_TRUE(probe.ok());
  auto wave = run_transient(c, {.tstep = 1e-9, .tstop = drive.duration()}, {*probe});
  ASSERT_TRUE(wave.ok()) << wave.status().message();

  auto rules = eye::load_rules("bq7961x");
  ASSERT_TRUE(rules.ok()) << rules.status().message();
  eye::CheckOptions opt;
  opt.expect = *bytes;
  auto result = eye::check_waveform(*wave, *rules, opt);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(to_hex(result->bytes), "B3 01 00 02 B7 78 BC 0A 35");
  EXPECT_TRUE(result->expect_match) << result->expect_detail;
  EXPECT_TRUE(result->pass) << eye::summary_text(*result);
  // A short link keeps the full swing: 5 V through 2 x 49 ohm (+ driver) into ~0.9 kohm.
  ASSERT_TRUE(result->vstart_min().has_value());
  EXPECT_GT(*result->vstart_min(), 4.0);
  EXPECT_EQ(result->pulses.size(), drive.pulses().size());
}

}  // namespace
}  // namespace isolink::link
