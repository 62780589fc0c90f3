#include "reports/run_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "netlists/link/cable.h"
#include "netlists/link/cards.h"
#include "reports/html_report.h"

namespace isolink::reports {

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

std::string margin_cell(const eye::CheckResult& r, const char* metric, const char* unit,
                        double scale) {
  for (const eye::WorstMargin& w : r.worst)
    if (w.metric == metric)
      return fmt::format("{:.3g} {} (margin {:+.3g} {}, pulse {} at {:.3f} us)", w.j.value * scale,
                         unit, w.j.margin * scale, unit, w.pulse, w.time * 1e6);
  return "-";
}

}  // namespace

nlohmann::ordered_json link_spec_json(const link::LinkSpec& s) {
  ordered_json cable{{"length", s.cable.length},
                     {"material", s.cable.material},
                     {"gauge", s.cable.gauge},
                     {"temperature", s.cable.temperature},
                     {"r", optional_json(s.cable.r)},
                     {"l", optional_json(s.cable.l)},
                     {"c", optional_json(s.cable.c)},
                     {"g", optional_json(s.cable.g)},
                     {"segments", s.cable.segments},
                     {"skin_effect", s.cable.skin_effect},
                     {"dielectric_loss", s.cable.dielectric_loss}};
  ordered_json dirs = ordered_json::array();
  for (link::Direction d : s.stimulus.directions) dirs.push_back(link::direction_name(d));
  ordered_json stim{{"frames", s.stimulus.frames},
                    {"tones", s.stimulus.tones},
                    {"patterns", s.stimulus.patterns},
                    {"script", s.stimulus.script},
                    {"directions", dirs}};
  ordered_json sim{{"tstep", s.sim.tstep},
                   {"tmax", optional_json(s.sim.tmax)},
                   {"method", s.sim.method},
                   {"reltol", optional_json(s.sim.reltol)}};
  return ordered_json{{"name", s.name},
                      {"source", s.source},
                      {"tx", end_json(s.tx)},
                      {"rx", end_json(s.rx)},
                      {"cable", cable},
                      {"stimulus", stim},
                      {"sim", sim}};
}

