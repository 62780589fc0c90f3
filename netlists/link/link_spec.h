// Link specs: a daisy-chain hop described as an isolation BOM in YAML (the engineer's view),
// read into plain structs with every default drawn from docs/physics.md section 4.
//
//   StatusOr<LinkSpec> spec = read_link_spec_file("netlists/examples/transformer_15m.yaml");
//   if (!spec) return spec.status();          // "file:line:col: error: key 'cable.length' ..."
//   // then expand_link(*spec, parts, Direction::kDown) (expand.h) gives the circuit.
// Keys (netlists/link/README.md has the full table):
//   name, tx / rx: {device, series_r, bypass_c, termination, isolation: {type, cap, chokes,
//   part, inductance, leakage, dcr, winding_c, centre_tap_c, cable_side_c, esd}},
//   cable: {length, material, gauge, temperature, r, l, c, g, segments},
//   stimulus: {frames, gaps, tones, patterns, script, direction}, sim: {tstep, tmax, method,
//   reltol}, noise: {injection, level, position, modulation, band, points_per_decade,
//   pin_limit, time_domain, samples, seed, verdict_on, tolerance: {...}} (isolink noise),
//   stress: {esd, ground_step, ground_rise, hot_plug_v, hot_plug_gap, wave_v, wave_f, wave_shape,
//   wave_dvdt, leak_ohms, pin_abs_max, pin_cm_limit, cap_rating, only}
//   (isolink stress; tx / rx
//   also take x_cap, y_cap, chassis_c, chassis_r, chassis_l, isolation.cable_side_return,
//   isolation.choke_loss, and cable chassis_c).
// `tx` is the end that transmits in the down direction (the host / bridge side); `rx` the end
// that receives it. With direction up (or both) the rx end transmits back to the tx end.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"
#include "config/yaml_reader.h"
#include "netlists/link/cable.h"

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
  // Where the cable-side caps return when the grounds are kept apart (isolink noise): "board"
  // (the end's board ground, TI's figure draws a ground symbol) or "chassis".
  std::string cable_side_return = "board";
  // The chokes' loss: "fitted" (the part's loss resistor, fitted to its data sheet's CM impedance
  // at the rated frequency), "none" (lossless), or a resistance across each winding (choke_loss_r).
  std::string choke_loss = "fitted";
  double choke_loss_r = 0;  // ohm, when choke_loss is "resistance"
  double esd = 0;           // F per line to ground (ESD part as a capacitance), 0: none
  std::string esd_part;     // or a TVS part number (nonlinear: diodes), "" when not
  SourceLoc esd_loc;        // where `esd` is written
  SourceLoc loc;            // the isolation map (or its end)
};

struct EndSpec {
  std::string device = "bq7961x";     // bq79600 | bq7961x | bq79606a
  std::optional<double> series_r;     // ohm per line (board preset's when absent)
  std::optional<double> bypass_c;     // F per line
  std::optional<double> termination;  // ohm, differential
  IsolationSpec isolation;
  double x_cap = 0;         // F across the lines at the connector (X capacitor), 0: none
  double y_cap = 0;         // F per line to the chassis at the connector (Y caps), 0: none
  double chassis_c = 1e-9;  // F, the board's ground (and its module) to the chassis;
                            // used when the grounds are kept apart (isolink noise)
  double chassis_r = 0;     // ohm, a DC bond of the board's ground to the chassis (strap,
                            // screw) in parallel with chassis_c; 0: none (the board floats)
  double chassis_l = 0;     // H, the bond's inductance, in series with chassis_r
  // The device pins' internal ESD clamps: "none" (linear pins, the default) or "rails" (a diode
  // from each COM pin to CVDD and one from CVSS to it: nonlinear, netlists/link/pins.h).
  std::string pin_clamps = "none";
  SourceLoc pin_clamps_loc;
  SourceLoc loc;
};

enum class Direction { kDown, kUp };
const char* direction_name(Direction d);  // "down" | "up"

struct StimulusSpec {
  std::vector<std::string> frames;    // command texts (traffic/command.h)
  std::vector<std::string> tones;     // tone items ("wake", "fault couplets=4")
  std::vector<std::string> patterns;  // pattern items ("prbs7 bytes=32")
  std::string script;                 // a stimulus script (traffic/stimulus.h), after the above
  std::vector<double> gaps;           // s, the idle before each frame (empty: lead / frame gap)
  std::vector<Direction> directions{Direction::kDown, Direction::kUp};
  SourceLoc loc;
  // The stimulus script of all items: tones, then frames, then patterns, then script.
  std::string to_script() const;
};

struct SimSpec {
  double tstep = 1e-9;          // s, output resolution
  std::optional<double> tmax;   // s, largest internal step
  std::string method = "trap";  // trap | gear
  std::optional<double> reltol;
};

// Part tolerances the noise analysis takes its worst case over (fractions, +/-): each P and N
// part moves on its own (isolink noise; analysis/README.md has the sources of the defaults).
struct NoiseTolerances {
  double isolation_cap = 0.10;    // isolation caps (Knowles 1206J2K00222KXR: K = 10 %)
  double series_r = 0.01;         // series resistors (1 % thick film)
  double bypass_c = 0.10;         // board bypass caps (C0G/X7R, 10 %)
  double y_cap = 0.10;            // Y caps and cable-side caps (CBYPASS2)
  double esd = 0.20;              // ESD parts' capacitance
  double winding_c = 0.20;        // choke winding and transformer inter-winding capacitance halves
  double choke_imbalance = 0.01;  // each choke winding's inductance (winding imbalance)
  double cable_chassis_c = 0.02;  // each conductor's capacitance to the chassis (twist, routing)
  double rx_pin = 0.05;           // receiver input R and C per pin
};

