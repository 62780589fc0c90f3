#include "analysis/compare.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "analysis/compare_model.h"
#include "analysis/sweep_spec.h"
#include "base/file_io.h"
#include "eye/rules.h"
#include "netlists/link/board.h"
#include "netlists/link/cards.h"
#include "netlists/traffic/encoding.h"
#include "netlists/traffic/stimulus.h"

namespace isolink::analysis {
namespace cd = compare_detail;
namespace {

constexpr double kLead = 1e-6;            // idle before the first frame of the replayed traffic
constexpr double kWindowBefore = 0.3e-6;  // residual window before a frame's first crossing
constexpr double kWindowAfter = 1.0e-6;   // and after its last pulse (the kickback, the tail)

// Level changes of the half bits of one byte frame starting at t0.
void frame_edges(const std::vector<int>& half_bits, double t0, double half, cd::EdgeList& out) {
  int level = 0;
  for (size_t j = 0; j <= half_bits.size(); ++j) {
    const int next = j < half_bits.size() ? half_bits[j] : 0;
    if (next != level) {
      out.t.push_back(t0 + static_cast<double>(j) * half);
      out.dl.push_back(next - level);
      level = next;
    }
  }
  out.frames.push_back({t0, t0 + static_cast<double>(half_bits.size()) * half});
}

// The decoded frames of the capture as drive edges; the first frame's preamble at kLead.
cd::EdgeList decoded_traffic(const eye::CheckResult& c, const traffic::EncodingOptions& enc0) {
  cd::EdgeList out;
  double first = std::numeric_limits<double>::quiet_NaN();
  for (const eye::FrameResult& f : c.frames) {
    if (!f.byte) continue;
    if (std::isnan(first)) first = f.start;
    traffic::EncodingOptions enc = enc0;
    enc.error_bit = f.error_bit ? 1 : 0;
    frame_edges(traffic::byte_half_bits(*f.byte, enc), kLead + (f.start - first), enc.half_bit,
                out);
  }
  return out;
}

// A drive (the spec's stimulus or --frames) as edges.
cd::EdgeList drive_traffic(const traffic::Drive& d) {
  cd::EdgeList out;
  int level = 0;
  for (const traffic::DriveSegment& g : d.segments) {
    if (g.level == level) continue;
    out.t.push_back(g.start);
    out.dl.push_back(g.level - level);
    level = g.level;
  }
  for (const traffic::DriveFrame& f : d.frames) out.frames.push_back({f.start, f.end});
  return out;
}

// Standard deviation of the capture in its idle stretches (0.5 us before to 3 us after every
// pulse and ringing excluded), less a 64-sample moving average (slow tails are not noise).
double idle_noise(const std::vector<double>& t, const std::vector<double>& v,
                  const eye::CheckResult& c,
                  const std::vector<std::pair<double, double>>& windows = {}) {
  std::vector<char> busy(t.size(), 0);
  auto mark = [&](double a, double b) {
    auto lo = std::lower_bound(t.begin(), t.end(), a - 0.5e-6);
    auto hi = std::upper_bound(t.begin(), t.end(), b + 3e-6);
    for (auto it = lo; it < hi; ++it) busy[static_cast<size_t>(it - t.begin())] = 1;
  };
  for (const eye::PulseMetrics& p : c.pulses) mark(p.a, p.b);
  for (const eye::Ringing& r : c.ringing) mark(r.start, r.end);
  for (const auto& [a, b] : windows) mark(a, b);  // the traffic's frames
  const size_t w = 64;
  double sum = 0, sum2 = 0;
  size_t n = 0;
  size_t i = 0;
  while (i < t.size()) {
    if (busy[i]) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < t.size() && !busy[j]) ++j;
    for (size_t k = i; k + w <= j; k += w) {  // blocks of w samples, each less its mean
      const double m = std::accumulate(v.begin() + static_cast<long>(k),
                                       v.begin() + static_cast<long>(k + w), 0.0) /
                       static_cast<double>(w);
      for (size_t q = k; q < k + w; ++q) {
        sum2 += (v[q] - m) * (v[q] - m);
        ++n;
      }
    }
    i = j;
  }
  (void)sum;
  if (n < 2 * w) return 0.0;
  return std::sqrt(sum2 / static_cast<double>(n) * static_cast<double>(w) /
                   static_cast<double>(w - 1));
}

// The step of the values' grid: the smallest gap between distinct values when (nearly) every gap
// is a whole multiple of it, else 0 (not quantised as far as can be seen).
double quantisation_step(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  if (v.size() < 8) return 0.0;
  std::vector<double> gaps;
  for (size_t i = 1; i < v.size(); ++i) gaps.push_back(v[i] - v[i - 1]);
  std::vector<double> sorted = gaps;
  std::sort(sorted.begin(), sorted.end());
  const double q = sorted[sorted.size() / 10];  // robust against a stray tiny gap
  if (!(q > 0)) return 0.0;
  size_t whole = 0;
  for (double g : gaps) {
    const double k = g / q;
    if (std::abs(k - std::round(k)) < 0.05 && std::round(k) >= 1) ++whole;
  }
  return whole >= gaps.size() * 9 / 10 ? q : 0.0;
}

// Merged residual windows [start - before, last pulse b + after] of the decoded frames (capture
// time), or of the traffic's frames placed at `offset` when none decoded.
std::vector<std::pair<double, double>> residual_windows(const eye::CheckResult& c,
                                                        const cd::EdgeList& e, bool decoded,
                                                        double offset, double t0, double t1) {
  std::vector<std::pair<double, double>> w;
  if (decoded) {
    for (const eye::FrameResult& f : c.frames)
      if (f.byte) w.push_back({f.start - kWindowBefore, c.pulses[f.last_pulse].b + kWindowAfter});
  } else {
    for (const auto& [a, b] : e.frames) w.push_back({a + offset, b + offset + kWindowAfter});
  }
  std::vector<std::pair<double, double>> out;
  for (auto [a, b] : w) {
    a = std::max(a, t0);
    b = std::min(b, t1);
    if (b <= a) continue;
    if (!out.empty() && a <= out.back().second)
      out.back().second = std::max(out.back().second, b);
    else
      out.push_back({a, b});
  }
  return out;
}

// Indices of the capture samples inside the windows.
std::vector<size_t> window_samples(const std::vector<double>& t,
                                   const std::vector<std::pair<double, double>>& w) {
  std::vector<size_t> idx;
  for (const auto& [a, b] : w) {
    auto lo = std::lower_bound(t.begin(), t.end(), a);
    auto hi = std::upper_bound(t.begin(), t.end(), b);
    for (auto it = lo; it < hi; ++it) idx.push_back(static_cast<size_t>(it - t.begin()));
  }
  return idx;
}

// A scope's ADC clips at the ends of its range: every sample beyond lands on the end value, so
// the record holds far more samples exactly on its extreme than on the levels just inside it
// (a peak that is not cut holds fewer: it only touches its top). The record's maximum (minimum)
// is taken as a rail when at least 16 samples sit exactly on it and 3 times as many as in either
// of the two bins next to it, a bin being the quantisation step q (1/256 of the record's span
// when it is not quantised). A peak cut only slightly does not meet this; it is then compared as
// it is, which can only make compare stricter.
Clipping find_clipping(const std::vector<double>& v, double q) {
  Clipping c;
  if (v.size() < 64) return c;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  const double w = q > 0 ? q : (*hi - *lo) / 256;
  if (!(w > 0)) return c;
  auto is_rail = [&](double rail, double inward) {
    size_t on = 0, bin1 = 0, bin2 = 0;
    for (double x : v) {
      const double k = (x - rail) * inward / w;  // bins inward from the rail
      if (x == rail)
        ++on;
      else if (k >= 0.5 && k < 1.5)
        ++bin1;
      else if (k >= 1.5 && k < 2.5)
        ++bin2;
    }
    return on >= 16 && on >= 3 * std::max(bin1, bin2);
  };
  if (is_rail(*hi, -1.0)) c.high_v = *hi;
  if (is_rail(*lo, 1.0)) c.low_v = *lo;
  for (double x : v)
    if ((c.high_v && x == *c.high_v) || (c.low_v && x == *c.low_v)) ++c.samples;
  return c;
}

Residual residual_of(std::span<const double> c, std::span<const double> s, const Clipping& clip) {
  Residual r;
  double sse = 0;
  for (size_t i = 0; i < c.size(); ++i) {
    const double d = clip.difference(c[i], s[i]);
    if (d == 0 && c[i] != s[i]) ++r.clipped;
    sse += d * d;
    r.max_v = std::max(r.max_v, std::abs(d));
  }
  r.samples = c.size();
  r.rms_v = c.empty() ? 0.0 : std::sqrt(sse / static_cast<double>(c.size()));
  return r;
}

// The first time |v| reaches half its peak (the first pulse's edge), or NaN.
double first_edge(std::span<const double> t, std::span<const double> v) {
  double peak = 0;
  for (double x : v) peak = std::max(peak, std::abs(x));
  if (!(peak > 0)) return std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i < v.size(); ++i)
    if (std::abs(v[i]) >= 0.5 * peak) return t[i];
  return std::numeric_limits<double>::quiet_NaN();
}

