#include "cli/run_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <fmt/format.h>

namespace isolink::cli {

namespace {

using nlohmann::ordered_json;

ordered_json optional_json(const std::optional<double>& v) {
  return v ? ordered_json(*v) : ordered_json(nullptr);
}

ordered_json end_json(const link::EndSpec& e) {
  const link::IsolationSpec& i = e.isolation;
  ordered_json iso{{"type", i.type}};
  if (i.type == "cap" || i.type == "capchoke") iso["cap"] = i.cap;
  if (i.type == "capchoke" || i.type == "transformer_choke") iso["chokes"] = i.chokes;
  if (i.type.rfind("transformer", 0) == 0) {
    iso["part"] = i.part;
    iso["inductance"] = optional_json(i.inductance);
    iso["leakage"] = optional_json(i.leakage);
    iso["dcr"] = optional_json(i.dcr);
    iso["winding_c"] = optional_json(i.winding_c);
    iso["centre_tap_c"] = optional_json(i.centre_tap_c);
  }
  if (i.cable_side_c >= 0) iso["cable_side_c"] = i.cable_side_c;
  iso["esd"] = i.esd;
  return ordered_json{{"device", e.device},
                      {"series_r", optional_json(e.series_r)},
                      {"bypass_c", optional_json(e.bypass_c)},
                      {"termination", optional_json(e.termination)},
                      {"isolation", iso}};
}

std::string si(double v, const char* unit) {
  if (v == 0) return fmt::format("0 {}", unit);
  static const std::pair<double, const char*> kScales[] = {
      {1e9, "G"}, {1e6, "M"}, {1e3, "k"}, {1, ""}, {1e-3, "m"}, {1e-6, "u"}, {1e-9, "n"},
      {1e-12, "p"}, {1e-15, "f"}};
  for (const auto& [s, p] : kScales)
    if (std::fabs(v) >= s * 0.9999) return fmt::format("{:.4g} {}{}", v / s, p, unit);
  return fmt::format("{:.3g} {}", v, unit);
}

std::string isolation_text(const link::EndSpec& e) {
  const link::IsolationSpec& i = e.isolation;
  std::string s;
  if (i.type == "none") s = "none (direct)";
  if (i.type == "cap" || i.type == "capchoke") s = si(i.cap, "F") + " per line";
  if (i.type.rfind("transformer", 0) == 0) {
    s = "transformer " + (i.part.empty() ? std::string("(device default)") : i.part);
    if (i.inductance) s += ", OCL " + si(*i.inductance, "H");
  }
  if (i.type == "capchoke" || i.type == "transformer_choke") {
    s += " + choke";
    if (i.chokes.size() > 1) s += "s";
    s += " ";
    std::string list;
    for (const std::string& c : i.chokes) list += (list.empty() ? "" : " + ") + c;
    s += list.empty() ? "(default)" : list;
  }
  if (i.esd > 0) s += ", ESD " + si(i.esd, "F");
  return s;
}

std::string margin_cell(const eye::CheckResult& r, const char* metric, const char* unit,
                        double scale) {
  for (const eye::WorstMargin& w : r.worst)
    if (w.metric == metric)
      return fmt::format("{:.3g} {} (margin {:+.3g} {}, pulse {} at {:.3f} us)",
                         w.j.value * scale, unit, w.j.margin * scale, unit, w.pulse,
                         w.time * 1e6);
  return "-";
}

}  // namespace

nlohmann::ordered_json link_spec_json(const link::LinkSpec& s) {
  ordered_json cable{{"length", s.cable.length},           {"material", s.cable.material},
                     {"gauge", s.cable.gauge},             {"temperature", s.cable.temperature},
                     {"r", optional_json(s.cable.r)},      {"l", optional_json(s.cable.l)},
                     {"c", optional_json(s.cable.c)},      {"g", optional_json(s.cable.g)},
                     {"segments", s.cable.segments},       {"skin_effect", s.cable.skin_effect},
                     {"dielectric_loss", s.cable.dielectric_loss}};
  ordered_json dirs = ordered_json::array();
  for (link::Direction d : s.stimulus.directions) dirs.push_back(link::direction_name(d));
  ordered_json stim{{"frames", s.stimulus.frames},     {"tones", s.stimulus.tones},
                    {"patterns", s.stimulus.patterns}, {"script", s.stimulus.script},
                    {"directions", dirs}};
  ordered_json sim{{"tstep", s.sim.tstep},
                   {"tmax", optional_json(s.sim.tmax)},
                   {"method", s.sim.method},
                   {"reltol", optional_json(s.sim.reltol)}};
  return ordered_json{{"name", s.name},          {"source", s.source}, {"tx", end_json(s.tx)},
                      {"rx", end_json(s.rx)},    {"cable", cable},     {"stimulus", stim},
                      {"sim", sim}};
}

nlohmann::ordered_json run_report_json(const link::LinkSpec& spec, const LinkRun& run) {
  ordered_json dirs = ordered_json::array();
  for (const DirectionRun& d : run.directions) {
    const TransientStats& st = d.sim.stats;
    ordered_json solver{{"seconds", d.sim.seconds},       {"nodes", d.sim.nodes},
                        {"unknowns", d.sim.unknowns},     {"elements", d.sim.elements},
                        {"steps", st.accepted},           {"rejected", st.rejected},
                        {"factorizations", st.factorizations},
                        {"breakpoints", st.breakpoints},  {"cable_segments", d.link.cable_segments},
                        {"warnings", d.sim.warnings}};
    ordered_json j{{"direction", link::direction_name(d.link.direction)},
                   {"transmitter", d.link.transmitter},
                   {"receiver", d.link.receiver},
                   {"rules", d.link.rules},
                   {"verdict", d.pass ? "pass" : "fail"},
                   {"check", d.data ? eye::to_json(*d.data) : ordered_json(nullptr)},
                   {"tones", d.tones ? eye::to_json(*d.tones) : ordered_json(nullptr)},
                   {"solver", solver}};
    dirs.push_back(std::move(j));
  }
  return ordered_json{{"verdict", run.pass ? "pass" : "fail"},
                      {"name", spec.name},
                      {"run_time_s", run.seconds},
                      {"directions", dirs},
                      {"spec", link_spec_json(spec)}};
}

std::string run_report_markdown(const link::LinkSpec& spec, const LinkRun& run,
                                const std::vector<std::string>& images) {
  std::string md;
  md += fmt::format("# isolink report: {}\n\n", spec.name);
  md += fmt::format("**Verdict: {}**", run.pass ? "PASS" : "FAIL");
  md += fmt::format(" (spec `{}`, simulated in {:.2f} s)\n\n", spec.source, run.seconds);
  md += "| direction | receiver rules | verdict | worst VSTART | worst VEND | worst width | "
        "slowest edge | bytes |\n|---|---|---|---|---|---|---|---|\n";
  for (const DirectionRun& d : run.directions) {
    const eye::CheckResult* r = d.data ? &*d.data : d.tones ? &*d.tones : nullptr;
    if (r == nullptr) continue;
    std::string bytes = d.data ? fmt::format("{} of {} decoded{}", d.data->bytes.size(),
                                             d.link.expected.size(),
                                             d.data->expect_match ? ", match" : ", MISMATCH")
                               : "-";
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", d.link.description, r->rules,
                      d.pass ? "pass" : "**FAIL**", margin_cell(*r, "vstart", "V", 1),
                      margin_cell(*r, "vend", "V", 1), margin_cell(*r, "width", "ns", 1e9),
                      margin_cell(*r, "edge", "ns", 1e9), bytes);
  }
  md += "\n";
  for (const DirectionRun& d : run.directions) {
    std::vector<std::string> reasons;
    if (d.data) reasons.insert(reasons.end(), d.data->reasons.begin(), d.data->reasons.end());
    if (d.tones) reasons.insert(reasons.end(), d.tones->reasons.begin(), d.tones->reasons.end());
    if (reasons.empty()) continue;
    md += fmt::format("Why {} fails:\n\n", d.link.description);
    for (size_t i = 0; i < reasons.size() && i < 12; ++i) md += "- " + reasons[i] + "\n";
    if (reasons.size() > 12) md += fmt::format("- ... and {} more\n", reasons.size() - 12);
    md += "\n";
  }
  for (const std::string& img : images) md += fmt::format("![{}]({})\n\n", img, img);
  md += "## Bill of materials\n\n| end | device | series R | bypass C | termination | isolation "
        "|\n|---|---|---|---|---|---|\n";
  for (const auto& [label, e] : {std::pair{"tx", &spec.tx}, std::pair{"rx", &spec.rx}}) {
    auto opt = [](const std::optional<double>& v, const char* unit) {
      return v ? si(*v, unit) : std::string("preset");
    };
    md += fmt::format("| {} | {} | {} | {} | {} | {} |\n", label, e->device,
                      opt(e->series_r, "ohm"), opt(e->bypass_c, "F"),
                      opt(e->termination, "ohm"), isolation_text(*e));
  }
  md += fmt::format("\n## Cable\n\n{} m of {} AWG {} twisted pair at {} degC", spec.cable.length,
                    spec.cable.gauge, spec.cable.material == "pp" ? "PP" : "PVC",
                    spec.cable.temperature);
  if (spec.cable.r || spec.cable.l || spec.cable.c || spec.cable.g)
    md += " (explicit per-metre values override the preset)";
  if (!run.directions.empty())
    md += fmt::format(", {} sections.\n", run.directions.front().link.cable_segments);
  md += "\n## Traffic\n\n";
  md += fmt::format("`{}`\n\n", spec.stimulus.to_script());
  md += "## Solver\n\n| direction | unknowns | steps | rejected | factorizations | time |\n"
        "|---|---|---|---|---|---|\n";
  for (const DirectionRun& d : run.directions)
    md += fmt::format("| {} | {} | {} | {} | {} | {:.3f} s |\n", d.link.description,
                      d.sim.unknowns, d.sim.stats.accepted, d.sim.stats.rejected,
                      d.sim.stats.factorizations, d.sim.seconds);
  md += "\nFiles: `report.json` (all figures), `wave.csv` (the probes of every direction).\n";
  return md;
}

