#include "analysis/worst.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <experimental/simd>
#include <limits>
#include <tuple>
#include <utility>

#include "netlists/traffic/command.h"
#include "netlists/traffic/encoding.h"

namespace isolink::analysis {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMetrics = 5;
const std::array<const char*, kMetrics> kNames{"vstart", "vend", "width_min", "width_max", "edge"};
constexpr double kLead = 1e-6;  // idle before the replayed traffic (the drive's default lead)

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

long to_samples(double t, double dt) {
  return std::lround(t / dt);
}

// A byte pattern: byte | error_bit << 8.
ByteFrame pattern_frame(int pattern) {
  return {static_cast<uint8_t>(pattern & 0xFF), (pattern >> 8) & 1};
}

// The level changes of half-bit levels h starting at sample `start`: (sample, dL). Linear in h
// (the line idles at 0 before and after), so it also gives the edges of a difference of levels.
void level_edges(const std::vector<int>& h, long start, long half,
                 std::vector<std::pair<long, int>>& out) {
  int prev = 0;
  for (size_t k = 0; k <= h.size(); ++k) {
    const int level = k < h.size() ? h[k] : 0;
    if (level != prev) out.push_back({start + static_cast<long>(k) * half, level - prev});
    prev = level;
  }
}

std::vector<int> pattern_levels(int pattern, const traffic::EncodingOptions& enc) {
  traffic::EncodingOptions e = enc;
  e.error_bit = (pattern >> 8) & 1;
  return traffic::byte_half_bits(static_cast<uint8_t>(pattern & 0xFF), e);
}

// The level changes of one byte frame starting at sample `start`: (sample, dL).
void frame_edges(const ByteFrame& f, const traffic::EncodingOptions& enc, long start, long half,
                 std::vector<std::pair<long, int>>& out) {
  level_edges(pattern_levels(f.byte | f.error_bit << 8, enc), start, half, out);
}

// A byte frame's half-bit levels are affine in its 9 free bits (the 8 data bits and the error
// bit, bit b of the pattern): h(q) = h(0) + sum_b bit_b(q) (h(2^b) - h(0)). So is the receiver's
// response to it. Checked here for every pattern, so an encoding that broke it would be refused
// rather than searched wrongly.
constexpr int kPatternBits = 9;
struct PatternBasis {
  std::vector<int> base;                           // h(0)
  std::array<std::vector<int>, kPatternBits> bit;  // h(2^b) - h(0)
};

StatusOr<PatternBasis> pattern_basis(const traffic::EncodingOptions& enc) {
  PatternBasis pb;
  pb.base = pattern_levels(0, enc);
  for (int b = 0; b < kPatternBits; ++b) {
    pb.bit[b] = pattern_levels(1 << b, enc);
    if (pb.bit[b].size() != pb.base.size())
      return Status::Error("internal error: byte frames of different lengths");
    for (size_t k = 0; k < pb.base.size(); ++k) pb.bit[b][k] -= pb.base[k];
  }
  for (int q = 0; q < (1 << kPatternBits); ++q) {
    std::vector<int> h = pb.base;
    for (int b = 0; b < kPatternBits; ++b)
      if (q >> b & 1)
        for (size_t k = 0; k < h.size(); ++k) h[k] += pb.bit[b][k];
    if (h != pattern_levels(q, enc))
      return Status::Error(fmt::format(
          "internal error: byte frame {:#05x} is not affine in its bits (the search needs it)", q));
  }
  return pb;
}

// v[i] += sum dL E(origin + i - n_edge) of E = e.e (add_response, edge_response.h).
void add_edges(const EdgeResponse& e, const std::vector<std::pair<long, int>>& edges, long origin,
               std::vector<double>& v) {
  add_response(e.e, e.pre, edges, origin, v);
}

// Per-metric "key": lower is worse. vstart, vend: the value; width_min: width - window min;
// width_max: window max - width; edge: limit - edge.
struct PulseScore {
  double key = kInf;
  double value = 0, limit = 0, margin = 0;
  size_t pulse = 0;
  double a = 0;  // in the scored window (s)
  int sign = 0;
  std::string role;
  bool valid() const { return key < kInf; }
};

struct Score {
  std::array<PulseScore, kMetrics> m;
  bool pass = true;
  std::string reason;  // first failure reason of the check
};

const eye::WidthWindow* nearest_window(const eye::Rules& r, int k) {
  const eye::WidthWindow* best = nullptr;
  for (const eye::WidthWindow& w : r.width)
    if (!best || std::abs(w.k - k) < std::abs(best->k - k)) best = &w;
  return best;
}

// Scores the pulses of a checked window (all of them belong to the target frame).
Score score_check(const eye::CheckResult& c, const eye::Rules& rules) {
  Score s;
  s.pass = c.pass;
  if (!c.pass) s.reason = c.reasons.empty() ? "fails its rules" : c.reasons.front();
  auto offer = [&](int m, double key, double value, double limit, const eye::PulseMetrics& p) {
    if (!std::isfinite(key) || key >= s.m[m].key) return;
    s.m[m] = {key, value, limit, 0, p.index, p.a, p.sign, p.role};
  };
  for (const eye::PulseMetrics& p : c.pulses) {
    if (p.truncated) continue;
    if (p.vstart.measured()) {
      const double lim = p.vstart.judged() ? p.vstart.limit : rules.vstart_min;
      offer(0, p.vstart.value, p.vstart.value, lim, p);
    }
    if (p.vend.measured()) offer(1, p.vend.value, p.vend.value, rules.vend_min, p);
    if (!p.idle && p.width.measured()) {
      if (const eye::WidthWindow* w = nearest_window(rules, std::max(p.k, 1))) {
        offer(2, p.width.value - w->min, p.width.value, w->min, p);
        offer(3, w->max - p.width.value, p.width.value, w->max, p);
      }
    }
    if (p.edge.measured()) offer(4, rules.edge_max - p.edge.value, p.edge.value, rules.edge_max, p);
  }
  for (int m = 0; m < kMetrics; ++m) {
    PulseScore& ps = s.m[m];
    if (!ps.valid()) continue;
    ps.margin = (m == 0 || m == 1 || m == 2) ? ps.value - ps.limit : ps.limit - ps.value;
  }
  return s;
}

// The search over one direction.
class Search {
 public:
  Search(const EdgeResponse& e, const eye::Rules& rules, const WorstOptions& opt)
      : e_(e), rules_(rules), enc_(opt.expand.stimulus.encoding) {
    half_ = to_samples(enc_.half_bit, e.dt);
    frame_ = half_ * traffic::byte_half_bit_count(enc_);
    pre_ = to_samples(300e-9, e.dt);
    post_ = to_samples(1.5e-6, e.dt);
    len_ = pre_ + frame_ + post_;
    t_.resize(static_cast<size_t>(len_));
    for (long i = 0; i < len_; ++i) t_[static_cast<size_t>(i)] = static_cast<double>(i) * e.dt;
  }

