// SPICE-subset netlist reader (ngspice dialect): includes, parameters, expressions and
// subcircuits are resolved here; the result is a flat list of element Cards for the solver.
//
//   StatusOr<Netlist> n = read_spice_file("link.cir");
//   if (!n) { std::cerr << n.status().message() << "\n"; return 2; }   // file:line:col: error: ...
//   for (const std::string& w : n->warnings) std::cerr << w << "\n";
//   for (const Card& c : n->cards) { const ElementKind* k = find_element_kind(c.letter); ... }
//
// See netlists/README.md for the supported subset.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"
#include "solver/card.h"

namespace isolink {

// .tran TSTEP TSTOP [TSTART [TMAX]] [UIC]
struct TranSpec {
  double tstep = 0, tstop = 0, tstart = 0, tmax = 0;  // tmax 0: not given
  bool uic = false;
  SourceLoc loc;  // the .tran card
};

// One entry of .options / .option: key=value (value a Number, or a lower-case Word), or a bare
// flag (value: Word with an empty word). The solver applies the ones it knows; the CLI warns
// about the others.
struct NetlistOption {
  std::string key;  // lower case
  CardArg value;
  SourceLoc loc;  // the key
};

// .ic v(NODE)=VALUE: without UIC the node is held at VALUE while the DC operating point is
// solved (then released); with UIC it is the node's voltage at t = 0.
struct InitialVoltage {
  std::string node;  // flattened, lower case
  double value = 0;  // V
  SourceLoc loc;     // the v(...) entry
};

struct Netlist {
  std::string title;                             // first line of the top file, as written (trimmed)
  std::vector<Card> cards;                       // flattened elements, in netlist order
  std::optional<TranSpec> tran;                  // the last .tran card
  std::vector<NetlistOption> options;            // in netlist order
  std::vector<InitialVoltage> initial_voltages;  // .ic, in netlist order
  std::vector<std::string> warnings;  // formatted diagnostics ("file:line:col: warning: ...")
};

// Reads a netlist file; .include paths are relative to the including file.
StatusOr<Netlist> read_spice_file(const std::string& path);
// Reads netlist text; `name` is used in diagnostics and .include paths are relative to the
// current directory.
StatusOr<Netlist> read_spice_text(const std::string& text, const std::string& name = "<string>");

}  // namespace isolink