// The `noise:` block: what is injected, how hard, over which band (isolink noise).
struct NoiseSpec {
  std::string injection = "bci";      // bci | ground_shift | dm
  double level = 0.1;                 // A (bci, dm: RMS of the CW carrier) or V (ground_shift: RMS)
  double position = 0.5;              // bci, dm: place on the cable, fraction of its length from tx
  std::string modulation = "am";      // cw | am (ISO 11452-4 AM: 80 % at 1 kHz, peak 1.8 x carrier)
  double f_start = 1e6;               // Hz, `noise.band` (bci, dm: ISO 11452-4's 1-400 MHz;
  double f_stop = 400e6;              // Hz   ground_shift: 100 kHz-400 MHz)
  int points_per_decade = 10;         // log-spaced
  double calibration_r = 100;         // ohm: bci / dm induce level x this in series (ISO 11452-4
                                      // calibration jig: 50 ohm line, 50 ohm at each end)
  double clamp_r = 50;                // ohm: the clamp's source impedance in the loop (the
                                      // generator's 50 ohm through the 1:1 probe)
  double pin_limit = 20;              // V, receiver pins' common-mode limit (docs/physics.md 2)
  bool time_domain = true;            // confirm the worst frequency with a transient + the checker
  int samples = 200;                  // Monte Carlo boards over the tolerances (uniform in each)
  int seed = 1;                       // their random seed
  std::string verdict_on = "corner";  // corner | statistical: which immunity the verdict uses
  NoiseTolerances tolerance;
  SourceLoc loc;
  // "A" or "V".
  const char* level_unit() const { return injection == "ground_shift" ? "V" : "A"; }
};

// The `stress:` block: the levels of isolink stress's scenarios and the limits it checks against
// (analysis/stress.h; netlists/link/README.md "stress" has the table with the sources).
struct StressSpec {
  double esd_v = 8e3;        // V, IEC 61000-4-2 contact discharge (level 4: +-8 kV)
  double step_v = 60;        // V, module ground step (issue 41's contactor experiment)
  double step_rise = 1e-6;   // s, its 0-100 % rise
  double pin_abs_max = 20;   // V, |COM pin to its device ground| (assumed: see README)
  double pin_cm_limit = 20;  // V, |pin common mode to its device ground| (docs/physics.md 2)
  double cap_rating = 2e3;   // V, isolation caps (1206J2K00222KXR: 2 kV)
  // hot_plug: the plugged module's potential to the chassis (a link spec has no module voltage:
  // 60 V, issue 41's module) and the time between its two lines' contacts (any gap longer than
  // the first contact's settling gives the same peaks; real ones are 0.1-1 ms).
  double hot_plug_v = 60;      // V
  double hot_plug_gap = 5e-6;  // s
  // cm_wave: the inverter's disturbance on the transmitting module's ground (assumed: see
  // docs/stress.md): peak-to-peak V, frequency, shape, the square's edge rate.
  double wave_v = 50;                 // V, 0 to wave_v
  double wave_f = 20e3;               // Hz
  std::string wave_shape = "square";  // square | sine
  double wave_dvdt = 2;               // V/ns, the square's edges
  // wire: a damaged port's pin leaking to its device ground (assumed: 1 kohm).
  double leak_ohms = 1e3;
  std::vector<std::string> only;  // scenario kinds to run (empty: all): stress_kinds()
  SourceLoc loc;
  bool given = false;  // the spec has a stress: block
};

struct LinkSpec {
  std::string name = "link";
  std::string source;  // the file it was read from
  EndSpec tx, rx;
  CableSpec cable;
  SourceLoc cable_loc;
  StimulusSpec stimulus;
  SimSpec sim;
  NoiseSpec noise;
  StressSpec stress;
};

// Reads a spec; errors name the file, line, column and key.
StatusOr<LinkSpec> read_link_spec_file(const std::string& path);
StatusOr<LinkSpec> read_link_spec_text(const std::string& text, const std::string& name);
// Reads a spec from a parsed document (sweeps edit the tree, then read it).
StatusOr<LinkSpec> read_link_spec(const config::YamlDoc& doc);

// The spec's nonlinear parts, in words with their keys ("tx.isolation.esd: TVS PESD2CAN",
// "rx.pin_clamps: rails"); empty for a linear link. Analyses that superpose responses (worst,
// the sweep's fast path, compare) or linearise (noise) refuse or step aside on them.
std::vector<std::string> nonlinear_parts(const LinkSpec& spec);
// "" for a linear link, else why `what` (e.g. "the worst case") cannot take it, naming the parts
// and the way out.
std::string linear_only(const LinkSpec& spec, const std::string& what);

// The scenario kinds of `stress.only` and `isolink stress --only`: "cm_step", "cm_wave", "esd",
// "hot_plug", "wire".
const std::vector<std::string>& stress_kinds();

// Devices and their receiver rule sets: bq79600 -> bq79600 (bridge), bq7961x and bq79606a ->
// bq7961x.
std::vector<std::string> device_names();
std::string device_rules(const std::string& device);

}  // namespace isolink::link