  const PatternBasis& basis() const { return basis_; }
  long half() const { return half_; }
  long frame() const { return frame_; }
  long pre() const { return pre_; }
  long len() const { return len_; }

  // Builds the target's per-bit windows (PatternBasis); an error when the encoding breaks it.
  Status init() {
    StatusOr<PatternBasis> basis = pattern_basis(enc_);
    if (!basis) return basis.status();
    basis_ = *basis;
    std::array<std::vector<double>, kPatternBits + 1> columns;  // v_idle + base, then per bit
    for (int b = 0; b <= kPatternBits; ++b) {
      std::vector<double>& w = columns[static_cast<size_t>(b)];
      w.assign(static_cast<size_t>(len_), b == 0 ? e_.v_idle : 0.0);
      std::vector<std::pair<long, int>> edges;
      level_edges(b == 0 ? basis->base : basis->bit[static_cast<size_t>(b - 1)], pre_, half_,
                  edges);
      add_edges(e_, edges, 0, w);
    }
    // The sums of the columns over every subset of the low and of the high bits: a pattern's
    // wave is then two additions (512 of them in the idle-target stage).
    for (int part = 0; part < 2; ++part) {
      const int first = part == 0 ? 0 : kLowBits,
                count = part == 0 ? kLowBits : kPatternBits - kLowBits;
      std::vector<std::vector<double>>& sums = subset_sums_[static_cast<size_t>(part)];
      sums.assign(size_t{1} << count, std::vector<double>(static_cast<size_t>(len_), 0.0));
      if (part == 0) sums[0] = columns[0];
      for (size_t s = 1; s < sums.size(); ++s) {
        const int low = std::countr_zero(s);  // s = (s without its lowest bit) + that bit
        const std::vector<double>& rest = sums[s & (s - 1)];
        const std::vector<double>& w = columns[static_cast<size_t>(first + low + 1)];
        for (size_t i = 0; i < w.size(); ++i) sums[s][i] = rest[i] + w[i];
      }
    }
    return Status::Ok();
  }

