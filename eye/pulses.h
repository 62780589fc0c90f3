// Pulse extraction (docs/physics.md section 8, rules 8.1-8.4): threshold excursions, merging across
// dips, ringing, transitions and frames.
//
// Usage:
//   SegmentParams p{.vth = 1.2, .merge_gap = 100e-9, .min_pulse = 100e-9, .transition_gap =
//   200e-9}; Segmentation seg = segment(w.time, w.columns[0], p); for (const FrameSpan& f :
//   seg.frames)  // pulses f.first..f.last joined by transitions
//     ...seg.pulses[f.first].a...
// Crossing times are linear interpolations between samples; a sample exactly at the threshold
// counts as past it (s * v >= vth).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace isolink::eye {

// A maximal interval where s * v >= vth.
struct Excursion {
  int sign = 0;             // +1 or -1
  double a = 0, b = 0;      // crossing into / out of the threshold (s)
  size_t ia = 0, ib = 0;    // first sample inside; first sample after (n when it runs to the end)
  double peak = 0;          // max of s * v
  double peak_t = 0;        // when
  bool open_start = false;  // already past the threshold at the first sample
  bool open_end = false;    // still past the threshold at the last sample
};

// The signal fell back below the threshold inside a pulse.
struct Dip {
  double start = 0, end = 0;  // b of the excursion before, a of the one after (s)
  double lowest = 0;          // min of s * v inside the dip (V)
  double lowest_t = 0;        // when
};

// A pulse: one excursion, or several of one sign merged across dips.
struct PulseSpan {
  int sign = 0;
  double a = 0, b = 0;     // start and end crossings (s)
  size_t ia = 0, ib = 0;   // sample range [ia, ib) between a and b
  double peak = 0;         // max of s * v
  double peak_t = 0;       // when
  std::vector<Dip> dips;   // empty for a clean pulse
  bool truncated = false;  // cut by the start or end of the record
};

// An excursion shorter than min_pulse: overshoot, not a pulse. Or (after_frame) the kickback of
// the line right after a complete frame (drop_frame_tail): allowed, inside the receiver's blanking.
struct Ringing {
  int sign = 0;
  double start = 0, end = 0;  // crossings (s)
  double peak = 0;            // max of s * v (V)
  double peak_t = 0;
  bool after_frame = false;  // the kickback after a frame's postamble, not a short excursion
};

// Pulses first..last (inclusive), each joined to the next by a transition.
struct FrameSpan {
  size_t first = 0, last = 0;
};

struct SegmentParams {
  double vth = 1.2;                // threshold (V)
  double merge_gap = 100e-9;       // same-sign excursions closer than this merge
  double min_pulse = 100e-9;       // shorter merged excursions are ringing
  double transition_gap = 200e-9;  // opposite pulse starting sooner than this after b joins
};

struct Segmentation {
  std::vector<PulseSpan> pulses;  // in time order
  std::vector<Ringing> ringing;   // in time order
  std::vector<bool> joined_next;  // joined_next[i]: a transition joins pulse i to pulse i + 1
  std::vector<FrameSpan> frames;  // runs of joined pulses; every pulse is in exactly one
};

// Contract of the functions below: t in seconds, v in volts (the differential at the pins); the
// spans are read during the call and not kept; the caller guarantees t strictly increasing, finite
// and the same size as v (check_samples checks it and returns an error; these do not).
// Rule 8.1: every excursion of either sign, in time order. t strictly increasing, same size as v.
std::vector<Excursion> find_excursions(std::span<const double> t, std::span<const double> v,
                                       double vth);
// Rules 8.1-8.4.
Segmentation segment(std::span<const double> t, std::span<const double> v, const SegmentParams& p);
// Rebuilds frames from pulses and joined_next.
void build_frames(Segmentation* seg);
// Rule 8.4a: pulse i is the line's kickback after a complete frame, not a pulse: it moves to
// ringing (after_frame), the pulse before it runs into idle, and the frames are rebuilt.
void drop_frame_tail(Segmentation* seg, size_t i);

}  // namespace isolink::eye
