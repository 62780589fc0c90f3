#include "eye/check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <experimental/simd>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "base/csv.h"
#include "base/file_io.h"
#include "base/hex.h"
#include "eye/commands.h"
#include "eye/verdict.h"

namespace isolink::eye {
namespace {

using json = nlohmann::ordered_json;

json num(double x) {
  return std::isnan(x) ? json(nullptr) : json(x);
}
json opt_num(const std::optional<double>& x, double scale = 1) {
  return x ? json(*x * scale) : json(nullptr);
}
double ns(double s) {
  return s * 1e9;
}
const char* sign_str(int s) {
  return s > 0 ? "+" : "-";
}

std::string byte_hex(uint8_t b) {
  return to_hex(std::span<const uint8_t>(&b, 1));
}

template <class F>
std::optional<double> fold(const std::vector<PulseMetrics>& ps, F pick, bool want_min) {
  std::optional<double> r;
  for (const PulseMetrics& p : ps) {
    std::optional<double> x = pick(p);
    if (!x) continue;
    if (!r || (want_min ? *x < *r : *x > *r)) r = *x;
  }
  return r;
}

bool is_time_metric(const std::string& m) {
  return m == "width" || m == "edge";
}

std::string place(const PulseMetrics& p) {
  std::string s = fmt::format("pulse {} ({} at {:.4f} us", p.index, sign_str(p.sign), p.a * 1e6);
  if (p.frame >= 0) s += fmt::format(", frame {}", p.frame);
  if (!p.role.empty()) s += ", " + p.role;
  return s + ")";
}

}  // namespace

size_t CheckResult::failing() const {
  return static_cast<size_t>(std::count_if(pulses.begin(), pulses.end(),
                                           [](const PulseMetrics& p) { return p.failing(); }));
}
std::optional<double> CheckResult::vstart_min() const {
  return fold(
      pulses,
      [](const PulseMetrics& p) {
        return p.vstart.measured() ? std::optional(p.vstart.value) : std::nullopt;
      },
      true);
}
std::optional<double> CheckResult::vend_min() const {
  return fold(
      pulses,
      [](const PulseMetrics& p) {
        return p.vend.measured() ? std::optional(p.vend.value) : std::nullopt;
      },
      true);
}
std::optional<double> CheckResult::width_min() const {
  return fold(
      pulses,
      [](const PulseMetrics& p) {
        return !p.idle && p.width.measured() ? std::optional(p.width.value) : std::nullopt;
      },
      true);
}
std::optional<double> CheckResult::width_max() const {
  return fold(
      pulses,
      [](const PulseMetrics& p) {
        return !p.idle && p.width.measured() ? std::optional(p.width.value) : std::nullopt;
      },
      false);
}
std::optional<double> CheckResult::edge_max() const {
  return fold(
      pulses,
      [](const PulseMetrics& p) {
        return p.edge.measured() ? std::optional(p.edge.value) : std::nullopt;
      },
      false);
}

namespace {
// Not inlined: inlined, its accumulator became the caller's `peak`, whose address fmt takes, and
// the loop stored it to memory at every sample (17 % of the worst-case search's time).
[[gnu::noinline]] double largest_magnitude(std::span<const double> v) {
  return running_max(v, 0, v.size(), 0.0, [](auto x) {
    using std::abs;
    return abs(x);
  });
}

// Where to start checking the samples one by one (a number not finite, time not increasing):
// past all but the last few when, a SIMD register of samples at a time, every x * 0 sums to 0
// (an infinity or a NaN makes it NaN) and every time step is positive; 0 when something is wrong
// somewhere, so that the one-by-one check finds and names it.
size_t first_unordered(std::span<const double> t, std::span<const double> v) {
  namespace stdx = std::experimental;
  using V = stdx::native_simd<double>;
  const size_t n = std::min(t.size(), v.size());
  if (n == 0) return 0;
  V probe = 0.0, step = std::numeric_limits<double>::infinity();
  size_t i = 1;
  for (; i + V::size() <= n; i += V::size()) {
    const V ti(t.data() + i, stdx::element_aligned),
        before(t.data() + i - 1, stdx::element_aligned), vi(v.data() + i, stdx::element_aligned);
    probe += ti * 0.0 + vi * 0.0;
    step = stdx::min(step, ti - before);
  }
  const bool ok =
      t[0] * 0.0 + v[0] * 0.0 == 0.0 && stdx::all_of(probe == 0.0) && stdx::all_of(step > 0.0);
  return ok ? i : 0;
}

// The input's errors: samples not finite or time not increasing, rules that do not validate, a
// command idle that is not a time.
Status validate_input(std::span<const double> t, std::span<const double> v, const Rules& rules,
                      const CheckOptions& opt) {
  if (t.size() != v.size())
    return Status::Error(fmt::format("{} time samples but {} values", t.size(), v.size()));
  if (t.size() < 2) return Status::Error("a waveform needs at least two samples");
  for (size_t i = first_unordered(t, v); i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || !std::isfinite(v[i]))
      return Status::Error(fmt::format("sample {} is not a finite number", i));
    if (i > 0 && !(t[i] > t[i - 1]))
      return Status::Error(fmt::format("time does not increase at sample {} ({:g} s after {:g} s)",
                                       i, t[i], t[i - 1]));
  }
  if (Status s = validate_rules(rules); !s.ok()) return s;
  if (!(opt.command_idle >= 0) || !std::isfinite(opt.command_idle))
    return Status::Error(
        fmt::format("command idle {:g} s is not a finite time >= 0", opt.command_idle));
  return Status::Ok();
}

// The result's header: the rule set, the frame format (the rules' with opt's overrides), the
// record's span; an error when the SOF value is neither 0 nor 1.
Status start_result(std::span<const double> t, const Rules& rules, const CheckOptions& opt,
                    CheckResult* r) {
  r->rules = rules.name;
  r->rules_source = rules.source;
  r->tone = rules.tone;
  r->frame_format = rules.frame;
  if (opt.sof) r->frame_format.sof = *opt.sof;
  if (opt.sof_value) r->frame_format.sof_value = *opt.sof_value;
  if (opt.bit_order) r->frame_format.bit_order = *opt.bit_order;
  if (r->frame_format.sof_value != 0 && r->frame_format.sof_value != 1)
    return Status::Error(fmt::format("SOF value {} is neither 0 nor 1", r->frame_format.sof_value));
  r->samples = t.size();
  r->t_begin = t.front();
  r->t_end = t.back();
  return Status::Ok();
}

// Rule 8.4a: when a run's half bits make whole frames up to its second-last pulse, its last
// pulse is the line's kickback after the postamble (AC coupling swinging back past the threshold
// when the driver goes idle), not the start of a frame: the receiver blanks it (tblank), and
// joining it would stretch the postamble's width to the kickback's start.
void drop_kickback_tails(const Rules& rules, size_t frame_len, Segmentation* seg) {
  std::vector<size_t> tails;
  for (const FrameSpan& fs : seg->frames) {
    size_t acc = 0;
    for (size_t p = fs.first; p < fs.last; ++p) acc += pulse_half_bits(*seg, p, rules);
    if (fs.last > fs.first && acc % frame_len == 0) tails.push_back(fs.last);
  }
  for (auto it = tails.rbegin(); it != tails.rend(); ++it) drop_frame_tail(seg, *it);
}

// What decoding found beyond the frames: the hints and the verdict read these.
struct DecodeCounts {
  size_t structural = 0;  // frames whose couplets form a byte (metrics aside)
  size_t inverted = 0;    // runs that decode only with every sign flipped (P and N swapped?)
};

// The first fault of a decoded frame's pulses, in the order a receiver meets them: a pulse the
// record cuts, a timing failure, the decoder's own fault, a weak bit; none leaves fr's fault empty.
void set_frame_fault(const std::vector<PulseMetrics>& pulses, const DecodedByte& d,
                     FrameResult* fr) {
  const PulseMetrics* trunc = nullptr;
  const PulseMetrics* timing = nullptr;
  const PulseMetrics* weak = nullptr;
  for (size_t p = fr->first_pulse; p <= fr->last_pulse; ++p) {
    const PulseMetrics& pm = pulses[p];
    if (pm.truncated && !trunc) trunc = &pm;
    if (pm.timing_fail && !timing) timing = &pm;
    if (pm.weak_fail && !weak) weak = &pm;
  }
  auto first_fail = [](const PulseMetrics& pm, const char* a, const char* b) {
    for (const std::string& f : pm.fails)
      if (f.rfind(a, 0) == 0 || (b && f.rfind(b, 0) == 0)) return f;
    return pm.fails.empty() ? std::string() : pm.fails.front();
  };
  if (trunc) {
    fr->fault = "truncated";
    fr->detail = "the record cuts " + place(*trunc);
  } else if (timing) {
    fr->fault = "timing";
    fr->detail = place(*timing) + ": " + first_fail(*timing, "width", "edge");
  } else if (!d.fault.empty()) {
    fr->fault = d.fault;
    fr->detail = d.detail;
  } else if (weak) {
    fr->fault = "weak bit";
    fr->detail = place(*weak) + ": " + first_fail(*weak, "vstart", "vend");
  }
}

// Rule 8.12: decodes one run of joined pulses into r's frames (and bytes), marking each pulse's
// frame and role.
void decode_run(const FrameSpan& fs, const Rules& rules, CheckResult* r, DecodeCounts* counts) {
  const FrameFormat& format = r->frame_format;
  std::vector<int> hb;
  std::vector<size_t> hb_pulse;
  std::vector<int> hb_off;
  for (size_t p = fs.first; p <= fs.last; ++p)
    for (int k = 0; k < r->pulses[p].half_bits; ++k) {
      hb.push_back(r->pulses[p].sign);
      hb_pulse.push_back(p);
      hb_off.push_back(k);
    }
  std::vector<DecodedByte> decoded;
  if (rules.tone) {
    DecodedByte d;
    d.half_count = hb.size();
    decoded.push_back(d);
  } else {
    decoded = decode_half_bits(hb, format);
    const size_t ok = static_cast<size_t>(std::count_if(
        decoded.begin(), decoded.end(), [](const DecodedByte& d) { return d.byte.has_value(); }));
    counts->structural += ok;
    if (ok == 0) {
      std::vector<int> flipped(hb.size());
      std::transform(hb.begin(), hb.end(), flipped.begin(), [](int x) { return -x; });
      const std::vector<DecodedByte> alt = decode_half_bits(flipped, format);
      if (!alt.empty() && alt.front().byte) ++counts->inverted;
    }
  }
  for (const DecodedByte& d : decoded) {
    FrameResult fr;
    const size_t h0 = d.first_half, h1 = d.first_half + d.half_count - 1;
    fr.first_pulse = hb_pulse[h0];
    fr.last_pulse = hb_pulse[h1];
    fr.start = r->pulses[fr.first_pulse].a + hb_off[h0] * rules.pulse_time;
    fr.error_bit = d.error_bit;
    const int idx = static_cast<int>(r->frames.size());
    for (size_t h = h0; h <= h1; ++h) {
      PulseMetrics& p = r->pulses[hb_pulse[h]];
      const std::string role = rules.tone ? "" : half_bit_role(h - h0, format);
      if (p.frame != idx) {
        p.frame = idx;
        p.role = role;
      } else if (!role.empty() && role != p.role) {
        p.role += "/" + role;
      }
    }
    set_frame_fault(r->pulses, d, &fr);
    if (fr.fault.empty() && d.byte) {
      fr.byte = d.byte;
      r->bytes.push_back(*d.byte);
    }
    r->frames.push_back(std::move(fr));
  }
}

// The decoded bytes against opt.expect: expect_match false and expect_detail on the first
// difference.
void compare_expected(const CheckOptions& opt, CheckResult* r) {
  if (!opt.expect) return;
  r->expect = opt.expect;
  const auto& e = *opt.expect;
  for (size_t i = 0; i < std::max(e.size(), r->bytes.size()); ++i) {
    if (i >= e.size() || i >= r->bytes.size()) {
      r->expect_match = false;
      r->expect_detail = fmt::format("expected {} bytes, decoded {}", e.size(), r->bytes.size());
      break;
    }
    if (e[i] != r->bytes[i]) {
      r->expect_match = false;
      r->expect_detail =
          fmt::format("byte {}: expected {}, decoded {}", i, byte_hex(e[i]), byte_hex(r->bytes[i]));
      break;
    }
  }
}

// Rule 8.11: the verdict (eye/verdict.h): failures measured on the link, then what keeps the
// record from showing that the link works (no verdict of pass without it).
Verdict judge(const CheckResult& r, const Rules& rules, double peak, size_t runs,
              const DecodeCounts& counts) {
  VerdictFacts facts;
  facts.peak = peak;
  facts.decodes = rules.tone || counts.structural > 0;
  facts.runs = runs;
  if (size_t nf = r.failing())
    facts.failures.push_back(fmt::format("{} of {} pulses fail", nf, r.pulses.size()));
  for (size_t i = 0; i < r.frames.size(); ++i)
    if (r.frames[i].fails())
      facts.failures.push_back(fmt::format("frame {} at {:.4f} us does not decode: {} ({})", i,
                                           r.frames[i].start * 1e6, r.frames[i].fault,
                                           r.frames[i].detail));
  if (!r.expect_match)
    facts.failures.push_back("decoded bytes differ from the expected: " + r.expect_detail);
  size_t cut = 0;
  for (const PulseMetrics& p : r.pulses) cut += p.truncated ? 1 : 0;
  if (cut > 0)
    facts.open.push_back(fmt::format(
        "the record cuts {} pulse{} (first: {}): {} not judged", cut, cut == 1 ? "" : "s",
        place(*std::find_if(r.pulses.begin(), r.pulses.end(),
                            [](const PulseMetrics& p) { return p.truncated; })),
        cut == 1 ? "it is" : "they are"));
  return decide_verdict(r.pulses, rules, facts);
}

// Hints: the samples look like the wrong units, the wrong column or swapped P and N.
void add_hints(const Rules& rules, double peak, const DecodeCounts& counts, CheckResult* r) {
  const bool decoded_nothing = !rules.tone && counts.structural == 0;
  if (peak > kImplausibleVth * rules.vth)
    r->hints.push_back(fmt::format(
        "|v| reaches {:.4g} V, over {:g}x the {:g} V threshold: a column in mV read as volts? "
        "(a units row such as \"s,mV\" under the names sets the scale)",
        peak, kImplausibleVth, rules.vth));
  else if (r->pulses.empty() && peak > 0 && peak < rules.vth / 100)
    r->hints.push_back(fmt::format(
        "|v| stays under {:.4g} V, 1/100 of the threshold: the wrong column (an idle channel, a "
        "trigger or math trace), or volts read as kV?",
        peak));
  else if (r->pulses.empty() && peak < rules.vth)
    r->hints.push_back(
        fmt::format("|v| peaks at {:.4g} V, under the {:g} V threshold: the wrong column, a probe "
                    "attenuation not applied, or one leg (P or N) alone instead of P - N?",
                    peak, rules.vth));
  if (!decoded_nothing || r->pulses.empty()) return;
  std::vector<double> widths;
  for (const PulseMetrics& p : r->pulses)
    if (!p.truncated) widths.push_back(p.b - p.a);
  if (!widths.empty()) {
    std::nth_element(widths.begin(), widths.begin() + widths.size() / 2, widths.end());
    const double w = widths[widths.size() / 2];
    if (w > 20 * rules.pulse_time || w < rules.pulse_time / 20)
      r->hints.push_back(fmt::format(
          "the median pulse lasts {:.4g} s against a {:g} ns half bit: time in us or ms read "
          "as seconds (or the reverse)? A units row such as \"(us)\" sets the scale",
          w, ns(rules.pulse_time)));
  }
  if (counts.inverted > 0)
    r->hints.push_back(fmt::format(
        "{} run{} decode{} with the signs flipped: P and N swapped (or the probe inverted)?",
        counts.inverted, counts.inverted == 1 ? "" : "s", counts.inverted == 1 ? "s" : ""));
}

}  // namespace