  // The target frame's own waveform (history idle) on the window; target starts at sample pre_.
  std::vector<double> target_wave(int pattern) const {
    std::vector<double> v;
    target_wave(pattern, v);
    return v;
  }
  // The same into v (its storage reused: the idle-target stage's 512 waves).
  void target_wave(int pattern, std::vector<double>& v) const {
    const std::vector<double>& a = subset_sums_[0][static_cast<size_t>(pattern & kLowMask)];
    const std::vector<double>& b = subset_sums_[1][static_cast<size_t>(pattern >> kLowBits)];
    v.resize(a.size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = a[i] + b[i];
  }
  // Adds the previous byte ending `gap` samples before the target's start.
  void add_previous(std::vector<double>& v, int pattern, long gap) const {
    std::vector<std::pair<long, int>> edges;
    frame_edges(pattern_frame(pattern), enc_, pre_ - gap - frame_, half_, edges);
    add_edges(e_, edges, 0, v);
  }

  StatusOr<eye::CheckResult> check(const std::vector<double>& v, int target) const {
    eye::CheckOptions co;
    co.expect = std::vector<uint8_t>{pattern_frame(target).byte};
    co.warning_texts = false;  // the search reads numbers only
    co.commands = false;
    return eye::check_samples(t_, v, rules_, co);
  }

  StatusOr<Score> score(const std::vector<double>& v, int target) {
    StatusOr<eye::CheckResult> c = check(v, target);
    if (!c) return c.status();
    ++scored_;
    return score_check(*c, rules_);
  }

  long scored_ = 0;

 private:
  const EdgeResponse& e_;
  const eye::Rules& rules_;
  traffic::EncodingOptions enc_;
  long half_ = 0, frame_ = 0, pre_ = 0, post_ = 0, len_ = 0;
  std::vector<double> t_;
  PatternBasis basis_;
  static constexpr int kLowBits = 5, kLowMask = (1 << kLowBits) - 1;
  // [0][s]: v_idle + base + the bit columns of low-bit subset s; [1][s]: those of high-bit s.
  std::array<std::vector<std::vector<double>>, 2> subset_sums_;
};

// Slope dv/dt at time a of sampled v (window times i * dt).
double slope_at(const std::vector<double>& v, double dt, double a) {
  const long i =
      std::clamp(static_cast<long>(std::floor(a / dt)), 1L, static_cast<long>(v.size()) - 3);
  return (v[static_cast<size_t>(i + 1)] - v[static_cast<size_t>(i)]) / dt;
}

// First-order model of one candidate target waveform: for each pulse and metric the key with
// idle history plus coefficients on u (the previous byte's contribution) at a few samples.
struct Term {
  long sample;  // where u is read (window sample)
  double coef;  // d key / d u there
};
struct Linear {
  int metric;
  double key0;
  std::vector<Term> terms;
};

std::vector<Linear> linearize(const eye::CheckResult& c, const std::vector<double>& v,
                              const eye::Rules& r, double dt) {
  std::vector<Linear> out;
  const std::vector<eye::PulseMetrics>& ps = c.pulses;
  auto sample = [&](double t) { return std::lround(t / dt); };
  // Crossing shift per unit u at a crossing t: -1 / v'(t).
  auto shift = [&](double t) {
    const double s = slope_at(v, dt, t);
    return std::abs(s) > 1e-3 / dt * 1e-6 ? -1.0 / s : 0.0;
  };
  for (size_t j = 0; j < ps.size(); ++j) {
    const eye::PulseMetrics& p = ps[j];
    if (p.truncated) continue;
    const double sg = p.sign;
    if (p.vstart.measured()) {
      // The time of the maximum of s v over [a, (a + b) / 2].
      long best = sample(p.a);
      for (long i = sample(p.a); i <= sample(0.5 * (p.a + p.b)) && i < static_cast<long>(v.size());
           ++i)
        if (sg * v[static_cast<size_t>(i)] > sg * v[static_cast<size_t>(best)]) best = i;
      out.push_back({0, p.vstart.value, {{best, sg}}});
    }
    if (p.vend.measured()) out.push_back({1, p.vend.value, {{sample(p.b - r.vend_offset), sg}}});
    if (!p.idle && p.width.measured() && j + 1 < ps.size()) {
      const eye::PulseMetrics& n = ps[j + 1];
      if (const eye::WidthWindow* w = nearest_window(r, std::max(p.k, 1))) {
        // width = a_next - a.
        const std::vector<Term> d{{sample(n.a), shift(n.a)}, {sample(p.a), -shift(p.a)}};
        out.push_back({2, p.width.value - w->min, d});
        out.push_back(
            {3, w->max - p.width.value, {{d[0].sample, -d[0].coef}, {d[1].sample, -d[1].coef}}});
      }
    }
    if (p.edge.measured() && j > 0) {
      const eye::PulseMetrics& q = ps[j - 1];
      // edge = a - b_prev; key = limit - edge.
      out.push_back(
          {4, r.edge_max - p.edge.value, {{sample(p.a), -shift(p.a)}, {sample(q.b), shift(q.b)}}});
    }
  }
  return out;
}

std::string traffic_text(const Traffic& t) {
  std::string s;
  for (size_t i = 0; i < t.frames.size(); ++i) {
    if (i) s += ", ";
    s += fmt::format("{:02X}{} after {:.3g} us", t.frames[i].byte,
                     t.frames[i].error_bit ? " (error bit)" : "", t.gaps[i] * 1e6);
  }
  return s;
}

}  // namespace

Status WorstOptions::validate() const {
  const std::pair<const char*, double> positive[] = {{"dt", dt},
                                                     {"gap_min", gap_min},
                                                     {"gap_step", gap_step},
                                                     {"tail_tol", tail_tol},
                                                     {"reltol", reltol},
                                                     {"settle_tol", settle_tol},
                                                     {"max_span", max_span},
                                                     {"max_memory", max_memory}};
  for (const auto& [name, v] : positive)
    if (!(v > 0) || !std::isfinite(v))
      return Status::Error(
          fmt::format("worst-case option {} = {:g}: must be a positive number", name, v));
  const double half = expand.stimulus.encoding.half_bit;
  for (const auto& [name, v] : {std::pair{"half bit", half}, std::pair{"gap_min", gap_min},
                                std::pair{"gap_step", gap_step}}) {
    const double n = v / dt;
    if (std::abs(n - std::round(n)) > 1e-6 * n)
      return Status::Error(fmt::format(
          "worst-case option {} = {:g} s: must be a whole number of dt = {:g} s", name, v, dt));
  }
  if (max_candidates < 1 || verify < 1)
    return Status::Error(fmt::format(
        "worst-case options max_candidates = {} and verify = {}: both must be at least 1",
        max_candidates, verify));
  for (const std::vector<int>* list : {&targets, &previous})
    for (int p : *list)
      if (p < 0 || p > 511)
        return Status::Error(
            fmt::format("worst-case pattern {}: must be 0-511 (byte | error bit << 8)", p));
  return Status::Ok();
}

double Traffic::frame_start(size_t i, double byte_duration) const {
  double t = 0;
  for (size_t k = 0; k <= i && k < gaps.size(); ++k) t += gaps[k] + (k < i ? byte_duration : 0);
  return t;
}

const WorstMetric* DirectionWorst::metric(const std::string& name) const {
  for (const WorstMetric& m : metrics)
    if (m.name == name) return &m;
  return nullptr;
}

namespace {

// P*(n) = max |p| over samples >= n (p(n) = E(n) - E(n - half), 0 past the record).
std::vector<double> pulse_envelope(const EdgeResponse& e, long half) {
  const long n = static_cast<long>(e.e.size()) - e.pre + half;
  std::vector<double> env(static_cast<size_t>(std::max(n, 1L)) + 1, 0.0);
  for (long i = n - 1; i >= 0; --i)
    env[static_cast<size_t>(i)] =
        std::max(env[static_cast<size_t>(i + 1)], std::abs(e.at(i) - e.at(i - half)));
  return env;
}

double bound_from(const std::vector<double>& env, long n0, long half) {
  double b = 0;
  for (long n = std::max(n0, 0L); n < static_cast<long>(env.size()); n += half)
    b += env[static_cast<size_t>(n)];
  return b;
}

}  // namespace

double tail_bound(const EdgeResponse& e, double half_bit, double tau) {
  const long half = to_samples(half_bit, e.dt);
  return bound_from(pulse_envelope(e, half), to_samples(tau, e.dt), half);
}

Waveform synthesize(const EdgeResponse& e, const Traffic& traffic,
                    const traffic::EncodingOptions& enc, double t0, double t1) {
  const long half = to_samples(enc.half_bit, e.dt);
  const long frame = half * traffic::byte_half_bit_count(enc);
  std::vector<std::pair<long, int>> edges;
  long start = 0;
  for (size_t i = 0; i < traffic.frames.size(); ++i) {
    start += to_samples(i < traffic.gaps.size() ? traffic.gaps[i] : 0.0, e.dt);
    frame_edges(traffic.frames[i], enc, start, half, edges);
    start += frame;
  }
  const long origin = to_samples(t0, e.dt);
  const long n = std::max(2L, to_samples(t1, e.dt) - origin + 1);
  std::vector<double> v(static_cast<size_t>(n), e.v_idle);
  add_edges(e, edges, origin, v);
  Waveform w;
  w.time.resize(static_cast<size_t>(n));
  for (long i = 0; i < n; ++i)
    w.time[static_cast<size_t>(i)] = static_cast<double>(origin + i) * e.dt;
  w.add_column("v(rxp,rxn)", std::move(v));
  return w;
}

namespace {

// The best score per metric so far and the traffic behind it.
struct Best {
  PulseScore s;
  int target = -1, prev = -1;
  long gap = 0;
};

// What the stages of one direction's search share (method items 2-5, worst.h): the window's
// sizes, the histories to try, each metric's best so far and the failures found (in *dw).
struct DirectionState {
  DirectionState(const EdgeResponse& e_, const eye::Rules& rules_, const WorstOptions& opt_,
                 Search& search_, DirectionWorst& dw_)
      : e(e_),
        rules(rules_),
        opt(opt_),
        search(search_),
        dw(dw_),
        half(search_.half()),
        frame(search_.frame()),
        pre(search_.pre()),
        dt(e_.dt) {}