Waveform run_waveforms(const LinkRun& run, double dt) {
  Waveform out;
  std::vector<Waveform> parts;
  double t_end = 1e300;
  for (const DirectionRun& d : run.directions) {
    parts.push_back(d.sim.wave.resampled(dt));
    t_end = std::min(t_end, parts.back().time.empty() ? 0.0 : parts.back().time.back());
  }
  if (parts.empty()) return out;
  size_t n = 0;
  while (n < parts[0].time.size() && parts[0].time[n] <= t_end) ++n;
  out.time.assign(parts[0].time.begin(), parts[0].time.begin() + n);
  for (size_t k = 0; k < parts.size(); ++k) {
    const char* dir = link::direction_name(run.directions[k].link.direction);
    for (size_t c = 0; c < parts[k].columns.size(); ++c) {
      std::vector<double> col(parts[k].columns[c].begin(), parts[k].columns[c].begin() + n);
      out.add_column(fmt::format("{} {}", dir, parts[k].names[c]), std::move(col));
    }
  }
  return out;
}

Status write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) {
      std::remove(tmp.c_str());
      return Status::Error(fmt::format("{}: error: cannot write", path));
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return Status::Error(fmt::format("{}: error: cannot rename {} into place", path, tmp));
  }
  return Status::Ok();
}