// s: the span of the capture's windows that aligns the simulation with it (align_offset).
constexpr double kAlignSpan = 2e-3;

// Alignment: squared error over integer lags of a 1 ns grid within +/-range of offset0, then a
// golden-section search of the continuous offset over +/-1.5 grid steps of the best lag.

double align_offset(const EdgeResponse& e, const cd::EdgeList& edges, std::span<const double> ts,
                    std::span<const double> vs, double offset0, double before, double after,
                    const Clipping& clip) {
  const double dt = 1e-9;
  // The capture on the grid offset0 + k dt inside its sample span: the first kAlignSpan of its
  // windows' samples (the frames), which hold edges from their start. One offset for the whole
  // record needs no more, and the grid and the simulation on it are then bounded (2 million
  // points each) where a 100 ms record took 1e8 (2.9 GB).
  std::vector<double> cg, tg;
  size_t i_end = ts.size();  // the samples past the span: left out of the refinement too
  for (size_t i = 0; i + 1 < ts.size(); ++i) {
    if (!tg.empty() && ts[i] - tg.front() > kAlignSpan) {
      i_end = i + 1;
      break;
    }
    const double k0 = std::ceil((ts[i] - offset0) / dt),
                 k1 = std::floor((ts[i + 1] - offset0) / dt);
    if (ts[i + 1] - ts[i] > 20e-9) continue;  // a gap between two windows
    for (double k = k0; k <= k1 && k - k0 < 64; k += 1.0) {
      const double tt = offset0 + k * dt;
      if (tt >= ts[i + 1]) break;
      if (!tg.empty() && tt <= tg.back()) continue;
      tg.push_back(tt);
      cg.push_back(vs[i] + (vs[i + 1] - vs[i]) * (tt - ts[i]) / (ts[i + 1] - ts[i]));
    }
  }
  if (tg.empty()) return offset0;
  ts = ts.first(i_end);
  vs = vs.first(i_end);
  const long lb = static_cast<long>(std::floor(before / dt)), la = static_cast<long>(after / dt);
  // The simulation on the grid, drive time (tg - offset0) + lag for lag in [-lb, la].
  std::vector<double> sg_t;
  const double s_lo = tg.front() - offset0 - static_cast<double>(la) * dt;
  const long ns = static_cast<long>(std::llround((tg.back() - tg.front()) / dt)) + lb + la + 2;
  for (long k = 0; k < ns; ++k) sg_t.push_back(s_lo + static_cast<double>(k) * dt);
  std::vector<double> sg(sg_t.size());
  cd::synth_at(e, edges, 0.0, sg_t, sg);
  double best = std::numeric_limits<double>::infinity();
  long best_lag = 0;
  for (long lag = -lb; lag <= la; ++lag) {  // capture at tg <-> simulation at tg - offset0 - lag
    double sse = 0;
    for (size_t j = 0; j < tg.size() && sse < best; ++j) {
      const long k = static_cast<long>(std::llround((tg[j] - tg.front()) / dt)) + la - lag;
      const double d = clip.difference(cg[j], sg[static_cast<size_t>(k)]);
      sse += d * d;
    }
    if (sse < best) {
      best = sse;
      best_lag = lag;
    }
  }
  std::vector<double> out(ts.size());
  auto cost = [&](double off) {
    cd::synth_at(e, edges, off, ts, out);
    double sse = 0;
    for (size_t i = 0; i < ts.size(); ++i) {
      const double d = clip.difference(vs[i], out[i]);
      sse += d * d;
    }
    return sse;
  };
  const double g = (std::sqrt(5.0) - 1) / 2;
  double a = offset0 + (static_cast<double>(best_lag) - 1.5) * dt;
  double b = offset0 + (static_cast<double>(best_lag) + 1.5) * dt;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = cost(x1), f2 = cost(x2);
  while (b - a > 1e-13) {
    if (f1 < f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      f1 = cost(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      f2 = cost(x2);
    }
  }
  return (a + b) / 2;
}

// Per metric, simulated minus measured over the capture's pulses matched to the simulation's
// (same sign, start crossings within 50 ns).
std::vector<MetricSummary> metric_summaries(const eye::CheckResult& cap,
                                            const eye::CheckResult& sim) {
  std::vector<MetricSummary> out;
  for (const char* m : {"vstart", "vend", "width", "edge"}) {
    MetricSummary s;
    s.metric = m;
    double sum = 0;
    size_t j = 0;
    for (const eye::PulseMetrics& p : cap.pulses) {
      while (j < sim.pulses.size() && sim.pulses[j].a < p.a - 50e-9) ++j;
      if (j >= sim.pulses.size()) break;
      const eye::PulseMetrics& q = sim.pulses[j];
      if (q.sign != p.sign || std::abs(q.a - p.a) > 50e-9) continue;
      auto pick = [&](const eye::PulseMetrics& x) -> const eye::Judged& {
        const std::string mm = m;
        return mm == "vstart" ? x.vstart : mm == "vend" ? x.vend : mm == "width" ? x.width : x.edge;
      };
      const eye::Judged &a = pick(p), &b = pick(q);
      if (!a.measured() || !b.measured()) continue;
      const double d = b.value - a.value;
      sum += d;
      ++s.pulses;
      if (std::abs(d) > s.max_abs_diff) {
        s.max_abs_diff = std::abs(d);
        s.at_time = p.a;
      }
    }
    if (s.pulses > 0) s.mean_diff = sum / static_cast<double>(s.pulses);
    out.push_back(s);
  }
  return out;
}

// A capture with no daisy-chain pulses: nothing past the threshold, and nothing of both signs
// above max(0.1 V, 10 noise, 4 q).
bool no_pulses(const eye::CheckResult& c, const std::vector<double>& v, double noise, double q) {
  if (!c.pulses.empty()) return false;
  const double level = std::max({0.1, 10 * noise, 4 * q});
  bool pos = false, neg = false;
  for (double x : v) {
    pos = pos || x > level;
    neg = neg || x < -level;
  }
  return !(pos && neg);
}

// The windows, worst rms residual first (at most 3).
std::vector<size_t> worst_windows(const CompareResult& r, const std::vector<double>& sim) {
  std::vector<std::pair<double, size_t>> score;
  for (size_t w = 0; w < r.windows.size(); ++w) {
    auto lo = std::lower_bound(r.time.begin(), r.time.end(), r.windows[w].first);
    auto hi = std::upper_bound(r.time.begin(), r.time.end(), r.windows[w].second);
    double sse = 0;
    size_t n = 0;
    for (auto it = lo; it < hi; ++it, ++n) {
      const size_t i = static_cast<size_t>(it - r.time.begin());
      sse += (r.capture[i] - sim[i]) * (r.capture[i] - sim[i]);
    }
    score.push_back({n ? sse / static_cast<double>(n) : 0.0, w});
  }
  std::sort(score.begin(), score.end(), [](auto& a, auto& b) { return a.first > b.first; });
  std::vector<size_t> out;
  for (size_t i = 0; i < score.size() && i < 3; ++i) out.push_back(score[i].second);
  return out;
}

struct Prepared {
  link::LinkSpec spec;
  std::string spec_text;
  eye::Rules rules;
  Waveform w;
};

StatusOr<Prepared> prepare(const CompareInput& in, const CompareOptions& opt, CompareResult& r) {
  Prepared p;
  StatusOr<std::string> text = read_input_file(in.spec_path);
  if (!text) return text.status();
  p.spec_text = *text;
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(p.spec_text, in.spec_path);
  if (!spec) return spec.status();
  p.spec = std::move(*spec);
  const link::EndSpec& receiver = opt.direction == link::Direction::kDown ? p.spec.rx : p.spec.tx;
  r.receiver_rules = link::device_rules(receiver.device);
  StatusOr<eye::Rules> rules = eye::load_rules(r.receiver_rules);
  if (!rules) return rules.status();
  p.rules = std::move(*rules);
  StatusOr<Waveform> w = eye::read_capture(in.files, in.cols, &r.input);
  if (!w) return w.status();
  p.w = std::move(*w);
  return p;
}

// The traffic: the decoded frames, else --frames, else the spec's stimulus.
StatusOr<cd::EdgeList> traffic_of(const Prepared& p, const CompareOptions& opt, CompareResult& r,
                                  bool* decoded) {
  cd::EdgeList e = decoded_traffic(r.check, opt.expand.stimulus.encoding);
  *decoded = !e.t.empty();
  if (*decoded) {
    r.traffic_from = fmt::format("capture: {} frames decoded", e.frames.size());
    return e;
  }
  const std::string script = opt.frames.empty() ? p.spec.stimulus.to_script() : opt.frames;
  StatusOr<traffic::Drive> d = traffic::build_drive(script, opt.expand.stimulus);
  if (!d) return d.status().with_context(opt.frames.empty() ? p.spec.source : "--frames");
  r.traffic_from =
      opt.frames.empty() ? "spec stimulus (nothing decoded)" : "--frames (nothing decoded)";
  return drive_traffic(*d);
}

// The sentence on a residual the fitted keys leave: where it is largest, and what moves it.
std::string unexplained_sentence(const ResidualPlace& pl) {
  std::string keys;
  for (const ResidualPlace::Suggestion& s : pl.suggested)
    keys += fmt::format("{}{} ({:.0f} mV per +10 %)", keys.empty() ? "" : ", ", s.key,
                        s.sensitivity_v * 1e3);
  return fmt::format(
      "the fitted keys do not explain the capture: the residual is largest in frame {} at "
      "{:.4f} us ({}{:+.0f} mV, {:.0f} mV rms within 200 ns); the spec keys that move the "
      "waveform most there: {} (or another topology, the wrong direction or channels)",
      pl.window + 1, pl.time * 1e6,
      pl.pulse ? fmt::format("pulse {}, ", *pl.pulse + 1) : std::string(), pl.residual_v * 1e3,
      pl.window_rms_v * 1e3, keys.empty() ? "none found" : keys);
}

void judge(const CompareOptions& opt, CompareResult& r) {
  const Residual& res = r.residual_after_fit ? *r.residual_after_fit : r.residual;
  if (res.rms_v > r.threshold_rms_v)
    r.reasons.push_back(fmt::format(
        "the residual's rms {:.1f} mV{} exceeds what noise and quantisation explain ({:.1f} mV)",
        res.rms_v * 1e3, r.residual_after_fit ? " after the fit" : "", r.threshold_rms_v * 1e3));
  if (res.max_v > r.threshold_max_v)
    r.reasons.push_back(fmt::format(
        "the residual's largest deviation {:.0f} mV{} exceeds {:.0f} mV", res.max_v * 1e3,
        r.residual_after_fit ? " after the fit" : "", r.threshold_max_v * 1e3));
  for (const Finding& f : r.findings) r.reasons.push_back(f.text);
  if (r.unexplained)
    r.reasons.push_back(unexplained_sentence(*r.unexplained));
  else if (r.residual_after_fit && !opt.fit.empty() &&
           (res.rms_v > r.threshold_rms_v || res.max_v > r.threshold_max_v))
    r.reasons.push_back(
        "the fitted keys do not explain the capture: another topology, a part not fitted, or "
        "the wrong direction or channels");
  r.verdict = r.reasons.empty() ? "match" : "mismatch";
}

}  // namespace

