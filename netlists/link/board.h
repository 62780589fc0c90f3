// Board networks between a device's COM pins and its isolation parts, with per-device presets
// from docs/physics.md section 4.
//
//   StatusOr<BoardNetwork> b = board_preset("bq7961x");
//   add_board_network(cards, "rxb", "rxp", "rxn", "rxlp", "rxln", *b);
// Topology per line: pin -- r_pin -- esd node -- r_line -- line node, bypass_c from the line
// node to ground; termination across the two line nodes. r_pin = 0 means no ESD split (one
// series resistor r_line).
//   bq7961x: 49 ohm, 220 pF bypass, 1 kohm termination (BQ7961x figures)
//   bq79600: 49 ohm, 100 pF bypass, 1 kohm termination
//   bq79606a: 10 ohm (pin side of the PESD2CAN) + 43 ohm, 51 pF, 10 kohm termination (cap and
//             cap + choke links; 1 kohm with transformers, set by the caller)
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "solver/card.h"

namespace isolink::link {

struct BoardNetwork {
  double r_pin = 0.0;         // ohm, between the pin and the ESD node (0: none)
  double r_line = 49.0;       // ohm, series resistor per line
  double bypass_c = 220e-12;  // F, per line to ground
  double termination = 1e3;   // ohm, differential, across the line nodes

  Status validate() const;
};

// Presets by device name: bq7961x, bq79600, bq79606a. Unknown names list the known ones.
StatusOr<BoardNetwork> board_preset(const std::string& device);
std::vector<std::string> board_preset_names();

Status add_board_network(std::vector<Card>& cards, const std::string& prefix,
                         const std::string& pin_p, const std::string& pin_n,
                         const std::string& line_p, const std::string& line_n,
                         const BoardNetwork& board);

}  // namespace isolink::link