std::string run_summary_text(const link::LinkSpec& spec, const LinkRun& run) {
  std::string s = fmt::format("{}: {} ({:.2f} s)\n", spec.name, run.pass ? "PASS" : "FAIL",
                              run.seconds);
  for (const DirectionRun& d : run.directions) {
    s += fmt::format("  {} [{}]: {}\n", d.link.description, d.link.rules,
                     d.pass ? "pass" : "FAIL");
    for (const eye::CheckResult* r : {d.data ? &*d.data : nullptr, d.tones ? &*d.tones : nullptr}) {
      if (r == nullptr) continue;
      for (const eye::WorstMargin& w : r->worst)
        s += fmt::format("    worst {:<6} {:>9.4g} (limit {:.4g}, margin {:+.4g}) at {:.3f} us\n",
                         w.metric, w.j.value * (w.metric == "width" || w.metric == "edge" ? 1e9 : 1),
                         w.j.limit * (w.metric == "width" || w.metric == "edge" ? 1e9 : 1),
                         w.j.margin * (w.metric == "width" || w.metric == "edge" ? 1e9 : 1),
                         w.time * 1e6);
      for (size_t i = 0; i < r->reasons.size() && i < 5; ++i) s += "    " + r->reasons[i] + "\n";
    }
  }
  return s;
}

}  // namespace isolink::cli