StatusOr<CheckResult> check_samples(std::span<const double> t, std::span<const double> v,
                                    const Rules& rules, const CheckOptions& opt) {
  if (Status s = validate_input(t, v, rules, opt); !s.ok()) return s;
  CheckResult r;
  if (Status s = start_result(t, rules, opt, &r); !s.ok()) return s;
  Segmentation seg = segment(t, v, segment_params(rules));
  if (!rules.tone) drop_kickback_tails(rules, r.frame_format.half_bits(), &seg);
  r.pulses = measure_pulses(t, v, seg, rules, opt.warning_texts);
  r.ringing = seg.ringing;
  r.idle = find_idle_undershoots(t, v, seg, rules);
  DecodeCounts counts;
  for (const FrameSpan& fs : seg.frames) decode_run(fs, rules, &r, &counts);
  compare_expected(opt, &r);
  r.worst = worst_margins(r.pulses);
  const double peak = largest_magnitude(v);
  const Verdict verdict = judge(r, rules, peak, seg.frames.size(), counts);
  add_hints(rules, peak, counts, &r);
  r.reasons = verdict.reasons;
  r.pass = verdict.kind == VerdictKind::kPass;
  r.inconclusive = verdict.kind == VerdictKind::kInconclusive;
  // The commands the bytes carry: reported beside the verdict, never part of it (a malformed
  // command on a clean waveform is the firmware's, not the link's).
  if (opt.commands) r.commands = parse_commands(r, opt.command_idle);
  return r;
}

