// Pack specs: a whole battery pack's daisy chain in YAML, read into one link spec per hop.
//
//   StatusOr<PackSpec> pack = read_pack_spec_file("netlists/examples/pack/pack_16.yaml");
//   if (!pack) return pack.status();          // "pack.yaml:12:5: error: key 'cable.lenght' ..."
//   for (const HopSpec& h : pack->hops) ... h.spec (a link::LinkSpec) ...
//   // then run_pack (analysis/pack.h).
//
// The file (the README's section "Packs" has the full description):
//   name: pack-16                     # names the report folder
//   bridge: bq79600                   # the host-side device (the BQ79600 bridge)
//   stack: bq7961x                    # the stack devices: bq7961x | bq79606a
//   stimulus: {frames: [...]}         # the pack's traffic: replaces every hop spec's stimulus
//   hops:                             # chain order from the bridge up: hop k joins device k-1
//     - spec: bridge_hop.yaml         #   (0 = the bridge) to device k, so N hops = N devices
//     - {spec: module.yaml, cable: {length: 2.5}}   # overrides under the link spec's own keys
//     - {spec: module.yaml, repeat: 6}              # 6 identical hops in a row
//     - spec: {tx: {...}, rx: {...}, cable: {length: 0.05}}   # an inline link spec
//   ring: true                        # the top device's COMH is wired back to the bridge's COML
//   ring_return: {spec: return.yaml}  # the return hop (needed with ring: true)
//   timing: {timeout: 1m, bridge_delay: 12u, device_delay: 3u, uart_byte: 10.3u,
//            chain_byte: 6.5u, response_delay: 0}
// Overrides merge key by key into the hop's spec (config::YamlDoc::merge): maps merge, values and
// lists replace. Each hop's `tx` end is the device nearer the bridge (it transmits commands in
// the link spec's "down" direction), `rx` the one above; the return hop's `tx` is the bridge,
// its `rx` the top device. A hop spec that leaves an end's device out gets the pack's (bridge or
// stack); one that names a different device is an error. Errors name the file, line and column
// of the key, whether it sits in the hop spec or in the pack file.
//
// Contract:
// - Units: as in link specs (SI, the config/ suffixes); timing in s.
// - Ownership: a PackSpec owns its hop specs (each a complete link::LinkSpec); nothing refers back
//   to the files read.
// - Errors: a Status, never thrown, with the file, line and column of the key at fault.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"
#include "config/yaml_reader.h"
#include "netlists/link/link_spec.h"

namespace isolink::analysis {

struct HopSpec {
  int index = 0;         // 1..N along the chain; N + 1 for the ring's return hop
  int from = 0, to = 0;  // devices at the tx and rx ends (0 = the bridge)
  bool ring_return = false;
  std::string file;     // the link spec file ("" when inline)
  link::LinkSpec spec;  // overrides applied
  SourceLoc loc;        // the entry in the pack file
};

// Command timing (docs/physics.md section 7); the README's section "Packs" derives the formulas.
struct TimingSpec {
  double bridge_delay = 12e-6;    // s, bridge byte delay including re-clock
  double device_delay = 3e-6;     // s, per stack device (re-clock)
  double uart_byte = 10.3e-6;     // s, one UART byte at 1 Mbps as the host sees it
  double chain_byte = 6.5e-6;     // s, one daisy-chain byte frame (13 bit times of 500 ns)
  double response_delay = 0;      // s, from a device having a read command to its first bit out
  std::optional<double> timeout;  // s, responses later than this are flagged
};

struct PackSpec {
  std::string name = "pack";
  std::string source;  // the pack file
  std::string bridge = "bq79600";
  std::string stack = "bq7961x";
  std::vector<HopSpec> hops;  // chain order; ring_return last when ring
  bool ring = false;
  TimingSpec timing;

  int devices() const;     // stack devices (N)
  int chain_hops() const;  // N (hops without the ring's return hop)
};

// An edit of one hop's link spec tree before it is read (sweeps over packs set keys this way):
// called with the hop's index (1..N, N + 1 for the ring's return hop) and its YAML tree, after
// the pack entry's overrides are merged.
using HopEdit = std::function<Status(int hop, config::YamlDoc& doc)>;

StatusOr<PackSpec> read_pack_spec_file(const std::string& path);
// The text of a pack file named name (hop spec paths are taken from name's folder).
StatusOr<PackSpec> read_pack_spec_text(const std::string& text, const std::string& name,
                                       const HopEdit& edit = {});
// Whether a parsed YAML file is a pack spec (a map with a `hops` key) rather than a link spec.
bool is_pack_spec(const config::YamlDoc& doc);

}  // namespace isolink::analysis
