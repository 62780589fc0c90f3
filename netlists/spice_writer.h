// SPICE writer: a Netlist back to ngspice text (flat: hierarchical elements are written with
// ngspice's flattened names, "x1.r3" as "r.x1.r3", which the reader maps back to "x1.r3").
//
//   std::string text = write_spice(netlist);   // read_spice_text(text) gives the same cards
//
// Numbers are written with %.12g; PWL/PULSE/SIN arguments as calls, broken into '+'
// continuation lines of 8 values; then the .model cards the elements name (each once), .options,
// .tran and .end.
#pragma once

#include <string>

#include "netlists/spice_reader.h"

namespace isolink {

std::string write_spice(const Netlist& netlist);

}  // namespace isolink
