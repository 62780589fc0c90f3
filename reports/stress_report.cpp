#include "reports/stress_report.h"

#include <fmt/format.h>

#include <cmath>

#include "netlists/link/cards.h"

namespace isolink::reports {

namespace {

using nlohmann::ordered_json;

// A JSON number, or null when it is not finite.
ordered_json num(double v) {
  return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr);
}

ordered_json scenario_json(const analysis::StressScenario& s, const std::string& netlist) {
  ordered_json j;
  j["id"] = s.id;
  j["kind"] = s.kind;
  j["end"] = s.end;
  j["line"] = s.line.empty() ? ordered_json(nullptr) : ordered_json(s.line);
  ordered_json level = ordered_json::object();
  for (const auto& [k, v] : s.level) level[k] = num(v);
  j["level"] = level;
  j["description"] = s.description;
  j["window_s"] = {num(s.t_start), num(s.t_end)};  // the disturbance's start and end
  ordered_json pins = ordered_json::object(), grounds = ordered_json::object();
  for (const auto& [node, p] : s.peak_pin_v)
    pins[node] = {{"max", num(p.max)}, {"min", num(p.min)}};
  for (const auto& [node, g] : s.pin_ground) grounds[node] = g;
  j["peak_pin_v"] = pins;
  j["pin_ground"] = grounds;
  j["peak_cm_V"] = num(s.peak_cm_v);
  ordered_json diodes = ordered_json::array();
  for (const analysis::DiodePeak& d : s.diodes) {
    ordered_json o{{"diode", d.diode},
                   {"what", d.what},
                   {"probe", "i(" + d.ammeter + ")"},
                   {"peak_A", num(d.peak_a)}};
    if (d.energy_j > 0) o["energy_J"] = num(d.energy_j);
    if (d.rating_a > 0) o["rating_A"] = {{"value", d.rating_a}, {"source", d.rating_source}};
    diodes.push_back(o);
  }
  j["diodes"] = diodes;
  ordered_json caps = ordered_json::array();
  for (const analysis::CapPeak& c : s.caps)
    caps.push_back({{"cap", c.cap}, {"peak_V", num(c.peak_v)}});
  j["isolation_caps"] = caps;
  if (!s.contacts.empty()) {
    ordered_json contacts = ordered_json::array();
    for (const analysis::ContactPeak& c : s.contacts)
      contacts.push_back({{"contact", c.contact},
                          {"probe", "i(" + c.ammeter + ")"},
                          {"peak_1ns_A", num(c.peak_1ns_a)},
                          {"charge_C", num(c.charge_c)}});
    j["contacts"] = contacts;
  }
  if (s.traffic) {
    j["receiver"] = {{"p", s.receiver_p}, {"n", s.receiver_n}, {"rules", s.rules}};
    const analysis::StressTraffic& t = *s.traffic;
    ordered_json worst = ordered_json::array();
    for (const eye::WorstMargin& w : t.worst)
      worst.push_back({{"metric", w.metric}, {"margin", num(w.j.margin)}, {"time_s", num(w.time)}});
    j["traffic"] = {{"bytes_sent", t.bytes_sent},
                    {"bytes_decoded", t.bytes_decoded},
                    {"bytes_during", t.bytes_during},
                    {"decoded_during", t.decoded_during},
                    {"pass", t.pass},
                    {"worst", worst},
                    {"first_failure", t.first_failure.empty() ? ordered_json(nullptr)
                                                              : ordered_json(t.first_failure)},
                    {"recovery_s", t.recovery_s ? num(*t.recovery_s) : ordered_json(nullptr)}};
  }
  j["survives"] = s.survives;
  j["communicates"] = s.communicates ? ordered_json(*s.communicates) : ordered_json(nullptr);
  j["first_broken"] = s.first_broken.empty() ? ordered_json(nullptr) : ordered_json(s.first_broken);
  j["broken"] = s.broken;
  j["engine"] = s.engine;
  j["seconds"] = num(s.seconds);
  if (!netlist.empty()) j["netlist"] = netlist;
  return j;
}

std::string at(const std::map<std::string, std::string>& m, const std::string& k) {
  auto it = m.find(k);
  return it == m.end() ? "" : it->second;
}

}  // namespace