StatusOr<CheckResult> check_waveform(const Waveform& w, const Rules& rules, const CheckOptions& opt,
                                     size_t column) {
  if (column >= w.columns.size())
    return Status::Error(fmt::format("the waveform has no column {}", column));
  return check_samples(w.time, w.columns[column], rules, opt);
}

json to_json(const CheckResult& r) {
  json j;
  j["verdict"] = r.verdict();
  j["reasons"] = r.reasons;
  j["hints"] = r.hints;
  j["rules"] = r.rules;
  j["rules_source"] = r.rules_source;
  j["samples"] = r.samples;
  j["t_begin_s"] = r.t_begin;
  j["t_end_s"] = r.t_end;

  json worst = json::object();
  for (const WorstMargin& w : r.worst) {
    const bool tm = is_time_metric(w.metric);
    const double k = tm ? 1e9 : 1.0;
    worst[w.metric] = {{"value", w.j.value * k},
                       {"limit", w.j.limit * k},
                       {"margin", w.j.margin * k},
                       {"unit", tm ? "ns" : "V"},
                       {"pulse", w.pulse},
                       {"time_s", w.time},
                       {"frame", w.frame >= 0 ? json(w.frame) : json(nullptr)},
                       {"bit", w.role.empty() ? json(nullptr) : json(w.role)}};
  }
  size_t frames_failing = 0;
  for (const FrameResult& f : r.frames) frames_failing += f.fails() ? 1 : 0;
  j["summary"] = {{"pulses", r.pulses.size()},
                  {"failing", r.failing()},
                  {"frames", r.frames.size()},
                  {"frames_failing", frames_failing},
                  {"ringing", r.ringing.size()},
                  {"idle_undershoots", r.idle.size()},
                  {"vstart_min", opt_num(r.vstart_min())},
                  {"vend_min", opt_num(r.vend_min())},
                  {"width_min_ns", opt_num(r.width_min(), 1e9)},
                  {"width_max_ns", opt_num(r.width_max(), 1e9)},
                  {"edge_max_ns", opt_num(r.edge_max(), 1e9)},
                  {"worst", worst}};

  // Memory linear in what is printed: at most kMaxJsonPulses pulses in detail (a JSON node per
  // field costs far more than the pulse; 2M pulses took 3.6 GB). --pulses-csv streams them all.
  json pulses = json::array();
  for (const PulseMetrics& p : r.pulses) {
    if (pulses.size() == kMaxJsonPulses) break;
    json cls = p.truncated ? json(nullptr) : (p.idle ? json("idle") : json(p.k));
    json dips = json::array();
    for (const Dip& d : p.dips)
      dips.push_back(
          {{"start_s", d.start}, {"length_ns", ns(d.end - d.start)}, {"lowest", d.lowest}});
    pulses.push_back({{"index", p.index},
                      {"sign", p.sign},
                      {"start_s", p.a},
                      {"end_s", p.b},
                      {"width_ns", num(ns(p.width.value))},
                      {"class", cls},
                      {"edge_ns", num(ns(p.edge.value))},
                      {"vstart", num(p.vstart.value)},
                      {"vend", num(p.vend.value)},
                      {"droop", num(p.droop.value)},
                      {"dips", dips},
                      {"frame", p.frame >= 0 ? json(p.frame) : json(nullptr)},
                      {"bit", p.role.empty() ? json(nullptr) : json(p.role)},
                      {"fails", p.fails},
                      {"warnings", p.warnings}});
  }
  j["pulses"] = std::move(pulses);
  j["pulses_omitted"] = r.pulses.size() - std::min(r.pulses.size(), kMaxJsonPulses);

  json ringing = json::array();
  for (const Ringing& g : r.ringing)
    if (ringing.size() < kMaxJsonPulses)
      ringing.push_back({{"start_s", g.start},
                         {"end_s", g.end},
                         {"duration_ns", ns(g.end - g.start)},
                         {"sign", g.sign},
                         {"peak", g.peak},
                         {"peak_s", g.peak_t},
                         {"after_frame", g.after_frame}});
  j["ringing"] = std::move(ringing);
  json idle = json::array();
  for (const IdleUndershoot& u : r.idle)
    if (idle.size() < kMaxJsonPulses)
      idle.push_back({{"start_s", u.start},
                      {"end_s", u.end},
                      {"sign", u.sign},
                      {"peak", u.peak},
                      {"peak_s", u.peak_t},
                      {"after_pulse", u.after_pulse}});
  j["idle"] = std::move(idle);

  json frames = json::array();
  for (const FrameResult& f : r.frames)
    frames.push_back({{"start_s", f.start},
                      {"byte", f.byte ? json(byte_hex(*f.byte)) : json(nullptr)},
                      {"fault", f.fault.empty() ? json(nullptr) : json(f.fault)},
                      {"detail", f.detail.empty() ? json(nullptr) : json(f.detail)},
                      {"error_bit", f.error_bit},
                      {"first_pulse", f.first_pulse},
                      {"last_pulse", f.last_pulse}});
  json decoded = {
      {"bytes", to_hex(r.bytes)},
      {"format",
       {{"sof", r.frame_format.sof},
        {"sof_value", r.frame_format.sof_value},
        {"bit_order", r.frame_format.bit_order == BitOrder::kLsbFirst ? "lsb" : "msb"}}},
      {"frames", std::move(frames)}};
  if (r.tone) decoded["format"] = nullptr;
  if (r.expect) {
    decoded["expect"] = to_hex(*r.expect);
    decoded["match"] = r.expect_match;
    decoded["mismatch"] = r.expect_detail.empty() ? json(nullptr) : json(r.expect_detail);
  }
  j["decoded"] = std::move(decoded);
  set_commands_json(r, j);
  return j;
}

