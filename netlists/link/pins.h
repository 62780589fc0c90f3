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
//   Clamps (opt-in, EndSpec::pin_clamps "rails"): each COM pin's internal ESD diodes, one from
//       the pin to CVDD (5 V) and one from CVSS (the device ground) to the pin, SPICE level-1
//       diodes. The data sheets give no figures for them: IS 1e-14 A and N 1 (ngspice's
//       defaults: 0.6 V at 0.1 mA), RS 2 ohm (a few ohms, typical of on-chip ESD diodes), no
//       junction capacitance of their own (the 5 pF per pin above already holds the pin's
//       capacitance). Assumptions, stated in netlists/link/README.md.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "netlists/traffic/drive.h"
#include "solver/card.h"

namespace isolink::link {

// The internal ESD clamp diodes of a COM pin (see the header comment for the figures' status).
struct PinClampModel {
  bool enabled = false;  // false: linear pins
  double vdd = 5.0;      // V, CVDD: the upper diode's rail
  double is = 1e-14;     // A, saturation current of each diode
  double rs = 2.0;       // ohm, series resistance of each diode

  Status validate() const;
};

struct TxDriverModel {
  double vdd = 5.0;     // V, line high level (CVDD)
  double edge = 10e-9;  // s, 0-100 % transition time of each line
  double r_out = 10.0;  // ohm, output resistance per line
  PinClampModel clamps;

  Status validate() const;  // names the field, its value and the rule
};

struct RxLoadModel {
  double r_in = 10e3;   // ohm, per pin to the bias
  double c_in = 5e-12;  // F, per pin to ground
  double bias = 2.5;    // V, the receiver's common-mode bias
  PinClampModel clamps;

  Status validate() const;
};

// With clamps enabled, both add a CVDD source "v<prefix>cvdd" (node "<prefix>_cvdd") and diodes
// "d<prefix>hp"/"d<prefix>hn" (pin to CVDD) and "d<prefix>lp"/"d<prefix>ln" (CVSS to pin) sharing
// the model "<prefix>_clamp".
// Adds sources "v<prefix>p"/"v<prefix>n" (PWL from the drive's segments, corners as
// breakpoints) behind resistors "r<prefix>p"/"r<prefix>n" to the pins p and n.
Status add_tx_driver(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                     const std::string& n, const traffic::Drive& drive, const TxDriverModel& model);

// Adds the receiver input network at pins p and n (bias source "v<prefix>bias").
Status add_rx_load(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                   const std::string& n, const RxLoadModel& model);

}  // namespace isolink::link
