#include "reports/compare_report.h"

#include <fmt/format.h>

#include <cmath>

#include "analysis/sweep_spec.h"
#include "eye/commands.h"
#include "netlists/link/cards.h"

namespace isolink::reports {
namespace {

using analysis::Clipping;
using analysis::CompareResult;
using analysis::Finding;
using analysis::FitKey;
using analysis::MetricSummary;
using analysis::Residual;
namespace sweep = analysis::sweep;

using json = nlohmann::ordered_json;

// Non-finite numbers never reach the output: null instead.
json num(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

json residual_json(const Residual& r) {
  return {{"rms_v", num(r.rms_v)},
          {"max_v", num(r.max_v)},
          {"samples", r.samples},
          {"clipped", r.clipped}};
}

json clipping_json(const Clipping& c) {
  json j = {{"high_v", nullptr}, {"low_v", nullptr}, {"samples", c.samples}};
  if (c.high_v) j["high_v"] = num(*c.high_v);
  if (c.low_v) j["low_v"] = num(*c.low_v);
  return j;
}

// One sentence on a clipping capture, or "".
std::string clipping_sentence(const CompareResult& r) {
  const Clipping& c = r.clipping;
  if (!c.high_v && !c.low_v) return "";
  std::string rails;
  if (c.low_v) rails = fmt::format("{:.4g} V", *c.low_v);
  if (c.high_v) rails += fmt::format("{}{:+.4g} V", c.low_v ? " and " : "", *c.high_v);
  return fmt::format(
      "the capture clips at {} ({} samples on the rails): the scope's vertical range cut the "
      "waveform, so where the design goes beyond a rail the difference is not counted ({} of the "
      "residual's samples); widen the range to compare the peaks",
      rails, c.samples, r.residual.clipped);
}

json metrics_json(const std::vector<MetricSummary>& ms) {
  json out = json::object();
  for (const MetricSummary& m : ms)
    out[m.metric] = {{"pulses", m.pulses},
                     {"mean_diff", num(m.mean_diff)},
                     {"max_abs_diff", num(m.max_abs_diff)},
                     {"at_s", num(m.at_time)}};
  return out;
}

const char* metric_unit(const std::string& m) {
  return m == "vstart" || m == "vend" ? "V" : "s";
}

std::string si(double v, const char* unit) {
  return link::format_si(v, unit);
}

std::string key_unit_symbol(const std::string& key) {
  const std::string path = key.rfind("ends.", 0) == 0 ? "tx." + key.substr(5) : key;
  return config::unit_symbol(sweep::key_unit(path));
}

}  // namespace

nlohmann::ordered_json compare_json(const CompareResult& r) {
  json j;
  j["verdict"] = r.verdict;
  j["direction"] = r.direction;
  j["offset_s"] = num(r.offset_s);
  j["residual"] = residual_json(r.residual);
  json fit = json::object();
  for (const FitKey& k : r.fit) {
    json alternatives = json::array();
    for (double a : k.alternatives) alternatives.push_back(num(a));
    fit[k.key] = {{"value", num(k.value)},
                  {"initial", num(k.initial)},
                  {"low", num(k.low)},
                  {"high", num(k.high)},
                  {"stderr", num(k.stderr_value)},
                  {"tolerance_rel", num(k.tolerance)},
                  {"tolerance_from", k.tolerance_from},
                  {"identifiable", k.identifiable},
                  {"at_bound", k.at_bound.empty() ? json(nullptr) : json(k.at_bound)},
                  {"alternatives", alternatives},
                  {"multiple_correlation", num(k.multiple_correlation)}};
  }
  j["fit"] = fit;
  json corr = json::array();
  for (const analysis::KeyCorrelation& c : r.correlations)
    corr.push_back({{"a", c.a}, {"b", c.b}, {"r", num(c.r)}, {"separable", c.separable()}});
  j["correlations"] = corr;
  if (!r.fit.empty())
    j["search"] = {{"scanned", r.search.scanned},
                   {"why", r.search.why},
                   {"points", r.search.points},
                   {"failed", r.search.failed},
                   {"starts", r.search.starts},
                   {"from_scan", r.search.from_scan},
                   {"near", r.search.near},
                   {"local_rms_v", num(r.search.local_rms_v)},
                   {"chosen_rms_v", num(r.search.chosen_rms_v)}};
  if (r.unexplained) {
    json sug = json::array();
    for (const auto& x : r.unexplained->suggested)
      sug.push_back({{"key", x.key}, {"sensitivity_v", num(x.sensitivity_v)}});
    j["unexplained"] = {{"frame", r.unexplained->window + 1},
                        {"pulse", r.unexplained->pulse ? json(*r.unexplained->pulse + 1) : json()},
                        {"time_s", num(r.unexplained->time)},
                        {"residual_v", num(r.unexplained->residual_v)},
                        {"window_rms_v", num(r.unexplained->window_rms_v)},
                        {"suggested", sug}};
  }
  j["residual_after_fit"] = r.residual_after_fit ? residual_json(*r.residual_after_fit) : json();
  if (r.offset_after_fit_s) j["offset_after_fit_s"] = num(*r.offset_after_fit_s);
  json findings = json::array();
  for (const Finding& f : r.findings)
    findings.push_back({{"key", f.key},
                        {"design", num(f.design)},
                        {"fitted", num(f.fitted)},
                        {"change_rel", num(f.change_rel)},
                        {"text", f.text}});
  j["findings"] = findings;
  j["reasons"] = r.reasons;
  j["unidentifiable"] = r.unidentifiable;
  j["traffic_from"] = r.traffic_from;
  j["rules"] = r.receiver_rules;
  j["noise"] = {{"rms_v", num(r.noise_rms_v)},
                {"quantisation_step_v", num(r.quant_step_v)},
                {"model_floor_v", num(r.model_floor_v)},
                {"threshold_rms_v", num(r.threshold_rms_v)},
                {"threshold_max_v", num(r.threshold_max_v)}};
  j["clipping"] = clipping_json(r.clipping);
  j["metrics"] = metrics_json(r.metrics);
  if (!r.metrics_after_fit.empty()) j["metrics_after_fit"] = metrics_json(r.metrics_after_fit);
  json windows = json::array();
  for (const auto& [a, b] : r.windows) windows.push_back({num(a), num(b)});
  j["windows_s"] = windows;
  j["capture_check"] = {{"verdict", r.check.verdict()},
                        {"pulses", r.check.pulses.size()},
                        {"frames", r.check.frames.size()},
                        {"bytes", r.check.bytes.size()}};
  eye::set_commands_json(r.check, j);
  j["notes"] = r.notes;
  j["simulations"] = r.evaluations;
  j["seconds"] = num(r.seconds);
  j["input"] = eye::capture_json(r.input);
  return j;
}

std::string compare_text(const CompareResult& r) {
  std::string s = fmt::format("{}  compare ({}, {}; traffic: {})\n", r.verdict, r.direction,
                              r.receiver_rules, r.traffic_from);
  if (r.verdict == "inconclusive") {
    for (const std::string& x : r.reasons) s += "  " + x + "\n";
    return s;
  }
  s += fmt::format("  offset {:.4f} us; residual rms {:.1f} mV, max {:.0f} mV over {} samples\n",
                   r.offset_s * 1e6, r.residual.rms_v * 1e3, r.residual.max_v * 1e3,
                   r.residual.samples);
  s += fmt::format(
      "  capture noise {:.1f} mV rms, quantisation step {:.2f} mV, model floor {:.1f} mV: "
      "match needs rms <= {:.1f} mV and max <= {:.0f} mV\n",
      r.noise_rms_v * 1e3, r.quant_step_v * 1e3, r.model_floor_v * 1e3, r.threshold_rms_v * 1e3,
      r.threshold_max_v * 1e3);
  if (const std::string c = clipping_sentence(r); !c.empty()) s += "  " + c + "\n";
  for (const MetricSummary& m : r.metrics)
    if (m.pulses)
      s += fmt::format("  {:<6} simulated - measured: mean {}, worst {} over {} pulses\n", m.metric,
                       si(m.mean_diff, metric_unit(m.metric)),
                       si(m.max_abs_diff, metric_unit(m.metric)), m.pulses);
  for (const FitKey& k : r.fit) {
    const std::string u = key_unit_symbol(k.key);
    s += fmt::format("  fit {} = {} +/- {} (design {}, bounds {} .. {}){}\n", k.key,
                     si(k.value, u.c_str()), si(k.stderr_value, u.c_str()),
                     si(k.initial, u.c_str()), si(k.low, u.c_str()), si(k.high, u.c_str()),
                     !k.at_bound.empty() ? "  at its bound (not a measurement)"
                     : k.identifiable    ? ""
                                         : "  not identifiable");
  }
  for (const analysis::KeyCorrelation& c : r.correlations)
    s += fmt::format("  correlation {} / {}: {:+.3f}{}\n", c.a, c.b, c.r,
                     c.separable() ? "" : "  (too correlated to separate)");
  if (!r.fit.empty() && !r.search.why.empty())
    s += fmt::format("  search: {}{}\n", r.search.why,
                     r.search.scanned
                         ? fmt::format(" ({} points, {} refinements; kept: {})", r.search.points,
                                       r.search.starts,
                                       r.search.from_scan ? "a scan start" : "the design's valley")
                         : "");
  if (r.residual_after_fit)
    s += fmt::format("  after the fit: residual rms {:.1f} mV, max {:.0f} mV\n",
                     r.residual_after_fit->rms_v * 1e3, r.residual_after_fit->max_v * 1e3);
  for (const std::string& u : r.unidentifiable) s += "  note: " + u + "\n";
  for (const Finding& f : r.findings) s += "  finding: " + f.text + "\n";
  for (const std::string& x : r.reasons) s += "  reason: " + x + "\n";
  if (const std::string note = eye::commands_note(r.check); !note.empty()) s += "  " + note + "\n";
  s += eye::commands_text(r.check.commands);
  return s;
}

std::string compare_markdown(const CompareResult& r) {
  std::string s = fmt::format("# isolink compare: {}\n\n", r.verdict);
  s += fmt::format("Direction {}, receiver rules {}, traffic from the {}.\n\n", r.direction,
                   r.receiver_rules, r.traffic_from);
  for (const std::string& x : r.reasons) s += "- " + x + "\n";
  if (!r.reasons.empty()) s += "\n";
  if (r.verdict == "inconclusive") return s;
  s += "| | rms | max |\n|---|---|---|\n";
  s += fmt::format("| residual | {:.1f} mV | {:.0f} mV |\n", r.residual.rms_v * 1e3,
                   r.residual.max_v * 1e3);
  if (r.residual_after_fit)
    s += fmt::format("| after the fit | {:.1f} mV | {:.0f} mV |\n",
                     r.residual_after_fit->rms_v * 1e3, r.residual_after_fit->max_v * 1e3);
  s += fmt::format("| match threshold | {:.1f} mV | {:.0f} mV |\n\n", r.threshold_rms_v * 1e3,
                   r.threshold_max_v * 1e3);
  s += fmt::format(
      "Capture noise {:.1f} mV rms (idle stretches), quantisation step {:.2f} mV, model floor "
      "{:.1f} mV; offset {:.4f} us (capture time minus drive time).\n\n",
      r.noise_rms_v * 1e3, r.quant_step_v * 1e3, r.model_floor_v * 1e3, r.offset_s * 1e6);
  if (const std::string c = clipping_sentence(r); !c.empty()) s += "Note: " + c + ".\n\n";
  if (!r.fit.empty()) {
    s += "| key | fitted | stderr | design | bounds | tolerance | identifiable | at bound |\n";
    s += "|---|---|---|---|---|---|---|---|\n";
    for (const FitKey& k : r.fit) {
      const std::string u = key_unit_symbol(k.key);
      s += fmt::format("| {} | {} | {} | {} | {} .. {} | {:.0f} % ({}) | {} | {} |\n", k.key,
                       si(k.value, u.c_str()), si(k.stderr_value, u.c_str()),
                       si(k.initial, u.c_str()), si(k.low, u.c_str()), si(k.high, u.c_str()),
                       k.tolerance * 100, k.tolerance_from, k.identifiable ? "yes" : "no",
                       k.at_bound.empty() ? "no" : k.at_bound);
    }
    s += "\n";
  }
  for (const std::string& u : r.unidentifiable) s += "Note: " + u + "\n\n";
  if (!r.findings.empty()) {
    s += "## Findings\n\n";
    for (const Finding& f : r.findings) s += "- " + f.text + "\n";
    s += "\n";
  }
  s += "## Pulse metrics, simulated minus measured\n\n| metric | pulses | mean | worst |\n";
  s += "|---|---|---|---|\n";
  const std::vector<MetricSummary>& ms =
      r.metrics_after_fit.empty() ? r.metrics : r.metrics_after_fit;
  for (const MetricSummary& m : ms)
    s += fmt::format("| {} | {} | {} | {} |\n", m.metric, m.pulses,
                     si(m.mean_diff, metric_unit(m.metric)),
                     si(m.max_abs_diff, metric_unit(m.metric)));
  if (!r.metrics_after_fit.empty()) s += "\n(after the fit)\n";
  return s;
}

}  // namespace isolink::reports
