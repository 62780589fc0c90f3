#include "reports/worst_report.h"

#include <fmt/format.h>

#include "netlists/link/link_spec.h"

namespace isolink::reports {

using analysis::ByteFrame;
using analysis::DirectionWorst;
using analysis::Traffic;
using analysis::WorstMetric;
using analysis::WorstResult;

namespace {

// A gap as `stimulus.gaps` reads it (microseconds, 10 digits: the reader's value equals the
// searched one to well under a picosecond).
std::string time_text(double s) {
  return fmt::format("{:.10g}u", s * 1e6);
}

std::string unit_of(const std::string& metric) {
  return metric == "vstart" || metric == "vend" ? "V" : "s";
}

std::string value_text(const std::string& metric, double v) {
  return unit_of(metric) == "V" ? fmt::format("{:.3f} V", v) : fmt::format("{:.1f} ns", v * 1e9);
}

std::string label_of(const std::string& metric) {
  if (metric == "vstart") return "lowest VSTART";
  if (metric == "vend") return "lowest VEND";
  if (metric == "width_min") return "narrowest pulse";
  if (metric == "width_max") return "widest pulse";
  return "slowest edge";
}

std::string frames_text(const Traffic& t) {
  std::string s;
  for (size_t i = 0; i < t.frames.size(); ++i)
    s +=
        fmt::format("{}{:02X}{}", i ? " " : "", t.frames[i].byte, t.frames[i].error_bit ? "*" : "");
  return s;
}

}  // namespace

std::string reproduce_stimulus(const WorstMetric& m, link::Direction d) {
  const link::StimulusSpec st = analysis::reproduce_spec(m, d);
  std::string frames, gaps;
  for (size_t i = 0; i < st.frames.size(); ++i) {
    frames += fmt::format("{}\"{}\"", i ? ", " : "", st.frames[i]);
    gaps += fmt::format("{}{}", i ? ", " : "", time_text(st.gaps[i]));
  }
  return fmt::format("stimulus: {{frames: [{}], gaps: [{}], direction: {}}}", frames, gaps,
                     link::direction_name(d));
}

nlohmann::ordered_json reproduce_json(const WorstMetric& m, link::Direction d) {
  const link::StimulusSpec st = analysis::reproduce_spec(m, d);
  nlohmann::ordered_json gaps = nlohmann::ordered_json::array();
  for (double g : st.gaps) gaps.push_back(time_text(g));
  return {{"frames", st.frames}, {"gaps", gaps}, {"direction", link::direction_name(d)}};
}

nlohmann::ordered_json worst_json(const WorstResult& r) {
  using nlohmann::ordered_json;
  ordered_json j;
  j["verdict"] = r.pass ? "pass" : "fail";
  j["seconds"] = r.seconds;
  j["directions"] = ordered_json::array();
  for (const DirectionWorst& d : r.directions) {
    ordered_json dj;
    dj["direction"] = link::direction_name(d.direction);
    dj["description"] = d.description;
    dj["receiver"] = d.receiver;
    dj["rules"] = d.rules.name;
    dj["verdict"] = d.pass ? "pass" : "fail";
    dj["reasons"] = d.reasons;
    dj["memory_us"] = d.memory * 1e6;
    dj["gap_range_us"] = {d.gap_min * 1e6, "idle"};
    dj["gap_grid_us"] = {{"from", d.gap_min * 1e6}, {"to", d.gap_max * 1e6}};
    dj["previous_byte_bound_mV"] = d.previous_bound * 1e3;
    dj["older_traffic_bound_mV"] = d.older_bound * 1e3;
    dj["scored"] = d.scored;
    dj["ranked"] = d.ranked;
    dj["seconds"] = d.seconds;
    if (!d.same_as.empty()) dj["same_circuit_as"] = d.same_as;
    dj["edge_response"] = {
        {"engine", d.edge.engine},          {"span_us", d.edge.span * 1e6},
        {"settle_mV", d.edge.settle * 1e3}, {"half_bit_residue_uV", d.edge.drift * 1e6},
        {"v_idle", d.edge.v_idle},          {"seconds", d.edge.seconds}};
    if (!d.edge.engine_note.empty()) dj["edge_response"]["engine_note"] = d.edge.engine_note;
    ordered_json w = ordered_json::object();
    for (const WorstMetric& m : d.metrics) {
      ordered_json mj;
      mj["value"] = m.value;
      mj["limit"] = m.limit;
      mj["margin"] = m.margin;
      mj["unit"] = unit_of(m.name);
      mj["bound"] = m.bound;
      ordered_json frames = ordered_json::array(), errs = ordered_json::array(),
                   gaps = ordered_json::array();
      for (size_t i = 0; i < m.traffic.frames.size(); ++i) {
        frames.push_back(fmt::format("{:02X}", m.traffic.frames[i].byte));
        errs.push_back(m.traffic.frames[i].error_bit);
        gaps.push_back(m.traffic.gaps[i] * 1e6);
      }
      mj["frames"] = frames;
      mj["error_bits"] = errs;
      mj["gaps_us"] = gaps;
      mj["pulse"] = {{"time_us", m.pulse_time * 1e6},
                     {"sign", m.pulse_sign > 0 ? "+" : "-"},
                     {"role", m.role}};
      mj["reproduce"] = reproduce_json(m, d.direction);
      mj["reproduce_yaml"] = reproduce_stimulus(m, d.direction);
      w[m.name] = mj;
    }
    dj["worst"] = w;
    j["directions"].push_back(dj);
  }
  return j;
}

std::string worst_markdown(const WorstResult& r) {
  std::string md;
  md += fmt::format("Worst case over all legal traffic: **{}**\n\n", r.pass ? "PASS" : "FAIL");
  for (const DirectionWorst& d : r.directions) {
    md += fmt::format("### {} ({})\n\n", d.description, d.pass ? "pass" : "FAIL");
    md +=
        "| metric | worst | limit | margin | traffic (byte frames, * = error bit; gap before each) "
        "| pulse |\n";
    md += "|---|---|---|---|---|---|\n";
    for (const WorstMetric& m : d.metrics) {
      std::string gaps;
      for (size_t i = 0; i < m.traffic.gaps.size(); ++i)
        gaps += fmt::format("{}{:.3g}", i ? ", " : "", m.traffic.gaps[i] * 1e6);
      md += fmt::format("| {} | {} | {} | {}{} | {} (gaps {} us) | {} {} at {:.3f} us |\n",
                        label_of(m.name), value_text(m.name, m.value), value_text(m.name, m.limit),
                        m.margin >= 0 ? "+" : "", value_text(m.name, m.margin),
                        frames_text(m.traffic), gaps, m.pulse_sign > 0 ? "+" : "-", m.role,
                        m.pulse_time * 1e6);
    }
    md += fmt::format(
        "\nMemory {:.2f} us; gaps searched from {:.2f} us (the shortest the devices produce) to "
        "idle; the previous byte moves v by at most {:.1f} mV, older traffic by at most {:.2f} mV "
        "(bound); {} waveforms scored, {} histories ranked, {:.1f} s. Edge response: {}.\n\n",
        d.memory * 1e6, d.gap_min * 1e6, d.previous_bound * 1e3, d.older_bound * 1e3, d.scored,
        d.ranked, d.seconds + d.edge.seconds, d.edge.engine);
    if (!d.edge.engine_note.empty()) md += "Edge response: " + d.edge.engine_note + ".\n\n";
    if (!d.same_as.empty())
      md += fmt::format(
          "The link is the same circuit as {} (the same parts at both ends): its "
          "result, computed once.\n\n",
          d.same_as);
    for (const std::string& why : d.reasons) md += "- " + why + "\n";
    if (!d.reasons.empty()) md += "\n";
    md += "Replay any row in `isolink run` with its stimulus block:\n\n```yaml\n";
    for (const WorstMetric& m : d.metrics)
      md += fmt::format("# {}\n{}\n", label_of(m.name), reproduce_stimulus(m, d.direction));
    md += "```\n\n";
  }
  return md;
}

std::string worst_summary_text(const WorstResult& r) {
  std::string s;
  for (const DirectionWorst& d : r.directions) {
    s += fmt::format("worst case {}: {}", d.description, d.pass ? "pass" : "FAIL");
    for (const WorstMetric& m : d.metrics)
      s += fmt::format("  {} {} ({}{})", m.name, value_text(m.name, m.value),
                       m.margin >= 0 ? "+" : "", value_text(m.name, m.margin));
    s += "\n";
  }
  return s;
}

}  // namespace isolink::reports
