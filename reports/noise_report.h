#pragma once
// The noise analysis's reports (analysis/noise.h computes it): the JSON of `isolink noise --json`
// and of report.json's `noise`, and the report.md section. Pure functions of a NoiseResult.
//
// Contract: pure functions of their arguments, which they only read: no I/O, no errors. Units
// are SI, named in the JSON keys (`_s`, `_V`, `_ns`) and the Markdown text.

#include <nlohmann/json.hpp>
#include <string>

#include "analysis/noise.h"

namespace isolink::reports {

// The shape of `isolink noise --json`: verdict, injection, level, band, the statistics, and per
// direction the frequency points, the worst corner's and the statistical immunity, the
// contributors, the noise budget and the time-domain confirmation.
nlohmann::ordered_json noise_json(const analysis::NoiseResult& r);
// The report.md section ("## Noise immunity ...").
std::string noise_markdown(const analysis::NoiseResult& r);

}  // namespace isolink::reports
