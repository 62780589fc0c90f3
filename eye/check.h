// The eye checker: a waveform and a rule set in, a verdict with margins, decoded bytes, JSON and a
// text summary out. Every checker path (isolink check, isolink run, sweeps) goes through here.
//
// Usage:
//   StatusOr<Rules> rules = load_rules("bq7961x");
//   StatusOr<Waveform> w = read_differential_csv("wave.csv");
//   CheckOptions opt;  opt.expect = *parse_hex_bytes("80 00 02 15 0B CB 49");
//   StatusOr<CheckResult> r = check_waveform(*w, *rules, opt);
//   std::puts(summary_text(*r).c_str());        // for people
//   std::string j = to_json(*r).dump(2);        // machine readable (names are stable)
//   Status s = write_pulses_csv(*r, "pulses.csv");
//   return r->pass ? 0 : 1;
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
#include "eye/metrics.h"
#include "eye/pulses.h"
#include "eye/rules.h"
#include "protocol/command_frames.h"
#include "protocol/frame.h"

namespace isolink::eye {

// Overrides of the rule set's decoding options, and the bytes expected.
struct CheckOptions {
  std::optional<bool> sof;                     // SOF bit present
  std::optional<int> sof_value;                // its value
  std::optional<BitOrder> bit_order;           // LSB / MSB first
  std::optional<std::vector<uint8_t>> expect;  // compare the decoded bytes with these
  // false: the pulses' warnings (PulseMetrics::warnings: droop) are left out, their numbers kept,
  // for a search that reads only numbers (the worst case: formatting one droop warning per pulse
  // was 8 % of its time). Failures and the verdict are the same either way.
  bool warning_texts = true;
  // The decoded bytes are parsed as TI's command and response frames (eye/commands.h); an idle
  // longer than this between two bytes ends a frame (protocol/command_frames.h, rule 1).
  double command_idle = FrameSplitOptions{}.max_idle_s;
  bool commands = true;  // false: not parsed (CheckResult::commands empty), for number searches
};

// One decoded byte (a frame), or a run of pulses that did not decode.
struct FrameResult {
  double start = 0;        // its preamble's start (s)
  size_t first_pulse = 0;  // pulses first_pulse..last_pulse
  size_t last_pulse = 0;
  std::optional<uint8_t> byte;  // null when it did not decode (or for tone rules)
  bool error_bit = false;       // the byte-error bit was set
  std::string fault;            // "" or "sync", "timing", "weak bit", "length", "truncated"
  std::string detail;           // the fault in words
  bool fails() const { return !fault.empty() && fault != "truncated"; }
};

struct CheckResult {
  std::string rules;                           // rule set name
  std::string rules_source;                    // where it came from
  bool tone = false;                           // tone rules: nothing is decoded
  FrameFormat frame_format;                    // decoding options in effect
  bool pass = false;                           // the verdict
  bool inconclusive = false;                   // no verdict (eye/verdict.h says when)
  std::vector<std::string> reasons;            // why it fails / is inconclusive (empty on pass)
  std::vector<std::string> hints;              // what to check when the data look misread
  size_t samples = 0;                          // samples in the waveform
  double t_begin = 0, t_end = 0;               // its time span (s)
  std::vector<PulseMetrics> pulses;            // in time order
  std::vector<Ringing> ringing;                // warnings
  std::vector<IdleUndershoot> idle;            // warnings
  std::vector<FrameResult> frames;             // decoded bytes / runs, in time order
  std::vector<uint8_t> bytes;                  // all decoded bytes in order
  std::optional<std::vector<uint8_t>> expect;  // the bytes expected, when given
  bool expect_match = true;                    // decoded bytes == expected (true when none given)
  std::string expect_detail;                   // first difference, in words
  std::vector<WorstMargin> worst;              // per metric, the smallest margin
  std::vector<ParsedFrame> commands;           // the frames the bytes carry (none for tones)

  size_t failing() const;                    // pulses that fail
  std::optional<double> vstart_min() const;  // over all measured pulses (V)
  std::optional<double> vend_min() const;    // over all measured pulses (V)
  std::optional<double> width_min() const;   // over pulses ending in an opposite edge (s)
  std::optional<double> width_max() const;   // same (s)
  std::optional<double> edge_max() const;    // over all edges (s)
  const char* verdict() const { return pass ? "pass" : inconclusive ? "inconclusive" : "fail"; }
};

// Checks time/value samples against rules: t in seconds, strictly increasing; v the differential
// V(P) - V(N) at the receiver pins in volts; both only read during the call (the result owns
// copies of what it reports). The verdict is formed by
// eye/verdict.h's decide_verdict (one rule for every path): fail when the record shows the link
// (a frame forms a byte, or a daisy-chain run) and something measured fails; "inconclusive"
// (pass = false, inconclusive = true) when it cannot show the link (no pulses, levels 100x off,
// nothing decoded and no daisy-chain run of failing pulses) or nothing fails but a pulse is cut;
// hints follow when the samples look like the wrong units, the wrong column or swapped P and N.
// A failing link is a result (pass = false), not an error. Errors (nothing measured): t and v of
// different sizes, fewer than two samples, a non-finite sample, time not increasing (the message
// names the sample), rules that do not pass validate_rules, a command_idle that is not a finite
// time >= 0, a SOF value other than 0 or 1. Thread-safe: no shared state.
StatusOr<CheckResult> check_samples(std::span<const double> t, std::span<const double> v,
                                    const Rules& rules, const CheckOptions& opt = {});
// Checks column `column` of w (its time axis in s, the column in V); an error, besides
// check_samples' own, when w has no such column.
StatusOr<CheckResult> check_waveform(const Waveform& w, const Rules& rules,
                                     const CheckOptions& opt = {}, size_t column = 0);

// The JSON object, keys in a fixed order (verdict, reasons, rules, ..., summary, pulses, ringing,
// idle, decoded, commands, commands_omitted, commands_note).
// Pulses (and ringing, idle undershoots) listed in detail are capped at kMaxJsonPulses each;
// "pulses_omitted" counts the pulses left out (write_pulses_csv has every one).
inline constexpr size_t kMaxJsonPulses = 10'000;
nlohmann::ordered_json to_json(const CheckResult& r);
// A few lines for people: verdict, worst margin per metric with place, counts, failures.
std::string summary_text(const CheckResult& r, const std::string& source = "");
// The per-pulse table as CSV (times in s, levels in V), written to a temp file then renamed
// (base/file_io.h): on an error (the folder cannot be written) path is left as it was.
Status write_pulses_csv(const CheckResult& r, const std::string& path);

}  // namespace isolink::eye
