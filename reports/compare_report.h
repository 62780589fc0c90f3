// isolink compare's reports (analysis/compare.h computes the comparison): report.json and
// `--json` (issue 29's shape and more), the terminal lines and report.md's body. Pure functions
// of a CompareResult; no I/O, no errors.
//
//   StatusOr<analysis::CompareResult> r = analysis::compare_capture(in, parts, opt);
//   std::puts(compare_json(*r).dump(2).c_str());
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "analysis/compare.h"

namespace isolink::reports {

// The JSON shape (verdict, direction, offset_s in s, residual in V, fit,
// residual_after_fit, findings) and more: noise, thresholds, metrics, input, and the capture's
// commands exactly as `isolink check --json` gives them (commands, commands_omitted,
// commands_note). Numbers that are not finite are null.
nlohmann::ordered_json compare_json(const analysis::CompareResult& r);
// A few lines for people (mV, us; the fitted keys in their own units).
std::string compare_text(const analysis::CompareResult& r);
// The Markdown report body (report.md without its image).
std::string compare_markdown(const analysis::CompareResult& r);

}  // namespace isolink::reports
