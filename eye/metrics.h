// Eye metrics per pulse (docs/physics.md section 8, rules 8.5-8.11): width and class, edge time,
// VSTART / VEND / droop judged by the amplitude rule, idle undershoot, margins.
//
// Usage:
//   Segmentation seg = segment(t, v, segment_params(rules));
//   std::vector<PulseMetrics> pm = measure_pulses(t, v, seg, rules);
//   std::vector<IdleUndershoot> idle = find_idle_undershoots(t, v, seg, rules);
//   std::vector<WorstMargin> worst = worst_margins(pm);   // one per metric, smallest margin
// Margins are distances to the limit, positive = inside; NaN where a metric does not apply.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <experimental/simd>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "eye/pulses.h"
#include "eye/rules.h"

namespace isolink::eye {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Half bits a single pulse may carry into decoding (a frame has 26 with SOF): a longer pulse is
// decoded as this many, which breaks the frame just the same, so memory never grows with the
// pulse's length.
constexpr int kMaxHalfBits = 64;

// One judged quantity.
struct Judged {
  double value = kNaN;   // the measurement (s or V)
  double limit = kNaN;   // the limit it was judged against (the nearer one for a window)
  double margin = kNaN;  // distance to the limit, positive = inside
  bool measured() const { return !std::isnan(value); }
  bool judged() const { return !std::isnan(margin); }
};

struct PulseMetrics {
  size_t index = 0;          // position in time order
  int sign = 0;              // +1 / -1
  double a = 0, b = 0;       // start and end crossings (s)
  bool idle = false;         // no transition after it: runs into idle (width = b - a, not judged)
  bool truncated = false;    // cut by the record: nothing judged
  int k = 0;                 // class round(width / T)
  int half_bits = 0;         // half bits it carries for decoding (1..kMaxHalfBits)
  Judged width;              // thigh / tlow (s)
  Judged edge;               // trise / tfall into this pulse (s); not measured for a frame's first
  Judged vstart;             // max of s*v over [a, (a+b)/2] (V)
  Judged vend;               // s*v at b - vend_offset (V)
  Judged droop;              // vstart - vend (V); over droop_max is a warning
  std::vector<Dip> dips;     // each one fails the pulse
  bool timing_fail = false;  // width / class / edge outside the rules
  bool weak_fail = false;    // dip, VSTART or VEND outside the rules
  std::vector<std::string> fails;     // "metric: what" per broken rule
  std::vector<std::string> warnings;  // "metric: what" per warning
  int frame = -1;                     // decoded frame (byte) it belongs to, -1 = none
  std::string role;                   // its place in the frame ("preamble", "bit 3", ...)

  bool failing() const { return !fails.empty(); }
};

// After a frame's last pulse (sign s) returned, s*v above idle.level within tblank.
struct IdleUndershoot {
  size_t after_pulse = 0;     // the frame's last pulse
  int sign = 0;               // = that pulse's sign
  double start = 0, end = 0;  // crossings of the level (s)
  double peak = 0;            // max of s*v (V)
  double peak_t = 0;
};

// The smallest margin of one metric over all pulses, and where.
struct WorstMargin {
  std::string metric;  // "vstart", "vend", "width", "edge", "droop"
  Judged j;            // value, limit, margin
  size_t pulse = 0;    // pulse index
  double time = 0;     // pulse start a (s)
  int frame = -1;      // decoded frame index, -1 = none
  std::string role;    // place in the frame
};

// Contract of the functions below: t in seconds, v in volts, the spans read during the call and
// not kept; seg must come from segment() over the same t and v (its indices point into them), t
// strictly increasing and finite (check_samples checks; these do not). No errors: every pulse
// gets its metrics, NaN where one is undefined (no edge before the first pulse).
SegmentParams segment_params(const Rules& r);
// The largest f(v[j]) over j in [lo, hi), at least `floor`, taken a SIMD register of samples at
// a time (std::experimental::simd): the eye check's per-sample loops. f maps a double and a
// register alike (written with auto and operators, or abs found by lookup).
template <class F>
double running_max(std::span<const double> v, size_t lo, size_t hi, double floor, F f) {
  namespace stdx = std::experimental;
  using V = stdx::native_simd<double>;
  V m = floor;
  size_t j = lo;
  for (; j + V::size() <= hi; j += V::size())
    m = stdx::max(m, f(V(v.data() + j, stdx::element_aligned)));
  double out = stdx::hmax(m);
  for (; j < hi; ++j) out = std::max(out, f(v[j]));
  return out;
}
// Rule 8.5: the half bits pulse i of seg carries for decoding (PulseMetrics::half_bits).
int pulse_half_bits(const Segmentation& seg, size_t i, const Rules& r);
// Rules 8.5-8.9 for every pulse of seg.
// warning_texts false: PulseMetrics::warnings left empty (CheckOptions::warning_texts).
std::vector<PulseMetrics> measure_pulses(std::span<const double> t, std::span<const double> v,
                                         const Segmentation& seg, const Rules& r,
                                         bool warning_texts = true);
// Rule 8.10, after every frame.
std::vector<IdleUndershoot> find_idle_undershoots(std::span<const double> t,
                                                  std::span<const double> v,
                                                  const Segmentation& seg, const Rules& r);
// Rule 8.11: per metric (vstart, vend, width, edge, droop) the judged pulse with the smallest
// margin; metrics nothing was judged on are left out.
std::vector<WorstMargin> worst_margins(const std::vector<PulseMetrics>& pulses);

}  // namespace isolink::eye
