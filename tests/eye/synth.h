// Synthetic daisy-chain waveforms for the eye tests: trapezoid pulse trains with set edges,
// linear or exponential droop, plus additive overlays (dips, ringing, idle undershoot) and noise.
//
// Every edge has the slope of a full swing -V..+V in `tr`, centred on the half-bit boundary; a
// frame's first edge rises from 0 at its boundary and its last edge falls to 0 at its boundary, so
// threshold crossings sit where a full-swing edge would put them. With V = 2 V and tr = 20 ns the
// +/-1.2 V crossings are 6 ns after each boundary: widths are exactly k*T and edges 0.6*tr.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "base/waveform.h"
#include "protocol/frame.h"

namespace synth {

struct Pt {
  double t, v;
};

// Piecewise linear, zero outside [first, last] point unless hold_ends.
struct Pwl {
  std::vector<Pt> pts;
  void add(double t, double v) { pts.push_back({t, v}); }
  double at(double t) const {
    if (pts.empty() || t <= pts.front().t || t >= pts.back().t) return 0.0;
    size_t lo = 0, hi = pts.size() - 1;
    while (hi - lo > 1) {
      size_t mid = (lo + hi) / 2;
      (pts[mid].t <= t ? lo : hi) = mid;
    }
    const Pt& a = pts[lo];
    const Pt& b = pts[hi];
    if (b.t == a.t) return b.v;
    return a.v + (t - a.t) / (b.t - a.t) * (b.v - a.v);
  }
};

struct Pulse {
  int sign = +1;
  int k = 1;            // half bits
  double vstart = 2.0;  // level at the top of the leading edge (V)
  double vend = 2.0;    // level where the droop ends (V), held for `hold` before the trailing edge
  double shift = 0;     // moves the boundary after this pulse (s)
  double tau = 0;       // > 0: exponential droop vstart * exp(-(t - t_top) / tau) (vend unused)
};

struct Train {
  double t0 = 1e-6;     // first boundary (s)
  double T = 250e-9;    // half bit (s)
  double tr = 20e-9;    // full-swing edge time (s)
  double hold = 30e-9;  // flat at vend before each trailing edge (s)
  double dt = 1e-9;     // sampling step used for exponential droop points (s)
  std::vector<Pulse> pulses;

  // Boundary before pulse j (j = pulses.size(): the end of the run).
  double boundary(size_t j) const {
    double b = t0;
    for (size_t i = 0; i < j; ++i) b += pulses[i].k * T;
    if (j > 0 && j <= pulses.size()) b += pulses[j - 1].shift;
    return b;
  }
  double end() const { return boundary(pulses.size()); }
};

// Same-sign neighbours merge into one pulse of k half bits.
inline std::vector<Pulse> pulses_from_half_bits(const std::vector<int>& hb, double amp = 2.0) {
  std::vector<Pulse> out;
  for (int s : hb) {
    if (!out.empty() && out.back().sign == s) {
      ++out.back().k;
    } else {
      Pulse p;
      p.sign = s;
      p.vstart = p.vend = amp;
      out.push_back(p);
    }
  }
  return out;
}

inline double end_level(const Pulse& p, double t_top, double t_end) {
  return p.tau > 0 ? p.vstart * std::exp(-(t_end - t_top) / p.tau) : p.vend;
}

// Appends the train's points to w (in time order after what is there).
inline void append_train(Pwl& w, const Train& tr) {
  const double h = tr.tr / 2;
  for (size_t j = 0; j < tr.pulses.size(); ++j) {
    const Pulse& p = tr.pulses[j];
    const double b0 = tr.boundary(j), b1 = tr.boundary(j + 1);
    const int s = p.sign;
    const double t_top = b0 + h;
    // lead-in: from 0 (first pulse) or from the previous pulse's end level
    if (j == 0) w.add(b0, 0.0);
    w.add(t_top, s * p.vstart);
    const double t_flat_end = b1 - h;
    if (p.tau > 0) {
      for (double t = t_top + tr.dt; t < t_flat_end; t += tr.dt)
        w.add(t, s * p.vstart * std::exp(-(t - t_top) / p.tau));
      w.add(t_flat_end, s * end_level(p, t_top, t_flat_end));
    } else {
      w.add(t_flat_end - tr.hold, s * p.vend);
      w.add(t_flat_end, s * p.vend);
    }
    if (j + 1 == tr.pulses.size()) w.add(b1, 0.0);
  }
}

// Samples base + overlays (+ uniform noise of +/- noise V from a fixed-seed generator) on
// t = 0, dt, ... <= t_end.
inline isolink::Waveform sample(const Pwl& base, double dt, double t_end,
                                const std::vector<Pwl>& overlays = {}, double noise = 0.0) {
  isolink::Waveform w;
  std::vector<double> v;
  const size_t n = static_cast<size_t>(std::llround(t_end / dt)) + 1;
  w.time.reserve(n);
  v.reserve(n);
  uint64_t state = 0x9E3779B97F4A7C15ull;
  size_t seg = 0;
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    // walk the base (monotone in t) for speed
    double x = 0.0;
    const auto& p = base.pts;
    while (seg + 1 < p.size() && p[seg + 1].t <= t) ++seg;
    if (!p.empty() && t > p.front().t && seg + 1 < p.size()) {
      const Pt& a = p[seg];
      const Pt& b = p[seg + 1];
      x = b.t == a.t ? b.v : a.v + (t - a.t) / (b.t - a.t) * (b.v - a.v);
    }
    for (const Pwl& o : overlays) x += o.at(t);
    if (noise > 0) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double u = static_cast<double>(state >> 11) / 9007199254740992.0;  // [0, 1)
      x += noise * (2 * u - 1);
    }
    w.time.push_back(t);
    v.push_back(x);
  }
  w.add_column("v", std::move(v));
  return w;
}

// Bytes -> one ideal waveform: one frame per byte, frames `gap` apart.
inline isolink::Waveform ideal_frames(const std::vector<uint8_t>& bytes,
                                      const isolink::FrameFormat& fmt, double gap = 2e-6,
                                      double dt = 1e-9) {
  Pwl w;
  double t0 = 1e-6;
  Train last;
  for (uint8_t b : bytes) {
    Train tr;
    tr.t0 = t0;
    tr.pulses = pulses_from_half_bits(isolink::frame_half_bits(b, fmt));
    append_train(w, tr);
    t0 = tr.end() + gap;
  }
  return sample(w, dt, t0);
}

}  // namespace synth
