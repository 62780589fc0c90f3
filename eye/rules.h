// Rule sets: every limit the eye checker judges against, from YAML (shipped or the user's own).
//
// Usage:
//   StatusOr<Rules> r = load_rules("bq7961x");          // a shipped name, or a path to a YAML file
//   if (!r) { fputs(r.status().message().c_str(), stderr); }  // "FILE:LINE: error: key: ..."
//   double vth = r->vth;
// Shipped sets (eye/rules/*.yaml, embedded at build time): bq7961x, bq79600 (bridge), tone.
// A user file may start with "base: bq7961x" and then override only the keys it names;
// without a base every key is required. Numbers take SPICE suffixes (250n, 4u).
// Every rule set is validated when it is loaded (validate_rules). Units: volts and seconds
// throughout (Rules' fields say which); a Rules is a plain value, copied freely.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"
#include "protocol/frame.h"

namespace isolink::eye {

// Allowed pulse class k = round(width / T) and its width window.
struct WidthWindow {
  int k = 1;         // class: 1 = single pulse, 2 = double pulse (two half bits)
  double min = 0.0;  // seconds
  double max = 0.0;  // seconds
};

enum class AmplitudeRule {
  kBq7961x,  // VEND >= vend_min; VEND <= vend_knee needs vstart_min_low_vend, else vstart_min
  kBridge,   // BQ79600: VSTART >= vstart_min and VEND >= vend_min
};

struct Rules {
  std::string name;                // e.g. "bq7961x"
  std::string description;         // one line for people
  std::string source;              // where it was read from (file path or "eye/rules/NAME.yaml")
  bool tone = false;               // kind: tone (no decoding) rather than data
  double vth = 1.2;                // receiver threshold, +/- (V)
  double pulse_time = 250e-9;      // T, one half bit (s)
  double merge_gap = 100e-9;       // same-sign excursions closer than this merge (a dip)
  double min_pulse = 100e-9;       // shorter excursions are ringing
  double transition_gap = 200e-9;  // opposite pulse starting sooner than this joins the frame
  double edge_max = 60e-9;         // trise / tfall limit
  double vend_offset = 20e-9;      // VEND is read at b - vend_offset
  std::vector<WidthWindow> width;  // allowed classes with their windows
  AmplitudeRule amplitude = AmplitudeRule::kBq7961x;  // which amplitude rule
  double vend_min = 1.2;                              // VEND below this fails (V)
  double vend_knee = 1.3;            // bq7961x: VEND above this needs only vstart_min
  double vstart_min = 1.6;           // VSTART minimum (V)
  double vstart_min_low_vend = 1.7;  // bq7961x: VSTART minimum when VEND <= vend_knee
  double droop_max = 1.0;            // VSTART - VEND above this is a warning
  double idle_level = 0.4;           // idle undershoot level (V)
  double tblank = 4e-6;              // idle watch time after a frame (s)
  FrameFormat frame;                 // decoding options (data rules only)

  // The VSTART a pulse with this VEND needs.
  double vstart_required(double vend) const;
  // The window for class k, or nullptr when k is not allowed.
  const WidthWindow* window(int k) const;
};

// The names of the shipped rule sets, sorted.
std::vector<std::string> builtin_rule_names();
// The YAML text of a shipped rule set ("" when there is none by that name).
std::string_view builtin_rule_text(std::string_view name);

// Parses and validates YAML text; source names the file in error messages. Errors: YAML syntax,
// an unknown or missing key, a value that is not a number with its unit, an unknown base, a
// limit validate_rules refuses; each as "SOURCE:LINE:COL: error: KEY: ...".
StatusOr<Rules> parse_rules(std::string_view yaml_text, const std::string& source);
// A shipped name (bq7961x, bq79600, tone) or a path to a YAML file. The shipped sets are parsed
// once and cached (thread-safe); a file is read each call (size-limited, base/file_io.h). Errors:
// neither a shipped name nor a readable file (the message lists the shipped names), or
// parse_rules' errors.
StatusOr<Rules> load_rules(const std::string& name_or_path);
// Checks every limit (vth > 0, min < max, ...); the message names the field, value and rule.
Status validate_rules(const Rules& r);

}  // namespace isolink::eye
