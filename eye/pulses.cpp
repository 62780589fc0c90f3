#include "eye/pulses.h"

#include <algorithm>

namespace isolink::eye {
namespace {

// A pulse span reported as ringing (or, after_frame, as the kickback after a frame).
Ringing ringing_of(const PulseSpan& ps, bool after_frame) {
  return Ringing{ps.sign, ps.a, ps.b, ps.peak, ps.peak_t, after_frame};
}

// Time where the segment (t0, x0)-(t1, x1) crosses level.
inline double cross(double t0, double x0, double t1, double x1, double level) {
  return t0 + (level - x0) / (x1 - x0) * (t1 - t0);
}

}  // namespace

std::vector<Excursion> find_excursions(std::span<const double> t, std::span<const double> v,
                                       double vth) {
  std::vector<Excursion> out;
  const size_t n = std::min(t.size(), v.size());
  if (n == 0) return out;
  int state = 0;
  Excursion cur;
  // One sample of the state machine: a change of state closes or opens an excursion.
  auto step = [&](size_t i) {
    const double x = v[i];
    const int st = x >= vth ? 1 : (x <= -vth ? -1 : 0);
    if (st != state) {
      if (state != 0) {
        cur.b = cross(t[i - 1], v[i - 1], t[i], x, state * vth);
        cur.ib = i;
        out.push_back(cur);
      }
      if (st != 0) {
        cur = Excursion{};
        cur.sign = st;
        cur.ia = i;
        if (i == 0) {
          cur.a = t[0];
          cur.open_start = true;
        } else {
          cur.a = cross(t[i - 1], v[i - 1], t[i], x, st * vth);
        }
        cur.peak = st * x;
        cur.peak_t = t[i];
      }
      state = st;
    } else if (state != 0 && state * x > cur.peak) {
      cur.peak = state * x;
      cur.peak_t = t[i];
    }
  };
  // Most samples stay in the state of the one before (a pulse's top, the idle line): blocks of
  // kBlock that do are taken whole, without a branch per sample; the block holding a change of
  // state, and the tail, go sample by sample. The same excursions, peaks and peak times.
  constexpr size_t kBlock = 8;
  size_t i = 0;
  while (i < n) {
    if (state == 0) {
      while (i + kBlock <= n) {
        bool quiet = true;
        for (size_t k = 0; k < kBlock; ++k) quiet &= v[i + k] < vth && v[i + k] > -vth;
        if (!quiet) break;
        i += kBlock;
      }
    } else {
      const double s = state;
      while (i + kBlock <= n) {
        bool inside = true;
        double most = s * v[i];
        for (size_t k = 0; k < kBlock; ++k) {
          inside &= s * v[i + k] >= vth;
          most = std::max(most, s * v[i + k]);
        }
        if (!inside) break;
        if (most > cur.peak)  // the first sample above the peak so far, as one by one
          for (size_t k = 0; k < kBlock; ++k)
            if (s * v[i + k] > cur.peak) cur.peak = s * v[i + k], cur.peak_t = t[i + k];
        i += kBlock;
      }
    }
    const size_t end = std::min(n, i + kBlock);
    for (; i < end; ++i) step(i);
  }
  if (state != 0) {
    cur.b = t[n - 1];
    cur.ib = n;
    cur.open_end = true;
    out.push_back(cur);
  }
  return out;
}

Segmentation segment(std::span<const double> t, std::span<const double> v, const SegmentParams& p) {
  Segmentation seg;
  const std::vector<Excursion> ex = find_excursions(t, v, p.vth);

  // Rule 8.2: merge neighbouring same-sign excursions less than merge_gap apart.
  std::vector<PulseSpan> merged;
  merged.reserve(ex.size());
  for (size_t k = 0; k < ex.size(); ++k) {
    const Excursion& e = ex[k];
    if (!merged.empty() && merged.back().sign == e.sign && e.a - merged.back().b < p.merge_gap) {
      PulseSpan& ps = merged.back();
      Dip d;
      d.start = ps.b;
      d.end = e.a;
      d.lowest = p.vth;
      d.lowest_t = ps.b;
      for (size_t i = ps.ib; i < e.ia; ++i)
        if (e.sign * v[i] < d.lowest) {
          d.lowest = e.sign * v[i];
          d.lowest_t = t[i];
        }
      ps.dips.push_back(d);
      ps.b = e.b;
      ps.ib = e.ib;
      ps.truncated = ps.truncated || e.open_end;
      if (e.peak > ps.peak) {
        ps.peak = e.peak;
        ps.peak_t = e.peak_t;
      }
      continue;
    }
    PulseSpan ps;
    ps.sign = e.sign;
    ps.a = e.a;
    ps.b = e.b;
    ps.ia = e.ia;
    ps.ib = e.ib;
    ps.peak = e.peak;
    ps.peak_t = e.peak_t;
    ps.truncated = e.open_start || e.open_end;
    merged.push_back(std::move(ps));
  }

  // Rule 8.3: short (merged) excursions are ringing, not pulses. One cut by the record is kept as
  // a (truncated) pulse: its length is unknown.
  for (size_t k = 0; k < merged.size(); ++k) {
    PulseSpan& ps = merged[k];
    if (ps.b - ps.a < p.min_pulse && !ps.truncated) {
      seg.ringing.push_back(ringing_of(ps, false));
    } else {
      seg.pulses.push_back(std::move(ps));
    }
  }

  // Rule 8.4: transitions and frames.
  const size_t np = seg.pulses.size();
  seg.joined_next.assign(np, false);
  for (size_t i = 0; i + 1 < np; ++i) {
    const PulseSpan& x = seg.pulses[i];
    const PulseSpan& y = seg.pulses[i + 1];
    seg.joined_next[i] = y.sign == -x.sign && y.a - x.b < p.transition_gap;
  }
  build_frames(&seg);
  return seg;
}

void build_frames(Segmentation* seg) {
  const size_t np = seg->pulses.size();
  seg->frames.clear();
  for (size_t i = 0; i < np;) {
    FrameSpan f{i, i};
    while (f.last + 1 < np && seg->joined_next[f.last]) ++f.last;
    seg->frames.push_back(f);
    i = f.last + 1;
  }
}

void drop_frame_tail(Segmentation* seg, size_t i) {
  const Ringing g = ringing_of(seg->pulses.at(i), true);
  auto at = std::lower_bound(seg->ringing.begin(), seg->ringing.end(), g.start,
                             [](const Ringing& x, double t) { return x.start < t; });
  seg->ringing.insert(at, g);
  seg->pulses.erase(seg->pulses.begin() + static_cast<std::ptrdiff_t>(i));
  seg->joined_next.erase(seg->joined_next.begin() + static_cast<std::ptrdiff_t>(i));
  if (i > 0) seg->joined_next[i - 1] = false;
  build_frames(seg);
}

}  // namespace isolink::eye