  const EdgeResponse& e;
  const eye::Rules& rules;
  const WorstOptions& opt;
  Search& search;
  DirectionWorst& dw;
  const long half, frame, pre;
  const double dt;
  long gap_min = 0, gap_step = 0, gap_max = 0;  // samples
  std::vector<int> targets, previous;           // patterns (byte | error bit << 8)
  std::vector<long> gaps;                       // samples, gap_min to gap_max
  std::array<Best, kMetrics> best;
  std::vector<Score> idle_scores;  // per targets entry, after idle
  double slope_min = 0;            // V/s; 0 when unknown

  // Keeps sc where it beats a metric's best; a failure adds a reason (one per kind).
  void consider(const Score& sc, int target, int prev, long gap) {
    for (int m = 0; m < kMetrics; ++m)
      if (sc.m[m].valid() && sc.m[m].key < best[m].s.key) best[m] = {sc.m[m], target, prev, gap};
    if (!sc.pass) {
      Traffic t;
      if (prev >= 0) t.frames.push_back(pattern_frame(prev)), t.gaps.push_back(kLead);
      t.frames.push_back(pattern_frame(target));
      t.gaps.push_back(prev >= 0 ? static_cast<double>(gap) * dt : kLead);
      const std::string why = sc.reason.substr(0, sc.reason.find(':'));
      for (const std::string& r : dw.reasons)
        if (r.rfind(why, 0) == 0) return;
      dw.reasons.push_back(fmt::format("{} (traffic {})", sc.reason, traffic_text(t)));
    }
  }
};

// Memory and bounds (method items 2 and 3), then the patterns and gaps to try.
void set_bounds_and_histories(DirectionState& st) {
  const WorstOptions& opt = st.opt;
  DirectionWorst& dw = st.dw;
  const long half = st.half, pre = st.pre;
  const std::vector<double> env = pulse_envelope(st.e, half);
  long memory = 0;
  const long max_memory = to_samples(opt.max_memory, st.dt);
  while (memory < static_cast<long>(env.size()) && memory < max_memory &&
         bound_from(env, memory, half) > opt.tail_tol)
    memory += half;
  dw.memory = static_cast<double>(memory) * st.dt;
  dw.gap_min = opt.gap_min;
  st.gap_min = to_samples(opt.gap_min, st.dt);
  st.gap_step = to_samples(opt.gap_step, st.dt);
  // The previous byte's last half bit ends >= gap_min before the target, seen from the window's
  // first sample (pre before the target); anything older is >= 2 gap_min + frame back.
  dw.previous_bound = bound_from(env, st.gap_min - pre, half);
  dw.older_bound = bound_from(env, 2 * st.gap_min + st.frame - pre, half);
  // The previous byte matters up to the gap where it falls inside the tail tolerance.
  st.gap_max = st.gap_min;
  while (st.gap_max < memory + pre && bound_from(env, st.gap_max - pre, half) > opt.tail_tol)
    st.gap_max += st.gap_step;
  dw.gap_max = static_cast<double>(st.gap_max) * st.dt;
  st.targets = opt.targets;
  st.previous = opt.previous;
  if (st.targets.empty())
    for (int p = 0; p < 512; ++p) st.targets.push_back(p);
  if (st.previous.empty())
    for (int p = 0; p < 512; ++p) st.previous.push_back(p);
  for (long g = st.gap_min; g <= st.gap_max; g += st.gap_step) st.gaps.push_back(g);
}

// Stage 1: every target pattern after idle.
Status search_idle_targets(DirectionState& st) {
  st.idle_scores.assign(st.targets.size(), Score{});
  std::vector<double> wave;
  for (size_t i = 0; i < st.targets.size(); ++i) {
    if (st.opt.progress && i % 64 == 0)
      st.opt.progress("search, idle targets", static_cast<double>(i) / st.targets.size());
    st.search.target_wave(st.targets[i], wave);
    StatusOr<Score> sc = st.search.score(wave, st.targets[i]);
    if (!sc) return sc.status();
    st.idle_scores[i] = *sc;
    st.consider(*sc, st.targets[i], -1, 0);
  }
  return Status::Ok();
}

// Slowest threshold-crossing slope of the idle-history winners: a voltage change dv moves a
// crossing by about dv / slope (the time slack and the time bounds).
Status find_slope_min(DirectionState& st) {
  double slope_min = kInf;
  for (size_t m = 0; m < kMetrics; ++m) {
    if (st.best[m].target < 0) continue;
    const std::vector<double> v = st.search.target_wave(st.best[m].target);
    StatusOr<eye::CheckResult> c = st.search.check(v, st.best[m].target);
    if (!c) return c.status();
    for (const eye::PulseMetrics& p : c->pulses) {
      if (p.truncated) continue;
      slope_min = std::min(
          {slope_min, std::abs(slope_at(v, st.dt, p.a)), std::abs(slope_at(v, st.dt, p.b))});
    }
  }
  st.slope_min = !std::isfinite(slope_min) || slope_min <= 0 ? 0 : slope_min;
  return Status::Ok();
}

// Every target after every previous pattern at every gap (WorstOptions::exhaustive).
Status search_histories_exhaustively(DirectionState& st) {
  for (int t : st.targets) {
    const std::vector<double> base = st.search.target_wave(t);
    for (int q : st.previous)
      for (long g : st.gaps) {
        std::vector<double> v = base;
        st.search.add_previous(v, q, g);
        StatusOr<Score> sc = st.search.score(v, t);
        if (!sc) return sc.status();
        st.consider(*sc, t, q, g);
      }
  }
  return Status::Ok();
}

// Per metric, the `verify` lowest distinct histories (key, previous index, gap index), in
// order. A metric's key is the lowest of its models', so offering every model's values and
// keeping each history once, at its lowest, gives the metric's lowest histories; a value above
// the `verify`-th kept cannot enter (the kept one only gets lower). What is kept does not depend
// on the order of the offers.
class LowestHistories {
 public:
  using Entry = std::tuple<double, size_t, size_t>;
  explicit LowestHistories(int verify) : verify_(verify) {}
  bool full() const { return static_cast<int>(list_.size()) >= verify_; }
  double last_key() const { return std::get<0>(list_.back()); }
  const std::vector<Entry>& entries() const { return list_; }
  void offer(const Entry& en) {
    for (auto it = list_.begin(); it != list_.end(); ++it) {
      if (std::get<1>(*it) != std::get<1>(en) || std::get<2>(*it) != std::get<2>(en)) continue;
      if (!(en < *it)) return;  // the same history, already as low
      list_.erase(it);
      break;
    }
    if (full()) {
      if (!(en < list_.back())) return;
      list_.pop_back();
    }
    list_.insert(std::upper_bound(list_.begin(), list_.end(), en), en);
  }

