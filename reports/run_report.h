// The text parts of the `isolink run` bundle: report.json, report.md, wave.csv. The images come
// from reports/ (eye_png.h, wave_png.h). Every file is written to a temporary name and renamed.
//
//   nlohmann::ordered_json j = run_report_json(spec, run);
//   std::string md = run_report_markdown(spec, run, {"eye.png", "wave.png"});
//   Waveform w = run_waveforms(run);          // every direction's probes on one time axis
//   Status s = write_file_atomic(dir + "/report.md", md);
//
// Contract: pure functions of their arguments (no I/O, no errors; units SI, named in the JSON
// keys); the caller writes the files (base/file_io.h write_file_atomic).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "base/waveform.h"
#include "netlists/link/link_spec.h"

namespace isolink::reports {

using analysis::DirectionRun;
using analysis::LinkRun;

// The spec with every default filled in (what was simulated).
nlohmann::ordered_json link_spec_json(const link::LinkSpec& spec);
// verdict, spec, per direction: rules, verdict, check JSON (eye/check.h), tones, solver stats.
nlohmann::ordered_json run_report_json(const link::LinkSpec& spec, const LinkRun& run);
// A reviewer's page: verdict, worst margins per direction, BOM, cable, run time, the images.
std::string run_report_markdown(const link::LinkSpec& spec, const LinkRun& run,
                                const std::vector<std::string>& images);
// The cable in one sentence: length, gauge, material, temperature, sections, impedance, delay
// and loss at 10 MHz (report.md and report.html).
std::string cable_summary(const link::LinkSpec& spec, const LinkRun& run);
// report.html (html_report.h): json is run_report_json's object (with "worst_case" when it was
// computed), eye_png the bytes of eye.png ("" when not drawn).
std::string run_report_page(const link::LinkSpec& spec, const LinkRun& run,
                            const nlohmann::ordered_json& json, const std::string& eye_png);
// "pass" / "FAIL" lines for the terminal: one per direction, with the worst margins.
std::string run_summary_text(const link::LinkSpec& spec, const LinkRun& run);

}  // namespace isolink::reports