StatusOr<CompareResult> compare_capture(const CompareInput& in, const link::PartLibrary& parts,
                                        const CompareOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  CompareResult r;
  r.direction = link::direction_name(opt.direction);
  StatusOr<Prepared> p = prepare(in, opt, r);
  if (!p) return p.status();
  // The design's waveform is synthesized from its edge response: a nonlinear link has none.
  if (std::string why = link::linear_only(p->spec, "compare"); !why.empty())
    return Status::Error(fmt::format("{}: {}", p->spec.source, why));
  for (const std::string& k : opt.fit) {  // bad keys and bounds are bad input, before any work
    StatusOr<DesignValue> dv = design_value(p->spec, parts, k);
    if (!dv) return dv.status();
    if (StatusOr<std::pair<double, double>> b = cd::fit_bounds(opt, k, dv->value); !b)
      return b.status();
  }
  const std::vector<double>& t = p->w.time;
  const std::vector<double>& v = p->w.columns[0];
  StatusOr<eye::CheckResult> check = eye::check_waveform(p->w, p->rules);
  if (!check) return check.status().with_context(in.files[0]);
  r.check = std::move(*check);
  r.noise_rms_v = idle_noise(t, v, r.check);
  r.quant_step_v = quantisation_step(v);
  r.clipping = find_clipping(v, r.quant_step_v);
  r.time = t;
  r.capture = v;
  if (no_pulses(r.check, v, r.noise_rms_v, r.quant_step_v)) {
    r.verdict = "inconclusive";
    r.reasons.push_back("the record holds no daisy-chain pulses");
    return r;
  }
  bool decoded = false;
  StatusOr<cd::EdgeList> edges = traffic_of(*p, opt, r, &decoded);
  if (!edges) return edges.status();
  cd::LinkModel model(p->spec_text, in.spec_path, parts, opt.direction, opt.expand);
  StatusOr<std::shared_ptr<const EdgeResponse>> e = model.response({}, {});
  if (!e) return e.status().with_context(in.spec_path);

  // Coarse offset: the first decoded frame's crossing, else the first pulses' half-peak edges.
  double offset0 = 0, before = 1e-6, after = 200e-9;  // the crossing lags the drive
  if (decoded) {
    for (const eye::FrameResult& f : r.check.frames)
      if (f.byte) {
        offset0 = f.start - kLead;
        break;
      }
  } else {
    // The first pulses are in the first frames: at most kAlignSpan of traffic is synthesized.
    const double span = edges->frames.empty() ? 20e-6
                                              : std::min(edges->frames.back().second + 5e-6,
                                                         edges->frames.front().first + kAlignSpan);
    std::vector<double> st, sv;
    for (double x = 0; x < span; x += 1e-9) st.push_back(x);
    sv.resize(st.size());
    cd::synth_at(**e, *edges, 0.0, st, sv);
    offset0 = first_edge(t, v) - first_edge(st, sv);
    if (!std::isfinite(offset0)) offset0 = t.front();
    before = after = 1e-6;
  }
  r.windows = residual_windows(r.check, *edges, decoded, offset0, t.front(), t.back());
  std::vector<size_t> idx = window_samples(t, r.windows);
  std::vector<double> ts, vs;
  for (size_t i : idx) {
    ts.push_back(t[i]);
    vs.push_back(v[i]);
  }
  if (ts.size() < 16) {
    r.verdict = "inconclusive";
    r.reasons.push_back("the traffic's frames do not overlap the record");
    return r;
  }
  r.offset_s = align_offset(**e, *edges, ts, vs, offset0, before, after, r.clipping);
  if (!decoded) {  // the windows follow the traffic: place them at the aligned offset
    r.windows = residual_windows(r.check, *edges, decoded, r.offset_s, t.front(), t.back());
    idx = window_samples(t, r.windows);
    ts.clear();
    vs.clear();
    for (size_t i : idx) {
      ts.push_back(t[i]);
      vs.push_back(v[i]);
    }
  }
  // With the traffic's windows known, noise is taken outside them too (a broken link's pulses
  // may never pass the threshold, so the check alone does not see them).
  r.noise_rms_v = idle_noise(t, v, r.check, r.windows);
  r.sim.resize(t.size());
  cd::synth_at(**e, *edges, r.offset_s, t, r.sim);
  std::vector<double> sw(ts.size());
  cd::synth_at(**e, *edges, r.offset_s, ts, sw);
  r.residual = residual_of(vs, sw, r.clipping);
  double peak = 0;
  for (double x : sw) peak = std::max(peak, std::abs(x));
  r.model_floor_v = opt.model_floor_rel * peak;
  r.threshold_rms_v = 3 * r.noise_rms_v + r.quant_step_v / std::sqrt(12.0) + r.model_floor_v;
  r.threshold_max_v = 6 * r.noise_rms_v + r.quant_step_v + 5 * r.model_floor_v;
  StatusOr<eye::CheckResult> sc = eye::check_samples(t, r.sim, p->rules);
  if (sc) r.metrics = metric_summaries(r.check, *sc);

  if (!opt.fit.empty()) {
    std::vector<double> fitted;
    const size_t first_window = static_cast<size_t>(
        std::upper_bound(ts.begin(), ts.end(), r.windows.front().second) - ts.begin());
    cd::FitData data{ts, vs, &*edges, r.offset_s, &r.clipping, first_window};
    if (Status s = cd::run_fit(model, p->spec, parts, opt, data, r, fitted); !s.ok()) return s;
    StatusOr<std::shared_ptr<const EdgeResponse>> ef = model.response(opt.fit, fitted);
    if (!ef) return ef.status();
    r.sim_after_fit.resize(t.size());
    cd::synth_at(**ef, *edges, *r.offset_after_fit_s, t, r.sim_after_fit);
    cd::synth_at(**ef, *edges, *r.offset_after_fit_s, ts, sw);
    r.residual_after_fit = residual_of(vs, sw, r.clipping);
    if (r.residual_after_fit->rms_v > r.threshold_rms_v ||
        r.residual_after_fit->max_v > r.threshold_max_v)
      if (Status s = cd::locate_residual(model, p->spec, parts, opt, fitted, data, sw, r); !s.ok())
        return s;
    StatusOr<eye::CheckResult> sf = eye::check_samples(t, r.sim_after_fit, p->rules);
    if (sf) r.metrics_after_fit = metric_summaries(r.check, *sf);
  }
  r.worst_frames = worst_windows(r, r.sim_after_fit.empty() ? r.sim : r.sim_after_fit);
  judge(opt, r);
  r.evaluations = model.evaluations();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

double cd::align(const EdgeResponse& e, const EdgeList& edges, std::span<const double> ts,
                 std::span<const double> vs, double offset0, double before, double after,
                 const Clipping& clip) {
  return align_offset(e, edges, ts, vs, offset0, before, after, clip);
}

StatusOr<DesignValue> design_value(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                   const std::string& key) {
  const std::string path = cd::key_paths(key).front();
  const size_t dot = path.rfind('.');
  const std::string last = dot == std::string::npos ? path : path.substr(dot + 1);
  auto refuse = [&](const std::string& why) {
    return Status::Error(fmt::format("--fit: error: key '{}' {}", key, why));
  };
  if (last == "gauge" || last == "segments" || last == "temperature" || path.rfind("sim.", 0) == 0)
    return refuse("cannot be fitted (a whole number, a temperature or a simulation setting)");
  DesignValue d;
  const link::EndSpec* end = path.rfind("tx.", 0) == 0   ? &spec.tx
                             : path.rfind("rx.", 0) == 0 ? &spec.rx
                                                         : nullptr;
  std::optional<double> v = sweep::spec_number(spec, path);
  const link::NoiseTolerances& tol = spec.noise.tolerance;
  auto band = [&](double rel, const std::string& from) {
    d.tol_low = d.tol_high = rel;
    d.tolerance_from = from;
  };
  band(0.10, "10 %, no tolerance known");
  if (!v && end && path.find("isolation") == std::string::npos) {
    StatusOr<link::BoardNetwork> b = link::board_preset(end->device);
    if (b && last == "series_r") v = b->r_line;
    if (b && last == "bypass_c") v = b->bypass_c;
    if (b && last == "termination") v = b->termination;
  }
  if (end && path.find("isolation") != std::string::npos && !end->isolation.part.empty()) {
    const link::Part* part = parts.find(end->isolation.part);
    const link::Figure* f = part ? part->figure(last) : nullptr;
    if (!v && part && part->kind == link::PartKind::Transformer) {
      const link::TransformerModel& m = part->transformer;
      if (last == "inductance") v = m.inductance;
      if (last == "leakage") v = m.leakage;
      if (last == "dcr") v = m.dcr;
      if (last == "winding_c") v = m.winding_c;
      if (last == "centre_tap_c") v = m.centre_tap_c;
    }
    if (v && f && f->min && f->max && f->value > 0) {
      d.tol_low = std::max(0.0, 1 - *f->min / f->value);
      d.tol_high = std::max(0.0, *f->max / f->value - 1);
      d.tolerance_from = "part " + part->number + " range";
    } else if (f && f->tolerance) {
      band(*f->tolerance, "part " + part->number);
    }
  }
  if (last == "cap" && path.find("isolation") != std::string::npos)
    band(tol.isolation_cap, "noise.tolerance.isolation_cap");
  if (last == "series_r") band(tol.series_r, "noise.tolerance.series_r");
  if (last == "bypass_c") band(tol.bypass_c, "noise.tolerance.bypass_c");
  if (last == "cable_side_c") band(tol.y_cap, "noise.tolerance.y_cap");
  if (last == "esd") band(tol.esd, "noise.tolerance.esd");
  if (!v) {
    if (sweep::key_unit(path) == config::Unit::kNone)
      return refuse(
          "is not a numeric link-spec key (sweep keys: cable.length, "
          "rx.isolation.cap, tx.isolation.leakage, ends.termination, ...)");
    return refuse("has no value in the spec, its board preset or its part: give it in the spec");
  }
  if (!(*v > 0))
    return refuse(fmt::format("has the design value {:g}: a fit needs one above 0", *v));
  d.value = *v;
  return d;
}

}  // namespace isolink::analysis
