// Link expansion: a LinkSpec and a direction -> the flat circuit (as a Netlist of Cards), the
// transmitted drive and what the receiver is scored against.
//
//   StatusOr<PartLibrary> parts = PartLibrary::load({});
//   StatusOr<ExpandedLink> down = expand_link(spec, *parts, Direction::kDown);
//   // down->netlist: simulate (analysis/simulate.h) or write_spice() it (export-spice)
//   // probe v(rxp,rxn): the receiver's pins; v(txp,txn): the transmitter's.
// Topology, from the transmitting device to the receiving one (netlists/link/README.md):
//   TX driver -> txp/txn -> board (series R, bypass C, termination) -> tx_lp/tx_ln
//   -> isolation (cap | cap + chokes | transformer | transformer + chokes) -> tx_cp/tx_cn
//   -> cable -> rx_cp/rx_cn -> isolation -> rx_lp/rx_ln -> board -> rxp/rxn -> RX load.
// Node names follow the role in this direction: txp/txn always drive, rxp/rxn always receive.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/link/pins.h"
#include "netlists/spice_reader.h"
#include "netlists/traffic/drive.h"
#include "netlists/traffic/stimulus.h"

namespace isolink::link {

struct ExpandOptions {
  TxDriverModel driver;                 // the transmitting pins
  RxLoadModel load;                     // the receiving pins
  traffic::StimulusOptions stimulus;    // encoding and timing of the traffic
};

struct ExpandedLink {
  Direction direction = Direction::kDown;
  std::string transmitter, receiver;    // device names
  std::string rules;                    // rule set the receiver is scored with
  std::string description;              // "down: bq79600 -> bq7961x"
  Netlist netlist;                      // cards, .tran, options
  traffic::Drive drive;                 // what the transmitter sends
  std::vector<uint8_t> expected;        // data bytes sent, in order
  int cable_segments = 0;               // sections the cable was split into
  std::string tx_bom, rx_bom;           // each spec end's parts as built, in words
};

StatusOr<ExpandedLink> expand_link(const LinkSpec& spec, const PartLibrary& parts, Direction d,
                                   const ExpandOptions& opt = {});

}  // namespace isolink::link