 private:
  int verify_;
  std::vector<Entry> list_;
};

// The ranked history search: per candidate target, a first-order model of each metric's key
// in the previous byte's bits ranks every (previous pattern, gap) history, and only the
// `verify` lowest per metric are simulated exactly.
class RankedHistorySearch {
 public:
  static constexpr size_t kCols = kPatternBits + 1;
  explicit RankedHistorySearch(DirectionState& st);
  Status run();

 private:
  void build_columns();
  std::vector<std::vector<size_t>> candidates() const;
  Status rank_target(size_t ci, const std::vector<std::vector<size_t>>& cands);
  void rank_model(const Linear& model, LowestHistories& top);
  void rank_every_pattern(const double* cl, size_t j, LowestHistories& top) const;
  std::tuple<long, long, long> gap_range(const Term& term) const;
  Status verify_exactly(const std::array<LowestHistories, kMetrics>& top, int t,
                        const std::vector<double>& base);

  DirectionState& st_;
  long reach_ = 0;  // samples of U: the previous frame, the largest gap and the window
  size_t ng_ = 0;   // gaps
  // U[b][i]: the previous byte's response per pattern bit (PatternBasis), the column of bit
  // b - 1 (0: the base); u_q at window sample i for gap g is U_0(i - pre + frame + g) +
  // sum_b bit_b(q) U_{1 + b}(i - pre + frame + g).
  std::array<std::vector<double>, kCols> U_;
  std::vector<double> reach_of_;  // sum_b |U_b(i)|: no previous byte moves v at i by more
  bool every_pattern_ = false;    // `previous` is every pattern, in order
  std::vector<double> coef_;      // one model's, per gap: kCols (constant, then per bit)
};

RankedHistorySearch::RankedHistorySearch(DirectionState& st)
    : st_(st), reach_(st.frame + st.gap_max + st.search.len()), ng_(st.gaps.size()) {}

Status RankedHistorySearch::run() {
  build_columns();
  // Every pattern, in order: the ranking then enumerates the best patterns per gap instead of
  // trying each (the `previous` index is the pattern itself).
  every_pattern_ = st_.previous.size() == (1u << kPatternBits);
  for (size_t k = 0; every_pattern_ && k < st_.previous.size(); ++k)
    every_pattern_ = st_.previous[k] == static_cast<int>(k);
  const std::vector<std::vector<size_t>> cands = candidates();
  std::vector<size_t> all;
  for (const auto& c : cands) all.insert(all.end(), c.begin(), c.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  for (size_t n = 0; n < all.size(); ++n) {
    if (st_.opt.progress)
      st_.opt.progress("search, histories",
                       static_cast<double>(n) / static_cast<double>(all.size()));
    if (Status s = rank_target(all[n], cands); !s.ok()) return s;
  }
  return Status::Ok();
}

void RankedHistorySearch::build_columns() {
  const PatternBasis& basis = st_.search.basis();
  for (size_t b = 0; b < kCols; ++b) {
    std::vector<double>& u = U_[b];
    u.assign(static_cast<size_t>(reach_), 0.0);
    std::vector<std::pair<long, int>> edges;
    level_edges(b == 0 ? basis.base : basis.bit[b - 1], 0, st_.half, edges);
    add_edges(st_.e, edges, 0, u);
  }
  reach_of_.assign(static_cast<size_t>(reach_), 0.0);
  for (size_t b = 0; b < kCols; ++b)
    for (size_t i = 0; i < reach_of_.size(); ++i) reach_of_[i] += std::abs(U_[b][i]);
}

// Candidates per metric: the target patterns within the slack of the best after idle.
std::vector<std::vector<size_t>> RankedHistorySearch::candidates() const {
  const double slack_v = 2 * st_.dw.previous_bound;
  const double slack_t = st_.slope_min > 0 ? slack_v / st_.slope_min : 0;
  std::vector<std::vector<size_t>> cands(kMetrics);
  for (int m = 0; m < kMetrics; ++m) {
    const double slack = m < 2 ? slack_v : slack_t;
    std::vector<std::pair<double, size_t>> order;
    for (size_t i = 0; i < st_.targets.size(); ++i)
      if (st_.idle_scores[i].m[m].valid()) order.push_back({st_.idle_scores[i].m[m].key, i});
    std::sort(order.begin(), order.end());
    for (const auto& [key, i] : order) {
      if (static_cast<int>(cands[m].size()) >= st_.opt.max_candidates) break;
      if (!cands[m].empty() && key > order.front().first + slack) break;
      cands[m].push_back(i);
    }
  }
  return cands;
}

Status RankedHistorySearch::rank_target(size_t ci, const std::vector<std::vector<size_t>>& cands) {
  const int t = st_.targets[ci];
  const std::vector<double> base = st_.search.target_wave(t);
  StatusOr<eye::CheckResult> c = st_.search.check(base, t);
  if (!c) return c.status();
  std::vector<Linear> lin = linearize(*c, base, st_.rules, st_.dt);
  std::array<bool, kMetrics> wanted{};
  for (int m = 0; m < kMetrics; ++m)
    wanted[m] = std::find(cands[m].begin(), cands[m].end(), ci) != cands[m].end();
  lin.erase(
      std::remove_if(lin.begin(), lin.end(), [&](const Linear& l) { return !wanted[l.metric]; }),
      lin.end());
  // Models in order of their key after idle, so that each metric's list fills with low keys
  // first and models that cannot reach it are skipped (bound in rank_model).
  std::stable_sort(lin.begin(), lin.end(),
                   [](const Linear& a, const Linear& b) { return a.key0 < b.key0; });
  std::array<LowestHistories, kMetrics> top{
      LowestHistories(st_.opt.verify), LowestHistories(st_.opt.verify),
      LowestHistories(st_.opt.verify), LowestHistories(st_.opt.verify),
      LowestHistories(st_.opt.verify)};
  for (const Linear& model : lin) rank_model(model, top[static_cast<size_t>(model.metric)]);
  st_.dw.ranked += static_cast<long>(st_.previous.size() * ng_);
  return verify_exactly(top, t, base);
}

// A term reads u at term.sample - pre + frame + g: the gap indices whose read falls inside the
// wave (0 <= at + gaps[j] < reach) are [j0, j1); returns (at + gap_min, j0, j1).
std::tuple<long, long, long> RankedHistorySearch::gap_range(const Term& term) const {
  const long at = term.sample - st_.pre + st_.frame;
  const long gap_min = st_.gap_min, gap_step = st_.gap_step;
  const long j0 = std::max(0L, (-at - gap_min + gap_step - 1) / gap_step);
  const long j1 =
      std::min(static_cast<long>(ng_), (reach_ - at - gap_min + gap_step - 1) / gap_step);
  return std::tuple<long, long, long>{at + gap_min, j0, j1};
}

void RankedHistorySearch::rank_model(const Linear& model, LowestHistories& top) {
  const long gap_step = st_.gap_step;
  // No history moves the key below key0 - sum |coef| max_g reach(at + g): a model whose bound
  // is above the list's last, once full, cannot enter it.
  if (top.full()) {
    double drop = 0;
    for (const Term& term : model.terms) {
      const auto [first, j0, j1] = gap_range(term);
      double most = 0;
      for (long j = j0; j < j1; ++j)
        most = std::max(most, reach_of_[static_cast<size_t>(first + j * gap_step)]);
      drop += std::abs(term.coef) * most;
    }
    if (model.key0 - drop > top.last_key()) return;
  }
  // The model's predicted key for previous pattern q at gap j is affine in q's bits:
  // c(j, 0) + sum_b bit_b(q) c(j, 1 + b), stored as cl[j * kCols + ...]; over the gap grid
  // each term is one strided sweep of U.
  coef_.assign(kCols * ng_, 0.0);
  double* cl = coef_.data();
  for (size_t j = 0; j < ng_; ++j) cl[j * kCols] = model.key0;
  for (const Term& term : model.terms) {
    const auto [first, j0, j1] = gap_range(term);
    for (size_t b = 0; b < kCols; ++b) {
      const double* u = U_[b].data() + first;
      for (long j = j0; j < j1; ++j)
        cl[static_cast<size_t>(j) * kCols + b] += term.coef * u[j * gap_step];
    }
  }
  for (size_t j = 0; j < ng_; ++j) {
    if (every_pattern_) {
      rank_every_pattern(cl + j * kCols, j, top);
      continue;
    }
    for (size_t k = 0; k < st_.previous.size(); ++k) {
      double y = cl[j * kCols];
      for (size_t b = 0; b < kPatternBits; ++b)
        if (st_.previous[k] >> b & 1) y += cl[j * kCols + b + 1];
      top.offer({y, k, j});
    }
  }
}

// Gap j's lowest keys with every pattern allowed (cl: its kCols coefficients): the lowest key
// sets the bits whose coefficient is negative, and the next lowest flip the bits with the
// smallest |coefficient|; the r-th lowest flips only bits among the r smallest (each flip adds
// its |coefficient|), so the subsets of the `verify` smallest hold them all.
void RankedHistorySearch::rank_every_pattern(const double* cl, size_t j,
                                             LowestHistories& top) const {
  const size_t r = std::min<size_t>(static_cast<size_t>(st_.opt.verify), kPatternBits);
  std::array<std::pair<double, int>, kPatternBits> mag;  // |coefficient|, bit
  double lowest = cl[0];
  int q = 0;
  for (int b = 0; b < kPatternBits; ++b) {
    const double w = cl[static_cast<size_t>(b) + 1];
    if (w < 0) lowest += w, q |= 1 << b;
    mag[b] = {std::abs(w), b};
  }
  if (top.full()) {
    const double worst_kept = top.last_key();
    if (lowest > worst_kept) return;
    // Only the best pattern itself can enter when one flip already costs too much.
    double flip = kInf;
    for (const auto& m2 : mag) flip = std::min(flip, m2.first);
    if (lowest + flip > worst_kept) {
      top.offer({lowest, static_cast<size_t>(q), j});
      return;
    }
  }
  std::partial_sort(mag.begin(), mag.begin() + r, mag.end());
  // The subsets in increasing order of their members (mag ascending): a member that pushes the
  // key past the `verify`-th lowest ends its branch, as all later ones would.
  auto visit = [&](auto&& self, size_t from, double key, int p) -> void {
    top.offer({key, static_cast<size_t>(p), j});
    for (size_t i = from; i < r; ++i) {
      const double next = key + mag[i].first;
      if (top.full() && next > top.last_key()) break;
      self(self, i + 1, next, p ^ (1 << mag[i].second));
    }
  };
  visit(visit, 0, lowest, q);
}

// Simulates the kept histories exactly: base + u_q over the window, from the basis (the same
// sums add_previous makes).
Status RankedHistorySearch::verify_exactly(const std::array<LowestHistories, kMetrics>& top, int t,
                                           const std::vector<double>& base) {
  std::vector<std::pair<size_t, long>> exact;
  for (const LowestHistories& tm : top)
    for (const auto& [key, k, j] : tm.entries()) exact.push_back({k, st_.gaps[j]});
  std::sort(exact.begin(), exact.end());
  exact.erase(std::unique(exact.begin(), exact.end()), exact.end());
  std::vector<double> v(base.size());
  for (const auto& [k, g] : exact) {
    const int q = st_.previous[k];
    const size_t off = static_cast<size_t>(st_.frame + g - st_.pre);  // window sample 0 in U
    // One pass, a SIMD register of samples at a time, summing the base and set bits' columns
    // in registers: a pass per column stalled on its stores (13 % of the search).
    std::array<const double*, kCols> cols;
    size_t nc = 0;
    for (size_t b = 0; b < kCols; ++b)
      if (b == 0 || (q >> (b - 1) & 1)) cols[nc++] = U_[b].data() + off;
    namespace stdx = std::experimental;
    using V = stdx::native_simd<double>;
    size_t i = 0;
    for (; i + V::size() <= v.size(); i += V::size()) {
      V sum(base.data() + i, stdx::element_aligned);
      for (size_t col = 0; col < nc; ++col) sum += V(cols[col] + i, stdx::element_aligned);
      sum.copy_to(v.data() + i, stdx::element_aligned);
    }
    for (; i < v.size(); ++i) {
      double sum = base[i];
      for (size_t col = 0; col < nc; ++col) sum += cols[col][i];
      v[i] = sum;
    }
    StatusOr<Score> sc = st_.search.score(v, t);
    if (!sc) return sc.status();
    st_.consider(*sc, t, q, g);
  }
  return Status::Ok();
}

// Results: each metric's best as a WorstMetric with the traffic that replays it and the bound on
// what older traffic could add; a metric past its limit fails the direction.
void assemble_metrics(const DirectionState& st) {
  DirectionWorst& dw = st.dw;
  const double byte_duration = static_cast<double>(st.frame) * st.dt;
  dw.pass = dw.reasons.empty();
  for (int m = 0; m < kMetrics; ++m) {
    const Best& b = st.best[m];
    if (b.target < 0) continue;
    WorstMetric wm;
    wm.name = kNames[m];
    wm.value = b.s.value;
    wm.limit = b.s.limit;
    wm.margin = b.s.margin;
    wm.pulse_sign = b.s.sign;
    wm.role = b.s.role;
    if (b.prev >= 0) {
      wm.traffic.frames = {pattern_frame(b.prev), pattern_frame(b.target)};
      wm.traffic.gaps = {kLead, static_cast<double>(b.gap) * st.dt};
    } else {
      wm.traffic.frames = {pattern_frame(b.target)};
      wm.traffic.gaps = {kLead};
    }
    const double target_start = wm.traffic.frame_start(wm.traffic.frames.size() - 1, byte_duration);
    wm.pulse_time = target_start - static_cast<double>(st.pre) * st.dt + b.s.a;
    wm.record = target_start + byte_duration + 5e-6;
    // Older traffic moves v by at most older_bound, each of a width's or an edge's two crossings
    // by about that over its slope.
    wm.bound =
        m < 2 ? dw.older_bound : (st.slope_min > 0 ? 2 * dw.older_bound / st.slope_min : 0.0);
    if (wm.margin < 0) {
      dw.pass = false;
      dw.reasons.push_back(fmt::format("{} {:.4g} breaks its limit {:.4g} (traffic {})", wm.name,
                                       wm.value, wm.limit, traffic_text(wm.traffic)));
    }
    dw.metrics.push_back(std::move(wm));
  }
}

}  // namespace

StatusOr<DirectionWorst> worst_case_direction(const EdgeResponse& e, const eye::Rules& rules,
                                              const WorstOptions& opt) {
  if (Status s = opt.validate(); !s.ok()) return s;
  const auto start = std::chrono::steady_clock::now();
  DirectionWorst dw;
  dw.rules = rules;
  Search search(e, rules, opt);
  if (Status s = search.init(); !s.ok()) return s;
  DirectionState st(e, rules, opt, search, dw);
  set_bounds_and_histories(st);
  if (Status s = search_idle_targets(st); !s.ok()) return s;
  if (Status s = find_slope_min(st); !s.ok()) return s;
  if (dw.previous_bound > opt.tail_tol) {
    Status s = opt.exhaustive ? search_histories_exhaustively(st) : RankedHistorySearch(st).run();
    if (!s.ok()) return s;
  }
  assemble_metrics(st);
  dw.scored = search.scored_;
  dw.seconds = seconds_since(start);
  return dw;
}

StatusOr<WorstResult> worst_case(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                 const WorstOptions& opt, std::vector<EdgeResponse> edges,
                                 std::vector<int> same) {
  if (Status s = opt.validate(); !s.ok()) return s;
  const size_t nd = spec.stimulus.directions.size();
  if (!edges.empty() && edges.size() != nd)
    return Status::Error(
        fmt::format("internal error: {} edge responses for {} directions", edges.size(), nd));
  if (!same.empty() && same.size() != nd)
    return Status::Error(
        fmt::format("internal error: {} circuit matches for {} directions", same.size(), nd));
  for (size_t di = 0; di < same.size(); ++di)
    if (same[di] >= static_cast<int>(di))
      return Status::Error(fmt::format(
          "internal error: direction {} is matched with a later one ({})", di, same[di]));
  const auto start = std::chrono::steady_clock::now();
  WorstResult out;
  std::vector<std::string> keys;  // link::circuit_key per direction done
  for (size_t di = 0; di < spec.stimulus.directions.size(); ++di) {
    const link::Direction d = spec.stimulus.directions[di];
    StatusOr<link::ExpandedLink> ex = link::expand_link(spec, parts, d, opt.expand);
    if (!ex) return ex.status();
    // A mirror-symmetric link (the same parts at both ends) is the same circuit both ways: its
    // worst case is computed once and reported for each direction.
    // The earlier direction this one is the same circuit as: the caller's match, or the first
    // with the same circuit key.
    int match = same.empty() ? -1 : same[di];
    if (same.empty()) {
      keys.push_back(link::circuit_key(*ex));
      const auto it = std::find(keys.begin(), keys.end() - 1, keys.back());
      if (it != keys.end() - 1) match = static_cast<int>(it - keys.begin());
    }
    if (match >= 0) {
      DirectionWorst dw = out.directions[static_cast<size_t>(match)];
      dw.same_as = link::direction_name(dw.direction);
      dw.seconds = dw.edge.seconds = 0;  // nothing computed for it
      dw.direction = d;
      dw.description = ex->description;
      dw.receiver = ex->receiver;
      out.directions.push_back(std::move(dw));
      continue;
    }
    StatusOr<eye::Rules> rules = eye::load_rules(ex->rules);
    if (!rules) return rules.status();
    WorstOptions dopt = opt;  // progress says which direction
    if (opt.progress)
      dopt.progress = [&](const std::string& what, double fraction) {
        opt.progress(fmt::format("{} {}", link::direction_name(d), what), fraction);
      };
    StatusOr<EdgeResponse> e =
        edges.empty() ? edge_response(spec, parts, d, dopt) : std::move(edges[di]);
    if (!e) return e.status();
    StatusOr<DirectionWorst> dw = worst_case_direction(*e, *rules, dopt);
    if (!dw) return dw.status().with_context(ex->description + ", worst case");
    dw->direction = d;
    dw->description = ex->description;
    dw->receiver = ex->receiver;
    dw->edge = std::move(*e);
    out.pass = out.pass && dw->pass;
    out.directions.push_back(std::move(*dw));
  }
  out.seconds = seconds_since(start);
  return out;
}

link::StimulusSpec reproduce_spec(const WorstMetric& m, link::Direction d) {
  link::StimulusSpec st;
  for (size_t i = 0; i < m.traffic.frames.size(); ++i) {
    const ByteFrame& f = m.traffic.frames[i];
    st.frames.push_back(fmt::format("raw {:02X} nocrc{}", f.byte, f.error_bit ? " err" : ""));
    st.gaps.push_back(m.traffic.gaps[i]);
  }
  st.directions = {d};
  return st;
}

}  // namespace isolink::analysis