ordered_json stress_json(const std::string& spec_name, const analysis::StressResult& r,
                         const std::map<std::string, std::string>& netlists) {
  ordered_json j;
  j["spec"] = spec_name;
  j["verdict"] = r.verdict;
  j["survives"] = r.survives;
  j["communicates"] = r.communicates;
  ordered_json limits = ordered_json::object();
  for (const analysis::StressLimit& l : r.limits)
    limits[l.key] = {{"value", num(l.value)}, {"source", l.source}};
  j["limits"] = limits;
  ordered_json sc = ordered_json::array();
  for (const analysis::StressScenario& s : r.scenarios)
    sc.push_back(scenario_json(s, at(netlists, s.id)));
  j["scenarios"] = sc;
  j["seconds"] = num(r.seconds);
  return j;
}

std::string stress_markdown(const std::string& spec_name, const analysis::StressResult& r,
                            const std::map<std::string, std::string>& netlists) {
  std::string md = fmt::format("# isolink stress: {}\n\n**Verdict:** {}\n\n", spec_name, r.verdict);
  md += "## Limits\n\n| limit | value | source |\n|---|---|---|\n";
  for (const analysis::StressLimit& l : r.limits)
    md += fmt::format("| {} | {:g} | {} |\n", l.key, l.value, l.source);
  md +=
      "\n## Scenarios\n\n| scenario | level | peak pin V (max / min) | peak CM V | survives | "
      "communicates | first broken |\n|---|---|---|---|---|---|---|\n";
  for (const analysis::StressScenario& s : r.scenarios) {
    std::string level, pins;
    for (const auto& [k, v] : s.level)
      level += fmt::format("{}{} {:g}", level.empty() ? "" : ", ", k, v);
    for (const auto& [node, p] : s.peak_pin_v)
      pins += fmt::format("{}{} {:.3g} / {:.3g}", pins.empty() ? "" : "; ", node, p.max, p.min);
    md += fmt::format("| {} | {} | {} | {:.3g} | {} | {} | {} |\n", s.id, level, pins, s.peak_cm_v,
                      s.survives ? "yes" : "**no**",
                      s.communicates ? (*s.communicates ? "yes" : "**no**") : "-",
                      s.first_broken.empty() ? "-" : s.first_broken);
  }
  for (const analysis::StressScenario& s : r.scenarios) {
    md += fmt::format("\n### {}\n\n{}. Engine: {}, {:.2f} s.", s.id, s.description, s.engine,
                      s.seconds);
    const std::string n = at(netlists, s.id);
    if (!n.empty()) md += fmt::format(" Netlist: `{}`.", n);
    md += "\n\n";
    if (!s.diodes.empty()) {
      md += "| part | peak current | energy | rating |\n|---|---|---|---|\n";
      for (const analysis::DiodePeak& d : s.diodes)
        md += fmt::format("| {} (`{}`) | {} | {} | {} |\n", d.what, d.diode,
                          link::format_si(d.peak_a, "A"),
                          d.energy_j > 0 ? link::format_si(d.energy_j, "J") : "-",
                          d.rating_a > 0 ? "IPP " + link::format_si(d.rating_a, "A") : "-");
      md += "\n";
    }
    for (const analysis::CapPeak& c : s.caps)
      md += fmt::format("- isolation cap `{}`: peak {:.4g} V\n", c.cap, c.peak_v);
    for (const analysis::ContactPeak& c : s.contacts)
      md += fmt::format(
          "- contact `{}`: inrush {} (largest mean over 1 ns), {} moved into the "
          "module\n",
          c.contact, link::format_si(c.peak_1ns_a, "A"), link::format_si(c.charge_c, "C"));
    if (s.traffic) {
      const analysis::StressTraffic& t = *s.traffic;
      md += fmt::format(
          "- traffic at {} / {} ({} rules): {} of {} bytes decoded, {} of {} during the step; {}\n",
          s.receiver_p, s.receiver_n, s.rules, t.bytes_decoded, t.bytes_sent, t.decoded_during,
          t.bytes_during, t.pass ? "passes" : "fails: " + t.first_failure);
      md += t.recovery_s ? fmt::format("- back within the rules {} after the step\n",
                                       link::format_si(*t.recovery_s, "s"))
                         : "- still failing at the end of the record\n";
      for (const eye::WorstMargin& w : t.worst)
        md += fmt::format("- worst {} margin {:.4g} at {}\n", w.metric, w.j.margin,
                          link::format_si(w.time, "s"));
    }
    for (const std::string& b : s.broken) md += "- broken: " + b + "\n";
  }
  md += fmt::format("\nRun time {:.1f} s.\n", r.seconds);
  return md;
}

