#include "reports/noise_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "netlists/link/cards.h"

namespace isolink::reports {

using namespace analysis;  // the result types: NoiseResult, NoiseDirection, NoisePoint, ...

nlohmann::ordered_json noise_json(const NoiseResult& r) {
  using nlohmann::ordered_json;
  const link::NoiseSpec& n = r.spec;
  ordered_json j;
  j["verdict"] = r.pass ? "pass" : "fail";
  j["injection"] = n.injection;
  j["level"] = n.level;
  j["level_unit"] = n.level_unit();
  j["level_is"] = "RMS of the unmodulated carrier";
  j["modulation"] = n.modulation;
  j["peak_factor"] = r.peak_factor;
  if (n.injection != "ground_shift") j["position"] = n.position;
  j["pin_limit_v"] = n.pin_limit;
  j["immunity_min_db"] = noise_immunity_min_db(r);
  j["band_hz"] = {n.f_start, n.f_stop};
  j["worst_case"] = "worst corner of the linearised tolerance box (adjoint sensitivities)";
  j["statistics"] = fmt::format(
      "Monte Carlo, {} boards, each part uniform within its tolerance, seed {}, on the same "
      "linearised response; immunity_min: the level 99 % of the boards reach",
      n.samples, n.seed);
  j["verdict_on"] = n.verdict_on;
  ordered_json dirs = ordered_json::array();
  for (const NoiseDirection& d : r.directions) {
    ordered_json dj;
    dj["direction"] = link::direction_name(d.direction);
    dj["description"] = d.description;
    ordered_json pts = ordered_json::array();
    for (const NoisePoint& p : d.points) {
      ordered_json pj;
      pj["freq_hz"] = p.freq_hz;
      pj["cm_to_dm_db"] = p.cm_to_dm_db;
      pj["cm_to_dm_nominal_db"] = p.cm_to_dm_nominal_db;
      pj["dm_per_unit"] = std::abs(p.dm);
      pj["dm_per_unit_worst"] = p.dm_worst;
      pj["cm_per_unit"] = std::abs(p.cm);
      pj["pin_cm_v"] = p.pin_cm_v;
      pj["dm_v"] = p.dm_v;
      pj["immunity"] = p.immunity;
      pj["limited_by"] = p.limited_by;
      pts.push_back(pj);
    }
    dj["points"] = pts;
    dj["immunity_min"] = {{"value", d.immunity_min}, {"freq_hz", d.immunity_min_freq}};
    dj["verdict_corner"] = d.pass_corner ? "pass" : "fail";
    const StatisticalImmunity& st = d.statistical;
    dj["statistical"] = {
        {"samples", st.samples},
        {"percentile", st.percentile},
        {"seed", st.seed},
        {"distribution", "uniform within each tolerance, parts independent"},
        {"immunity_min", {{"value", st.immunity_min}, {"freq_hz", st.immunity_min_freq}}},
        {"median_board_min", st.median},
        {"verdict", st.pass ? "pass" : "fail"}};
    dj["verdict"] = d.pass ? "pass" : "fail";
    ordered_json contributors = ordered_json::array();
    for (const Contributor& c : d.contributors)
      contributors.push_back({{"element", c.element}, {"kind", c.kind}, {"share", c.share}});
    dj["contributors"] = contributors;
    const NoiseBudget& b = d.budget;
    dj["budget"] = {{"dm_amplitude_v", b.dm_amplitude},
                    {"limited_by", b.limited_by},
                    {"vstart_vend_v", b.amplitude},
                    {"width_v", b.width},
                    {"edge_v", b.edge},
                    {"idle_v", b.idle},
                    {"slope_v_per_ns", b.slope * 1e-9},
                    {"pin_signal_v", b.pin_signal}};
    const TimeDomainCheck& t = d.time_domain;
    ordered_json tj;
    tj["done"] = t.done;
    if (!t.done) {
      tj["skipped"] = t.skipped;
    } else {
      tj["freq_hz"] = t.freq_hz;
      tj["dm_amplitude_v"] = t.dm_amplitude;
      tj["phases"] = t.phases;
      tj["phases_pass"] = t.phases_pass;
      tj["phases_decoded"] = t.phases_decoded;
      tj["predicted_pass"] = t.predicted_pass;
      tj["failures"] = t.failures;
    }
    dj["time_domain"] = tj;
    dj["tolerances"] = d.tolerances;
    dj["unknowns"] = d.unknowns;
    dirs.push_back(dj);
  }
  j["directions"] = dirs;
  j["factorizations"] = r.factorizations;
  j["seconds"] = r.seconds;
  return j;
}

namespace {

// "What drives the number": the top three parts at the weakest frequency.
std::string contributors_markdown(const NoiseDirection& d) {
  std::string md = fmt::format("- {}, at {} (worst corner): ", d.description,
                               link::format_si(d.immunity_min_freq, "Hz"));
  const NoisePoint* weakest = nullptr;
  for (const NoisePoint& p : d.points)
    if (p.freq_hz == d.immunity_min_freq) weakest = &p;
  if (weakest != nullptr && weakest->limited_by == "pins")
    md += "limited by the pins' common mode, which the tolerances barely move; ";
  if (d.contributors.empty()) return md + "no toleranced part moves the differential voltage.\n";
  md += "the differential voltage's imbalance comes from ";
  for (size_t i = 0; i < d.contributors.size() && i < 3; ++i)
    md += fmt::format("{}{} ({}) {:.0f} %", i ? ", " : "", d.contributors[i].element,
                      d.contributors[i].kind, d.contributors[i].share * 100);
  return md + (d.contributors.size() > 3 ? ", the rest less.\n" : ".\n");
}

}  // namespace

std::string noise_markdown(const NoiseResult& r) {
  const link::NoiseSpec& n = r.spec;
  const char* unit = n.level_unit();
  auto level = [&](double v) { return link::format_si(v, unit); };
  std::string md = fmt::format("## Noise immunity: {}\n\n", r.pass ? "PASS" : "FAIL");
  std::string what =
      n.injection == "bci" ? fmt::format(
                                 "BCI: common-mode current into both wires at {:g} of the "
                                 "cable from the tx end (ISO 11452-4)",
                                 n.position)
      : n.injection == "dm" ? fmt::format("differential current at {:g} of the cable", n.position)
                            : std::string("ground shift between the two boards' grounds");
  md +=
      fmt::format("- Injection: {}, test level {} RMS, {} (peak {:.3g} x the level), {} to {}.\n",
                  what, level(n.level), n.modulation == "am" ? "AM 80 % at 1 kHz" : "CW",
                  r.peak_factor, link::format_si(n.f_start, "Hz"), link::format_si(n.f_stop, "Hz"));
  md +=
      "- Worst case: each P and N part at its own tolerance limit, the worst corner of the "
      "linearised response at every frequency (`noise.tolerance`).\n";
  md += fmt::format(
      "- Statistics: {} boards, each part uniform within its tolerance (seed {}); the figure is "
      "the immunity 99 % of the boards reach.\n",
      n.samples, n.seed);
  md += fmt::format(
      "- Immunity: the highest level at which the differential noise at the "
      "receiver, at its worst phase, still meets every receiver rule and the pins "
      "stay inside +/-{:g} V. See `noise.png`.\n",
      n.pin_limit);
  md += n.verdict_on == "statistical"
            ? "- **The verdict is on the statistical figure** (`noise.verdict_on: statistical`); "
              "the worst corner is shown beside it.\n\n"
            : "- **The verdict is on the worst corner** (the default; `noise.verdict_on: "
              "statistical` judges the 99 % figure instead).\n\n";
  md +=
      "| direction | noise budget (DM) | limited by | immunity, worst corner | at | immunity, "
      "99 % of boards | at | verdict | time domain (worst corner) |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  for (const NoiseDirection& d : r.directions) {
    const TimeDomainCheck& t = d.time_domain;
    std::string td = t.done ? fmt::format("{:.3g} V DM at {}: {}/{} phases pass, {}/{} decode",
                                          t.dm_amplitude, link::format_si(t.freq_hz, "Hz"),
                                          t.phases_pass, t.phases, t.phases_decoded, t.phases)
                            : "skipped: " + t.skipped;
    const StatisticalImmunity& st = d.statistical;
    md += fmt::format("| {} | {:.3g} V | {} | {} | {} | {} | {} | {} | {} |\n", d.description,
                      d.budget.dm_amplitude, d.budget.limited_by, level(d.immunity_min),
                      link::format_si(d.immunity_min_freq, "Hz"), level(st.immunity_min),
                      link::format_si(st.immunity_min_freq, "Hz"), d.pass ? "pass" : "FAIL", td);
  }
  md += "\n";
  md +=
      "What drives the number: each toleranced part's share of the worst-corner differential "
      "voltage at the weakest frequency (`contributors` in report.json), the parts to tighten "
      "or match:\n\n";
  for (const NoiseDirection& d : r.directions) md += contributors_markdown(d);
  md += "\n";
  for (const NoiseDirection& d : r.directions) {
    md += fmt::format(
        "### {}\n\n| f | CM->DM worst (dB) | nominal (dB) | DM at level (V) | pin CM "
        "at level (V) | immunity | limited by |\n|---|---|---|---|---|---|---|\n",
        d.description);
    const size_t stride = std::max<size_t>(1, d.points.size() / 16);
    for (size_t i = 0; i < d.points.size(); i += stride) {
      const NoisePoint& p = d.points[i];
      md += fmt::format("| {} | {:.1f} | {:.1f} | {:.3g} | {:.3g} | {} | {} |\n",
                        link::format_si(p.freq_hz, "Hz"), p.cm_to_dm_db, p.cm_to_dm_nominal_db,
                        p.dm_v, p.pin_cm_v, level(p.immunity), p.limited_by);
    }
    md += fmt::format("\nToleranced parts: {}.\n\n", fmt::join(d.tolerances, ", "));
  }
  return md;
}

}  // namespace isolink::reports