std::string summary_text(const CheckResult& r, const std::string& source) {
  std::string out;
  const size_t nf = r.failing();
  size_t frames_failing = 0;
  for (const FrameResult& f : r.frames) frames_failing += f.fails() ? 1 : 0;
  out += fmt::format("{}{} (rules {})\n", source.empty() ? "" : source + ": ",
                     r.pass           ? "PASS"
                     : r.inconclusive ? "INCONCLUSIVE"
                                      : "FAIL",
                     r.rules);
  for (const std::string& why : r.reasons) out += "  " + why + "\n";
  for (const std::string& hint : r.hints) out += "  hint: " + hint + "\n";
  if (const std::string note = commands_note(r); !note.empty()) out += "  " + note + "\n";
  if (!r.worst.empty()) {
    out += "worst margin per metric:\n";
    for (const WorstMargin& w : r.worst) {
      const PulseMetrics& p = r.pulses[w.pulse];
      if (is_time_metric(w.metric))
        out += fmt::format("  {:<7}{:>+9.1f} ns  {:7.1f} ns vs {:5.0f} ns  {}\n", w.metric,
                           ns(w.j.margin), ns(w.j.value), ns(w.j.limit), place(p));
      else
        out += fmt::format("  {:<7}{:>+9.1f} mV  {:7.3f} V  vs {:5.2f} V   {}\n", w.metric,
                           w.j.margin * 1e3, w.j.value, w.j.limit, place(p));
    }
  }
  out += fmt::format(
      "counts: {} pulses ({} failing), {} ringing, {} idle undershoots, {} {} "
      "({} failing)\n",
      r.pulses.size(), nf, r.ringing.size(), r.idle.size(), r.frames.size(),
      r.tone ? "runs" : "frames", frames_failing);
  if (!r.tone) {
    constexpr size_t kShown = 64;  // a long record decodes thousands: the JSON has them all
    const std::span<const uint8_t> shown(r.bytes.data(), std::min(r.bytes.size(), kShown));
    out += "decoded: " + (r.bytes.empty() ? std::string("(none)") : to_hex(shown));
    if (r.bytes.size() > kShown) out += fmt::format(" ... ({} bytes in all)", r.bytes.size());
    if (r.expect)
      out += r.expect_match ? "  (as expected)"
                            : "  (expected " + to_hex(*r.expect) + ": " + r.expect_detail + ")";
    out += "\n";
    out += commands_text(r.commands);
  }
  const size_t kMax = 20;
  std::vector<std::string> fails, warns;
  for (const PulseMetrics& p : r.pulses) {
    for (const std::string& f : p.fails) fails.push_back(place(p) + ": " + f);
    for (const std::string& w : p.warnings) warns.push_back(place(p) + ": " + w);
  }
  for (size_t i = 0; i < r.frames.size(); ++i)
    if (!r.frames[i].fault.empty())
      (r.frames[i].fails() ? fails : warns)
          .push_back(fmt::format("frame {} at {:.4f} us: {}: {}", i, r.frames[i].start * 1e6,
                                 r.frames[i].fault, r.frames[i].detail));
  for (const Ringing& g : r.ringing)
    warns.push_back(
        g.after_frame
            ? fmt::format("kickback after a frame: {} excursion of {:.1f} ns at {:.4f} us, peak "
                          "{:.3f} V (the line swinging back past the threshold after the "
                          "postamble; allowed: the receiver blanks it)",
                          sign_str(g.sign), ns(g.end - g.start), g.start * 1e6, g.peak)
            : fmt::format("ringing: {} excursion of {:.1f} ns at {:.4f} us, peak {:.3f} V "
                          "(not a pulse)",
                          sign_str(g.sign), ns(g.end - g.start), g.start * 1e6, g.peak));
  for (const IdleUndershoot& u : r.idle)
    warns.push_back(fmt::format("idle undershoot: {} to {:.3f} V at {:.4f} us after pulse {}",
                                sign_str(u.sign), u.sign * u.peak, u.peak_t * 1e6, u.after_pulse));
  auto list = [&](const char* title, const std::vector<std::string>& items) {
    if (items.empty()) return;
    out += fmt::format("{} ({}):\n", title, items.size());
    for (size_t i = 0; i < std::min(items.size(), kMax); ++i) out += "  " + items[i] + "\n";
    if (items.size() > kMax) out += fmt::format("  ... and {} more\n", items.size() - kMax);
  };
  list("failures", fails);
  list("warnings", warns);
  return out;
}

