#pragma once
// The worst case's reports (analysis/worst.h computes it): the JSON of `isolink worst --json` and
// of report.json's `worst_case`, the Markdown section of report.md, the terminal lines, and each
// metric's replay block. Pure functions of a WorstResult; no I/O.
//
//   StatusOr<analysis::WorstResult> w = analysis::worst_case(spec, parts);
//   std::puts(worst_json(*w).dump(2).c_str());
//
// Contract: pure functions of their arguments, which they only read: no I/O, no errors. Units
// are SI, named in the JSON keys (`_s`, `_V`, `_ns`) and the Markdown text.

#include <nlohmann/json.hpp>
#include <string>

#include "analysis/worst.h"

namespace isolink::reports {

// The stimulus block that replays a metric's traffic in `isolink run` (YAML flow map).
std::string reproduce_stimulus(const analysis::WorstMetric& m, link::Direction d);
// The same block as JSON, exactly the keys `stimulus:` takes (frames, gaps as times with their
// unit, "3.85u", direction): `spec["stimulus"] = reproduce` replays it. worst_json's `reproduce`.
nlohmann::ordered_json reproduce_json(const analysis::WorstMetric& m, link::Direction d);

// JSON (verdict, directions[].worst.{vstart, vend, width_min, width_max, edge} with each
// metric's value, limit, margin, traffic and replay block), Markdown section body, terminal lines.
nlohmann::ordered_json worst_json(const analysis::WorstResult& r);
std::string worst_markdown(const analysis::WorstResult& r);
std::string worst_summary_text(const analysis::WorstResult& r);

}  // namespace isolink::reports
