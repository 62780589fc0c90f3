// Pin models of the daisy-chain devices: the TX driver and the RX load, appended as ordinary
// element Cards built in code (netlists/link/cards.h).
//
//   traffic::Drive drive = builder.finish();
//   std::vector<Card> cards;
//   add_tx_driver(cards, "tx", "txp", "txn", drive, TxDriverModel{});  // VTX.P/N + output Rs
//   add_rx_load(cards, "rx", "rxp", "rxn", RxLoadModel{});             // R to bias, C to ground
// The probed differential voltage is v(rxp,rxn): at the pins.
//
// Defaults (our assumptions where the data sheets are silent; netlists/link/README.md):
//   TX: CVDD 5 V, lines driven 0 / 5 V complementary, 2.5 V when idle (actively held), 10 ns
//       linear edges (0-100 %) centred on each corner (traffic::line_pwl, as `isolink frame
//       --pwl`), 10 ohm output resistance per line.
//   RX: 10 kohm per pin to a 2.5 V bias, 5 pF per pin to ground.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "netlists/traffic/drive.h"
#include "solver/card.h"

namespace isolink::link {

struct TxDriverModel {
  double vdd = 5.0;     // V, line high level (CVDD)
  double edge = 10e-9;  // s, 0-100 % transition time of each line
  double r_out = 10.0;  // ohm, output resistance per line

  Status validate() const;  // names the field, its value and the rule
};

struct RxLoadModel {
  double r_in = 10e3;   // ohm, per pin to the bias
  double c_in = 5e-12;  // F, per pin to ground
  double bias = 2.5;    // V, the receiver's common-mode bias

  Status validate() const;
};

// Adds sources "v<prefix>p"/"v<prefix>n" (PWL from the drive's segments, corners as
// breakpoints) behind resistors "r<prefix>p"/"r<prefix>n" to the pins p and n.
Status add_tx_driver(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                     const std::string& n, const traffic::Drive& drive, const TxDriverModel& model);

// Adds the receiver input network at pins p and n (bias source "v<prefix>bias").
Status add_rx_load(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                   const std::string& n, const RxLoadModel& model);

}  // namespace isolink::link
