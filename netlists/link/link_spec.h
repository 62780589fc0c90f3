// Link specs: a daisy-chain hop described as an isolation BOM in YAML (the engineer's view),
// read into plain structs with every default drawn from domain.md.
//
//   StatusOr<LinkSpec> spec = read_link_spec_file("netlists/examples/xfmr_12m.yaml");
//   if (!spec) return spec.status();          // "file:line:col: error: key 'cable.length' ..."
//   // then expand_link(*spec, parts, Direction::kDown) (expand.h) gives the circuit.
// Keys (netlists/link/README.md has the full table):
//   name, tx / rx: {device, series_r, bypass_c, termination, isolation: {type, cap, chokes,
//   part, inductance, leakage, dcr, winding_c, centre_tap_c, cable_side_c, esd}},
//   cable: {length, material, gauge, temperature, r, l, c, g, segments},
//   stimulus: {frames, tones, patterns, script, direction}, sim: {tstep, tmax, method, reltol}.
// `tx` is the end that transmits in the down direction (the host / bridge side); `rx` the end
// that receives it. With direction up (or both) the rx end transmits back to the tx end.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "config/yaml_reader.h"
#include "netlists/link/cable.h"
#include "base/source_loc.h"
#include "base/status.h"

namespace isolink::link {

struct IsolationSpec {
  std::string type = "cap";            // none | cap | capchoke | transformer | transformer_choke
  double cap = 2.2e-9;                 // F per line (cap, capchoke)
  std::vector<std::string> chokes;     // part numbers, in order from the device to the cable
  std::string part;                    // transformer part number ("" with explicit values)
  std::optional<double> inductance;    // H, transformer OCL (overrides the part's)
  std::optional<double> leakage;       // H, other winding shorted
  std::optional<double> dcr;           // ohm per winding
  std::optional<double> winding_c;     // F
  std::optional<double> centre_tap_c;  // F, cable-side centre tap to ground
  double cable_side_c = -1;            // F per line to ground on the cable side (-1: default)
  double esd = 0;                      // F per line to ground (ESD part), 0: none
  SourceLoc loc;                       // the isolation map (or its end)
};

struct EndSpec {
  std::string device = "bq7961x";      // bq79600 | bq7961x | bq79606a
  std::optional<double> series_r;      // ohm per line (board preset's when absent)
  std::optional<double> bypass_c;      // F per line
  std::optional<double> termination;   // ohm, differential
  IsolationSpec isolation;
  SourceLoc loc;
};

enum class Direction { kDown, kUp };
const char* direction_name(Direction d);  // "down" | "up"

struct StimulusSpec {
  std::vector<std::string> frames;    // command texts (traffic/command.h)
  std::vector<std::string> tones;     // tone items ("wake", "fault couplets=4")
  std::vector<std::string> patterns;  // pattern items ("prbs7 bytes=32")
  std::string script;                 // a stimulus script (traffic/stimulus.h), after the above
  std::vector<Direction> directions{Direction::kDown, Direction::kUp};
  SourceLoc loc;
  // The stimulus script of all items: tones, then frames, then patterns, then script.
  std::string to_script() const;
};

struct SimSpec {
  double tstep = 1e-9;                // s, output resolution
  std::optional<double> tmax;         // s, largest internal step
  std::string method = "trap";        // trap | gear
  std::optional<double> reltol;
};

struct LinkSpec {
  std::string name = "link";
  std::string source;                 // the file it was read from
  EndSpec tx, rx;
  CableSpec cable;
  SourceLoc cable_loc;
  StimulusSpec stimulus;
  SimSpec sim;
};

// Reads a spec; errors name the file, line, column and key.
StatusOr<LinkSpec> read_link_spec_file(const std::string& path);
StatusOr<LinkSpec> read_link_spec_text(const std::string& text, const std::string& name);
// Reads a spec from a parsed document (sweeps edit the tree, then read it).
StatusOr<LinkSpec> read_link_spec(const config::YamlDoc& doc);

// Devices and their receiver rule sets: bq79600 -> bq79600 (bridge), bq7961x and bq79606a ->
// bq7961x.
std::vector<std::string> device_names();
std::string device_rules(const std::string& device);

}  // namespace isolink::link