namespace {

std::string devices_text(const std::vector<int>& d) {
  if (d.empty()) return "-";
  std::string s;
  for (int k : d) s += (s.empty() ? "" : " ") + std::to_string(k);
  return s;
}

}  // namespace

ordered_json pack_stress_json(const std::string& pack_name, const analysis::PackStressResult& r) {
  ordered_json j;
  j["pack"] = pack_name;
  j["devices"] = r.devices;
  j["ring"] = r.ring;
  j["verdict"] = r.verdict;
  j["survives"] = r.survives;
  j["all_reached"] = r.all_reached;
  j["simulations"] = r.simulations;
  j["seconds"] = num(r.seconds);
  ordered_json faults = ordered_json::array();
  for (const analysis::HopFault& f : r.faults)
    faults.push_back({{"hop", f.hop},
                      {"breaks_hop", f.breaks_hop},
                      {"normal_side",
                       f.breaks_hop ? ordered_json(f.reroute.normal_side) : ordered_json(nullptr)},
                      {"reverse_side",
                       f.breaks_hop ? ordered_json(f.reroute.reverse_side) : ordered_json(nullptr)},
                      {"unreached", f.unreached},
                      {"reroute_delay_s", num(f.reroute_delay_s)},
                      {"scenario", scenario_json(f.scenario, "")}});
  j["faults"] = faults;
  return j;
}

std::string pack_stress_markdown(const std::string& pack_name,
                                 const analysis::PackStressResult& r) {
  std::string md = fmt::format(
      "# isolink stress: {} (pack)\n\n**Verdict:** {}\n\n{} devices{}; each hop's wire faults "
      "on its own link spec ({} distinct circuits simulated in {:.1f} s). A fault that stops a "
      "hop (it no longer communicates in either direction) is taken as that hop's cable "
      "broken: the devices the ring still reaches the other way round, those none reaches, and "
      "the most a command's arrival is delayed by the re-route.\n\n",
      pack_name, r.verdict, r.devices, r.ring ? ", ring" : ", no ring", r.simulations, r.seconds);
  md +=
      "| hop | fault | survives | communicates | re-routed (other way round) | unreached | "
      "added delay | first broken |\n|---|---|---|---|---|---|---|---|\n";
  for (const analysis::HopFault& f : r.faults) {
    const analysis::StressScenario& s = f.scenario;
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", f.hop, s.id,
                      s.survives ? "yes" : "**no**",
                      s.communicates ? (*s.communicates ? "yes" : "**no**") : "-",
                      f.breaks_hop ? devices_text(f.reroute.reverse_side) : "-",
                      f.breaks_hop ? devices_text(f.unreached) : "-",
                      f.breaks_hop ? link::format_si(f.reroute_delay_s, "s") : "-",
                      s.first_broken.empty() ? "-" : s.first_broken);
  }
  return md;
}

}  // namespace isolink::reports