Status write_pulses_csv(const CheckResult& r, const std::string& path) {
  StatusOr<OutputFile> f = OutputFile::open(path);
  if (!f) return f.status();
  auto cell = [](double x, double scale = 1) {
    return std::isnan(x) ? std::string() : fmt::format("{:.9g}", x * scale);
  };
  auto joined = [](const std::vector<std::string>& items) {
    std::string s;
    for (const std::string& i : items) s += (s.empty() ? "" : " | ") + i;
    return csv_field(s);
  };
  if (Status s = f->write(
          "index,sign,start_s,end_s,width_ns,class,edge_ns,vstart,vend,droop,frame,bit,fails,"
          "warnings\n");
      !s.ok())
    return s;
  for (const PulseMetrics& p : r.pulses) {
    const std::string cls = p.truncated ? "" : (p.idle ? "idle" : std::to_string(p.k));
    const std::string line = fmt::format(
        "{},{},{:.12g},{:.12g},{},{},{},{},{},{},{},{},{},{}\n", p.index, p.sign, p.a, p.b,
        cell(p.width.value, 1e9), cls, cell(p.edge.value, 1e9), cell(p.vstart.value),
        cell(p.vend.value), cell(p.droop.value), p.frame >= 0 ? std::to_string(p.frame) : "",
        p.role, joined(p.fails), joined(p.warnings));
    if (Status s = f->write(line); !s.ok()) return s;
  }
  return f->commit();
}

}  // namespace isolink::eye
