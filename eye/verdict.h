// The verdict of a checked record (pass, fail or inconclusive) and its reasons, by one rule that
// every path forming a verdict shares: isolink check, run, worst, noise, Python's isolink.check
// (all through eye::check_samples) and any later command that judges a record (compare).
//
// Usage:
//   VerdictFacts f;
//   f.peak = 2.1;                          // largest |v| in the record (V)
//   f.decodes = structural > 0;            // data rules: a frame's couplets form a byte
//   f.runs = seg.frames.size();
//   f.failures = {"3 of 40 pulses fail"};  // measured: pulses, frames, bytes not as expected
//   f.open = {"the record cuts 1 pulse"};  // what keeps it from passing without a failure
//   Verdict v = decide_verdict(pulses, rules, f);
//   v.kind == VerdictKind::kFail;  v.reasons;  verdict_name(v.kind) == "fail"
//
// The rule (eye/README.md "Verdict" says the same in words):
// - inconclusive when the record cannot show the link: no pulses; levels over kImplausibleVth
//   thresholds (mV read as volts); or (data rules) no frame whose couplets form a byte and no
//   daisy-chain run (daisy_chain_run) whose pulses fail their rules (a sine, a square wave at
//   another rate, the wrong column, a record cut in the only frame, P and N swapped);
// - fail when it shows the link and something measured fails: a pulse, a frame, the bytes;
// - inconclusive when nothing fails but the record cuts a pulse (`open`);
// - pass otherwise.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "eye/metrics.h"
#include "eye/rules.h"

namespace isolink::eye {

// Levels over this many thresholds (120 V for the 1.2 V data threshold) are no daisy-chain
// signal: the units are wrong (mV read as V).
inline constexpr double kImplausibleVth = 100;

// A daisy-chain run: at least kChainRunPulses consecutive pulses, each followed by the opposite
// pulse of the same run (joined within the rules' transition gap, as frames are), each with a
// width (a to the next pulse's a') within [kChainWidthMin, kChainWidthMax] half bits T, and at
// least kChainRunSingles of them under kChainSingleMax * T (one half bit: every frame opens with
// the preamble and sync pulses + - + -, one half bit each). A square wave of 500 ns pulses (1
// MHz) or a sine slower than ~1.5 MHz (its edges take over 200 ns) makes none.
inline constexpr size_t kChainRunPulses = 8;
inline constexpr size_t kChainRunSingles = 4;
inline constexpr double kChainWidthMin = 0.5;
inline constexpr double kChainWidthMax = 2.5;
inline constexpr double kChainSingleMax = 1.5;

struct ChainRun {
  size_t first = 0;      // index of its first pulse
  size_t pulses = 0;     // pulses in it
  size_t singles = 0;    // of them, one half bit wide
  size_t failing = 0;    // of them, failing their rules
  double width_min = 0;  // s
  double width_max = 0;  // s
};
// The longest daisy-chain run among the pulses (in time order), if any.
std::optional<ChainRun> daisy_chain_run(std::span<const PulseMetrics> pulses, const Rules& rules);

enum class VerdictKind { kPass, kFail, kInconclusive };
const char* verdict_name(VerdictKind k);  // "pass", "fail", "inconclusive"

// What a check measured besides the pulses.
struct VerdictFacts {
  double peak = 0;                    // largest |v| in the record (V)
  bool decodes = true;                // data rules: some frame forms a byte (tone rules: true)
  size_t runs = 0;                    // runs of joined pulses (frames as segmented)
  std::vector<std::string> failures;  // measured failures, in words
  std::vector<std::string> open;      // what keeps it from a pass short of a failure (cut pulses)
};

struct Verdict {
  VerdictKind kind = VerdictKind::kInconclusive;
  std::vector<std::string> reasons;  // failures first, then what leaves it open; empty on pass
};

// A pure function of its inputs (read during the call, not kept): every input gives a verdict,
// there is no error. pulses in time order, as measure_pulses gives them.
Verdict decide_verdict(std::span<const PulseMetrics> pulses, const Rules& rules,
                       const VerdictFacts& facts);

}  // namespace isolink::eye
