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
//      (+ kCableBleed to ground per line)
//   -> cable -> rx_cp/rx_cn -> isolation -> rx_lp/rx_ln -> board -> rxp/rxn -> RX load.
// X caps (x_cap) across and Y caps (y_cap, to the chassis "0") sit at each end's connector
// (the cable side of its isolation).
// Node names follow the role in this direction: txp/txn always drive, rxp/rxn always receive.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/link/pins.h"
#include "netlists/spice_reader.h"
#include "netlists/traffic/drive.h"
#include "netlists/traffic/stimulus.h"

namespace isolink::link {

// Bleed resistance (ohm) from each cable line to ground at every end with isolation (cards
// r<end>bleedp / r<end>bleedn, at the connector nodes <end>_..p / <end>_..n). The isolation caps or
// transformer leave the cable, and the parts on its side, with no DC path; on a board the
// isolation barrier's insulation resistance and the cable-side ESD / TVS parts' leakage (tens of
// nA at a few volts) set its DC level. 10 Mohm per line is that order; with both ends, 5 Mohm per
// line against the two 2.2 nF isolation caps gives a time constant of 22 ms, over 100 times the
// longest frame train, so no edge or level the receiver sees moves (tests/link/dc_path_test.cpp).
inline constexpr double kCableBleed = 10e6;

struct ExpandOptions {
  TxDriverModel driver;               // the transmitting pins
  RxLoadModel load;                   // the receiving pins
  traffic::StimulusOptions stimulus;  // encoding and timing of the traffic
  // Ground nodes of the transmitting and the receiving board. "0" (the default) is the chassis:
  // both boards' grounds joined to it, as `isolink run` simulates. Other names keep the boards
  // apart (isolink noise): everything the board references goes to its ground node, which
  // reaches the chassis through the end's chassis_c; the cable's capacitance to the chassis and
  // the Y caps stay on "0".
  std::string tx_ground = "0", rx_ground = "0";
  // Drives the link with this instead of the spec's stimulus (analyses that make their own
  // traffic, e.g. one edge for the worst-case search); .tran then ends with it.
  std::optional<traffic::Drive> drive;
};

struct ExpandedLink {
  Direction direction = Direction::kDown;
  std::string transmitter, receiver;  // device names
  std::string rules;                  // rule set the receiver is scored with
  std::string description;            // "down: bq79600 -> bq7961x"
  Netlist netlist;                    // cards, .tran, options
  traffic::Drive drive;               // what the transmitter sends
  std::vector<uint8_t> expected;      // data bytes sent, in order
  int cable_segments = 0;             // sections the cable was split into (0: a measured cable)
  // The cable's end nodes: the transmitting end's P and N, the receiving end's P and N (where a
  // measured cable's ports attach).
  std::array<std::string, 4> cable_ends;
  std::string tx_bom, rx_bom;  // each spec end's parts as built, in words
};

StatusOr<ExpandedLink> expand_link(const LinkSpec& spec, const PartLibrary& parts, Direction d,
                                   const ExpandOptions& opt = {});

// What makes two expanded directions the same analysis: the circuit and traffic as SPICE text
// (the title, which names the spec, left out), the receiver's rules and the bytes it must decode.
// A mirror-symmetric link (the same parts at both ends) has the same key both ways, as do the
// identical hops of a pack (node names follow the roles): the link-level analyses compute one
// result per key.
std::string circuit_key(const ExpandedLink& x);

}  // namespace isolink::link
