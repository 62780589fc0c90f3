#include "eye/metrics.h"

#include <fmt/format.h>

#include <algorithm>

namespace isolink::eye {
namespace {

// v at time tq by linear interpolation, searching samples [lo, hi) (clamped to the data).
double interp(std::span<const double> t, std::span<const double> v, size_t lo, size_t hi,
              double tq) {
  lo = std::min(lo, t.size() - 1);
  hi = std::min(std::max(hi, lo + 1), t.size());
  auto first = t.begin() + static_cast<std::ptrdiff_t>(lo);
  auto last = t.begin() + static_cast<std::ptrdiff_t>(hi);
  size_t j = static_cast<size_t>(std::upper_bound(first, last, tq) - t.begin());
  if (j == 0) return v[0];
  if (j >= t.size()) return v[t.size() - 1];
  const double t0 = t[j - 1], t1 = t[j];
  return v[j - 1] + (tq - t0) / (t1 - t0) * (v[j] - v[j - 1]);
}

double ns(double s) {
  return s * 1e9;
}

}  // namespace

SegmentParams segment_params(const Rules& r) {
  return SegmentParams{r.vth, r.merge_gap, r.min_pulse, r.transition_gap};
}

namespace {
// Rule 8.5: a pulse's width (to the next pulse's start when joined to it) and its class k.
double pulse_width(const Segmentation& seg, size_t i) {
  const PulseSpan& ps = seg.pulses[i];
  return seg.joined_next[i] ? seg.pulses[i + 1].a - ps.a : ps.b - ps.a;
}
int pulse_class(double width, const Rules& r) {
  // A pulse far longer than a frame (a DC level, a 10 s pulse in the wrong units) carries at most
  // kMaxHalfBits half bits for decoding: memory stays linear in samples, not in pulse length.
  return static_cast<int>(std::lround(std::min(width / r.pulse_time, 1e9)));
}
}  // namespace

int pulse_half_bits(const Segmentation& seg, size_t i, const Rules& r) {
  return std::clamp(pulse_class(pulse_width(seg, i), r), 1, kMaxHalfBits);
}

std::vector<PulseMetrics> measure_pulses(std::span<const double> t, std::span<const double> v,
                                         const Segmentation& seg, const Rules& r,
                                         bool warning_texts) {
  std::vector<PulseMetrics> out(seg.pulses.size());
  for (size_t i = 0; i < seg.pulses.size(); ++i) {
    const PulseSpan& ps = seg.pulses[i];
    PulseMetrics& m = out[i];
    const int s = ps.sign;
    m.index = i;
    m.sign = s;
    m.a = ps.a;
    m.b = ps.b;
    m.truncated = ps.truncated;
    m.dips = ps.dips;
    const bool joined = seg.joined_next[i];
    m.idle = !joined;

    // Rules 8.5-8.6: width and class.
    const double width = pulse_width(seg, i);
    m.k = pulse_class(width, r);
    m.half_bits = std::clamp(m.k, 1, kMaxHalfBits);
    if (!m.truncated) m.width.value = width;
    if (joined && !m.truncated) {
      const WidthWindow* best = nullptr;
      double best_margin = -std::numeric_limits<double>::infinity();
      for (const WidthWindow& w : r.width) {
        const double mg = std::min(width - w.min, w.max - width);
        if (mg > best_margin) {
          best_margin = mg;
          best = &w;
        }
      }
      m.width.margin = best_margin;
      m.width.limit = width - best->min < best->max - width ? best->min : best->max;
      if (best_margin < 0) {
        m.timing_fail = true;
        if (const WidthWindow* w = r.window(m.k))
          m.fails.push_back(fmt::format("width: {:.1f} ns outside {:.0f}-{:.0f} ns (class {})",
                                        ns(width), ns(w->min), ns(w->max), m.k));
        else
          m.fails.push_back(
              fmt::format("width: {:.1f} ns is class {}, which these rules do not "
                          "allow (nearest window {:.0f}-{:.0f} ns)",
                          ns(width), m.k, ns(best->min), ns(best->max)));
      }
    }

    // Rule 8.7: edge time into this pulse.
    if (i > 0 && seg.joined_next[i - 1]) {
      m.edge.value = ps.a - seg.pulses[i - 1].b;
      m.edge.limit = r.edge_max;
      m.edge.margin = r.edge_max - m.edge.value;
      if (m.edge.margin < 0) {
        m.timing_fail = true;
        m.fails.push_back(fmt::format("edge: {} {:.1f} ns > {:.0f} ns", s > 0 ? "trise" : "tfall",
                                      ns(m.edge.value), ns(r.edge_max)));
      }
    }

    // Rule 8.2: dips fail.
    for (const Dip& d : ps.dips) {
      m.weak_fail = true;
      m.fails.push_back(fmt::format("dip: {:.1f} ns below {:.2f} V at {:.4f} us, lowest {:.3f} V",
                                    ns(d.end - d.start), r.vth, d.start * 1e6, d.lowest));
    }

    if (m.truncated) {
      if (warning_texts)
        m.warnings.push_back("truncated: cut by the start or end of the record, not judged");
      continue;
    }

    // Rule 8.8: VSTART, VEND.
    const double mid = 0.5 * (ps.a + ps.b);
    // s*v is vth at a; the samples from a up to mid, then mid itself (interpolated).
    const size_t j = static_cast<size_t>(
        std::upper_bound(t.begin() + static_cast<std::ptrdiff_t>(ps.ia),
                         t.begin() + static_cast<std::ptrdiff_t>(std::max(ps.ia, ps.ib)), mid) -
        t.begin());
    double vstart = running_max(v, ps.ia, j, r.vth, [s](auto x) { return s * x; });
    vstart = std::max(vstart, s * interp(t, v, ps.ia > 0 ? ps.ia - 1 : 0, j + 1, mid));
    const double vend =
        s * interp(t, v, ps.ia > 0 ? ps.ia - 1 : 0, ps.ib + 1, ps.b - r.vend_offset);
    m.vstart.value = vstart;
    m.vend.value = vend;

    // Rule 8.9: amplitude rule, droop.
    m.vend.limit = r.vend_min;
    m.vend.margin = vend - r.vend_min;
    m.vstart.limit = r.vstart_required(vend);
    m.vstart.margin = vstart - m.vstart.limit;
    if (m.vend.margin < 0) {
      m.weak_fail = true;
      m.fails.push_back(fmt::format("vend: {:.3f} V < {:.2f} V", vend, r.vend_min));
    }
    if (m.vstart.margin < 0) {
      m.weak_fail = true;
      if (r.amplitude == AmplitudeRule::kBq7961x)
        m.fails.push_back(fmt::format(
            "vstart: {:.3f} V < {:.2f} V (needed with VEND {:.3f} V {} "
            "{:.2f} V)",
            vstart, m.vstart.limit, vend, vend > r.vend_knee ? ">" : "<=", r.vend_knee));
      else
        m.fails.push_back(fmt::format("vstart: {:.3f} V < {:.2f} V", vstart, m.vstart.limit));
    }
    m.droop.value = vstart - vend;
    m.droop.limit = r.droop_max;
    m.droop.margin = r.droop_max - m.droop.value;
    if (m.droop.margin < 0 && warning_texts)
      m.warnings.push_back(
          fmt::format("droop: {:.3f} V > {:.2f} V (VSTART {:.3f} V, VEND {:.3f} V)", m.droop.value,
                      r.droop_max, vstart, vend));
  }
  return out;
}

std::vector<IdleUndershoot> find_idle_undershoots(std::span<const double> t,
                                                  std::span<const double> v,
                                                  const Segmentation& seg, const Rules& r) {
  std::vector<IdleUndershoot> out;
  const size_t n = std::min(t.size(), v.size());
  const double inf = std::numeric_limits<double>::infinity();
  for (const FrameSpan& f : seg.frames) {
    const PulseSpan& p = seg.pulses[f.last];
    if (p.truncated) continue;
    const int s = p.sign;
    const double next_a = f.last + 1 < seg.pulses.size() ? seg.pulses[f.last + 1].a : inf;
    const double watch_end = p.b + r.tblank;
    const double lvl = r.idle_level;
    size_t i = p.ib;
    // wait until the pulse has returned (s*v <= level)
    while (i < n && t[i] < watch_end && t[i] < next_a && s * v[i] > lvl) ++i;
    if (i >= n || t[i] >= watch_end || t[i] >= next_a) continue;
    bool in = false;
    IdleUndershoot u;
    for (; i < n; ++i) {
      const double x = s * v[i];
      if (!in) {
        if (t[i] >= watch_end || t[i] >= next_a) break;
        if (x > lvl) {
          in = true;
          u = IdleUndershoot{};
          u.after_pulse = f.last;
          u.sign = s;
          const double x0 = s * v[i - 1];  // i > p.ib - 1 >= 0: a returned sample precedes it
          u.start = t[i - 1] + (lvl - x0) / (x - x0) * (t[i] - t[i - 1]);
          u.peak = x;
          u.peak_t = t[i];
        }
      } else {
        if (t[i] >= next_a) {  // the next pulse's leading edge, not an undershoot
          in = false;
          break;
        }
        if (x > lvl) {
          if (x > u.peak) {
            u.peak = x;
            u.peak_t = t[i];
          }
        } else {
          const double x0 = s * v[i - 1];
          u.end = t[i - 1] + (lvl - x0) / (x - x0) * (t[i] - t[i - 1]);
          out.push_back(u);
          in = false;
        }
      }
    }
    if (in) {
      u.end = t[n - 1];
      out.push_back(u);
    }
  }
  return out;
}

std::vector<WorstMargin> worst_margins(const std::vector<PulseMetrics>& pulses) {
  std::vector<WorstMargin> out;
  auto scan = [&](const char* name, Judged PulseMetrics::*field) {
    const PulseMetrics* worst = nullptr;
    for (const PulseMetrics& p : pulses) {
      const Judged& j = p.*field;
      if (j.judged() && (!worst || j.margin < (worst->*field).margin)) worst = &p;
    }
    if (!worst) return;
    WorstMargin w;
    w.metric = name;
    w.j = worst->*field;
    w.pulse = worst->index;
    w.time = worst->a;
    w.frame = worst->frame;
    w.role = worst->role;
    out.push_back(w);
  };
  scan("vstart", &PulseMetrics::vstart);
  scan("vend", &PulseMetrics::vend);
  scan("width", &PulseMetrics::width);
  scan("edge", &PulseMetrics::edge);
  scan("droop", &PulseMetrics::droop);
  return out;
}

}  // namespace isolink::eye