nlohmann::ordered_json run_report_json(const link::LinkSpec& spec, const LinkRun& run) {
  ordered_json dirs = ordered_json::array();
  for (const DirectionRun& d : run.directions) {
    const TransientStats& st = d.sim.stats;
    const bool lti = d.sim.engine == analysis::Engine::Lti;
    ordered_json solver{{"engine", analysis::engine_name(d.sim.engine)},
                        {"seconds", d.sim.seconds},
                        {"nodes", d.sim.nodes},
                        {"unknowns", d.sim.unknowns},
                        {"elements", d.sim.elements},
                        {"steps", lti ? d.sim.lti.steps : st.accepted},
                        {"rejected", lti ? d.sim.lti.rejected : st.rejected},
                        {"factorizations", lti ? d.sim.lti.factorizations : st.factorizations},
                        {"breakpoints", lti ? d.sim.grid.corners : st.breakpoints},
                        {"cable_segments", d.link.cable_segments},
                        {"warnings", d.sim.warnings}};
    if (lti) {
      solver["lti_method"] = d.sim.lti.method;
      if (d.sim.lti.method == "reduced model") {
        const ReducedModelStats& m = d.sim.lti.model;
        solver["reduced_model"] = {{"order", m.order},
                                   {"poles", m.poles},
                                   {"expansion_points", m.expansion_points},
                                   {"check_points", m.check_points},
                                   {"ac_error", m.error},
                                   {"ac_error_hz", m.error_frequency}};
      } else if (!d.sim.lti.note.empty()) {
        solver["lti_note"] = d.sim.lti.note;
        solver["reduced_model_seconds"] = d.sim.lti.model_seconds;
        solver["march_seconds"] = d.sim.lti.march_seconds;
      }
      solver["response_span_s"] = d.sim.lti.settled_at;
      solver["grid_step_s"] = d.sim.grid.step;
      solver["rows"] = d.sim.grid.rows;
    } else if (!d.sim.engine_note.empty()) {
      solver["engine_note"] = d.sim.engine_note;
      solver["lti_attempt_seconds"] = d.sim.lti_attempt_seconds;
    }
    solver["accuracy"] = analysis::engine_accuracy(d.sim);
    if (!d.same_as.empty()) solver["same_circuit_as"] = d.same_as;
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
  md +=
      "| direction | receiver rules | verdict | worst VSTART | worst VEND | worst width | "
      "slowest edge | bytes |\n|---|---|---|---|---|---|---|---|\n";
  for (const DirectionRun& d : run.directions) {
    const eye::CheckResult* r = d.data ? &*d.data : d.tones ? &*d.tones : nullptr;
    if (r == nullptr) continue;
    std::string bytes =
        d.data ? fmt::format("{} of {} decoded{}", d.data->bytes.size(), d.link.expected.size(),
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
  md += "## Bill of materials (as simulated)\n\n";
  if (!run.directions.empty()) {
    const link::ExpandedLink& x = run.directions.front().link;
    md += "- tx end: " + x.tx_bom + "\n- rx end: " + x.rx_bom + "\n";
  }
  md += "\n## Cable\n\n" + cable_summary(spec, run) + "\n";
  md += "\n## Traffic\n\n";
  md += fmt::format("`{}`\n\n", spec.stimulus.to_script());
  md +=
      "## Solver\n\n| direction | engine | unknowns | steps | rejected | factorizations | time "
      "|\n|---|---|---|---|---|---|---|\n";
  for (const DirectionRun& d : run.directions) {
    const bool lti = d.sim.engine == analysis::Engine::Lti;
    const bool reduced = lti && d.sim.lti.method == "reduced model";
    // The reduced model has no steps: its order stands in that column.
    const std::string steps = reduced
                                  ? fmt::format("- (order {})", d.sim.lti.model.order)
                                  : fmt::format("{}", lti ? d.sim.lti.steps : d.sim.stats.accepted);
    const std::string rejected =
        reduced ? "-" : fmt::format("{}", lti ? d.sim.lti.rejected : d.sim.stats.rejected);
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {:.3f} s |\n", d.link.description,
                      reduced ? "LTI, reduced model"
                      : lti   ? "LTI, march"
                              : "transient",
                      d.sim.unknowns, steps, rejected,
                      lti ? d.sim.lti.factorizations : d.sim.stats.factorizations, d.sim.seconds);
  }
  for (const DirectionRun& d : run.directions) {
    if (!d.same_as.empty())
      md += fmt::format(
          "\n{}: the same circuit and traffic as {} (the same parts at both ends): its waveform, "
          "simulated once.\n",
          d.link.description, d.same_as);
    else if (d.sim.engine == analysis::Engine::Lti && d.sim.lti.method == "reduced model")
      md += fmt::format(
          "\n{}: waveform by the LTI engine from a reduced model (order {}, {} poles, {} "
          "expansion points; its transfer within {:.1e} of the peak of the exact AC solution at "
          "{} frequencies from 1 kHz to 3 GHz), superposing {} source corners in closed form; "
          "output rows at most {:.3g} ns apart, down to {:.3g} ns where the response bends "
          "(linear interpolation within 1 mV).\n",
          d.link.description, d.sim.lti.model.order, d.sim.lti.model.poles,
          d.sim.lti.model.expansion_points, d.sim.lti.model.error, d.sim.lti.model.check_points,
          d.sim.grid.corners, d.sim.grid.coarse_step * 1e9, d.sim.grid.step * 1e9);
    else if (d.sim.engine == analysis::Engine::Lti)
      md += fmt::format(
          "\n{}: waveform by the LTI engine, superposing {} source corners on step "
          "responses marched to {:.3g} us ({}); output every {:.3g} ns (linear "
          "interpolation within 1 mV).\n",
          d.link.description, d.sim.grid.corners, d.sim.lti.settled_at * 1e6,
          d.sim.lti.note.empty() ? "the march was asked for"
                                 : "the reduced model did not pass its check: " + d.sim.lti.note,
          d.sim.grid.step * 1e9);
    else if (!d.sim.engine_note.empty())
      md += fmt::format("\n{}: transient engine ({}; the LTI attempt took {:.3f} s).\n",
                        d.link.description, d.sim.engine_note, d.sim.lti_attempt_seconds);
    if (d.same_as.empty()) md += fmt::format("Accuracy: {}.\n", analysis::engine_accuracy(d.sim));
  }
  md += "\nFiles: `report.json` (all figures), `wave.csv` (the probes of every direction).\n";
  return md;
}

std::string cable_summary(const link::LinkSpec& spec, const LinkRun& run) {
  std::string md =
      fmt::format("{} m of {} AWG {} twisted pair at {} degC", spec.cable.length, spec.cable.gauge,
                  spec.cable.material == "pp" ? "PP" : "PVC", spec.cable.temperature);
  if (spec.cable.r || spec.cable.l || spec.cable.c || spec.cable.g)
    md += " (explicit per-metre values override the preset)";
  if (!run.directions.empty())
    md += fmt::format(", {} sections", run.directions.front().link.cable_segments);
  if (StatusOr<link::CableModel> cm = link::cable_model(spec.cable); cm.ok()) {
    const double a10 = std::real(cm->gamma_diff(10e6)) * spec.cable.length * 8.685889638;
    md += fmt::format(
        ": differential impedance {:.0f} ohm, velocity {:.2f} c, delay {:.1f} ns, "
        "loss {:.2f} dB at 10 MHz",
        cm->z_diff(), cm->velocity() / 299792458.0, spec.cable.length / cm->velocity() * 1e9, a10);
  }
  return md + ".";
}

std::string run_report_page(const link::LinkSpec& spec, const LinkRun& run,
                            const nlohmann::ordered_json& json, const std::string& eye_png) {
  std::vector<HtmlWave> waves;
  ordered_json vth = ordered_json::array();
  for (const DirectionRun& d : run.directions) {
    const Waveform& w = d.sim.wave;
    waves.push_back({d.link.description, w.time, w.columns[0]});
    vth.push_back(d.data ? d.rules.vth : d.tone_rules.vth);
  }
  ordered_json extra{
      {"cable", cable_summary(spec, run)}, {"traffic", spec.stimulus.to_script()}, {"vth", vth}};
  if (!run.directions.empty())
    extra["bom"] = {{"tx", run.directions.front().link.tx_bom},
                    {"rx", run.directions.front().link.rx_bom}};
  return run_report_html(json, extra, waves, eye_png);
}

std::string run_summary_text(const link::LinkSpec& spec, const LinkRun& run) {
  std::string s =
      fmt::format("{}: {} ({:.2f} s)\n", spec.name, run.pass ? "PASS" : "FAIL", run.seconds);
  for (const DirectionRun& d : run.directions) {
    s += fmt::format("  {} [{}]: {}\n", d.link.description, d.link.rules, d.pass ? "pass" : "FAIL");
    for (const eye::CheckResult* r : {d.data ? &*d.data : nullptr, d.tones ? &*d.tones : nullptr}) {
      if (r == nullptr) continue;
      for (const eye::WorstMargin& w : r->worst) {
        const bool ns = w.metric == "width" || w.metric == "edge";
        const double k = ns ? 1e9 : 1;
        s += fmt::format(
            "    worst {:<6} {:>8.4g} {:<2} (limit {:.4g}, margin {:+.4g}{}) at {:.3f} us\n",
            w.metric, w.j.value * k, ns ? "ns" : "V", w.j.limit * k, w.j.margin * k,
            w.metric == "droop" ? ", a warning" : "", w.time * 1e6);
      }
      for (size_t i = 0; i < r->reasons.size() && i < 5; ++i) s += "    " + r->reasons[i] + "\n";
    }
  }
  return s;
}

}  // namespace isolink::reports
