#pragma once
// The stress analysis's reports (analysis/stress.h computes it): the JSON of
// `isolink stress --json` and report.json, and report.md. Pure functions of a StressResult.
//
// Contract: pure functions of their arguments, which they only read: no I/O, no errors. Units
// are SI, named in the JSON keys (`_V`, `_A`, `_J`, `_s`, `_kV`) and the Markdown text.
// JSON shape (issue 42): {"spec", "verdict", "survives", "communicates", "limits": {KEY:
// {"value", "source"}}, "scenarios": [{"id", "kind", "end", "line", "level": {KEY_UNIT: v},
// "description", "window_s": [start, end], "peak_pin_v": {NODE: {"max", "min"}}, "pin_ground":
// {NODE: GROUND}, "peak_cm_V", "diodes": [...], "isolation_caps": [...], hot_plug's "contacts":
// [{"contact", "probe", "peak_1ns_A", "charge_C"}] (current positive into the plugged module),
// "receiver": {"p", "n", "rules"}, "traffic": {...}, "survives", "communicates", "first_broken",
// "broken", "engine", "seconds", "netlist"}]}.

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/pack_stress.h"
#include "analysis/stress.h"

namespace isolink::reports {

// `netlists`: scenario id -> its exported netlist's path (--export-spice), else empty.
nlohmann::ordered_json stress_json(const std::string& spec_name, const analysis::StressResult& r,
                                   const std::map<std::string, std::string>& netlists = {});
std::string stress_markdown(const std::string& spec_name, const analysis::StressResult& r,
                            const std::map<std::string, std::string>& netlists = {});

// A pack's stress (analysis/pack_stress.h): {"pack", "devices", "ring", "verdict", "survives",
// "all_reached", "simulations", "seconds", "faults": [{"hop", "breaks_hop", "normal_side",
// "reverse_side", "unreached", "reroute_delay_s", "scenario": a scenario object as above}]}.
nlohmann::ordered_json pack_stress_json(const std::string& pack_name,
                                        const analysis::PackStressResult& r);
std::string pack_stress_markdown(const std::string& pack_name, const analysis::PackStressResult& r);

}  // namespace isolink::reports
