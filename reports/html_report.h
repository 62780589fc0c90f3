// report.html: the browser's view of a run, a sweep or a pack, as one self-contained file. The
// page carries its data as JSON in a <script type="application/json"> block (report.json's
// content plus the waveforms as base64 typed arrays and the images as data: URIs) and draws it
// with Debian's dygraphs and the page script (reports/html/report.js), both inlined at build time:
// no network reference of any kind, it opens offline. When every plot is drawn the script sets
// data-ready="1" on <body> (the headless-browser test waits for it).
//
//   std::vector<HtmlWave> waves{{.direction = "down: bq79600 -> bq7961x", .time = w.time,
//                                .values = *w.column("v(rxp,rxn)")}};
//   std::string page = run_report_html(report_json, waves, eye_png_bytes);
//   Status s = write_file_atomic(dir + "/report.html", page);
//
// Contract: the page builders are pure functions of their arguments (no I/O, no errors); the
// caller writes the page (write_file_atomic).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/stress.h"
#include "analysis/sweep_run.h"
#include "base/status.h"

namespace isolink::reports {

// --- shared helpers (every page) ---

// Text for HTML content and attribute values: & < > " ' escaped.
std::string html_escape(std::string_view s);
// RFC 4648 base64 (with padding).
std::string base64(std::span<const uint8_t> bytes);
// "data:image/png;base64,..." for PNG file bytes ("" for none).
std::string png_data_uri(const std::string& png);
// JSON for a <script type="application/json"> block: every "</" written "<\/" (still the same
// JSON), so no string in it can close the block.
std::string script_json(const nlohmann::ordered_json& j);
// The whole document: the style, the data block, the library and the page script. `kind` is
// "run", "sweep" or "pack" (the script draws that page from data).
std::string html_page(const std::string& kind, const std::string& title,
                      const nlohmann::ordered_json& data);

// --- waveforms ---

// One series to embed: samples at strictly increasing times.
struct HtmlWave {
  std::string direction;           // "down: bq79600 -> bq7961x"
  std::span<const double> time;    // s (not owned)
  std::span<const double> values;  // V (not owned)
};
// The base64 bytes a page spends on its waves at most (all distinct directions together): with the
// rest (the library ~130 kB, report.json up to a few MB, the eye image ~1 MB) a page stays under
// 40 MB. A uniform grid costs 16/3 bytes a sample (Float32 values), another 16/3 for Float32 time
// offsets (records up to kFloat32TimeSpan) or 32/3 for Float64 ones (longer records, where a
// Float32 offset would round to more than 6 ps). A longer record is thinned (below) and the page
// says within what; min/max buckets only when even the coarsest thinning does not fit.
inline constexpr size_t kHtmlWaveBytes = 32'000'000;
inline constexpr double kFloat32TimeSpan = 100e-6;
// The tolerances a record is thinned with, finest first (V): analysis/link_run_wave.h thin_rows,
// linear interpolation between the kept samples within the tolerance of every sample. Up to
// 100 mV (2.5 % of a 4 V pulse) so that a 200 ms record (2,000 frames, 364,000 pulses) still
// keeps its pulses' shape when zoomed to a frame, rather than each bucket's extremes.
inline constexpr double kHtmlThinTolerances[] = {1e-3, 2e-3, 5e-3, 10e-3, 20e-3, 50e-3, 100e-3};
// A wave as JSON: {direction, samples, kept, t0, and dt, t_last (a uniform grid: times t0 + i dt
// within 1e-6 of dt, the last sample at t_last), or t (base64 Float32 offsets from t0) or t64
// (base64 Float64 offsets, records longer than kFloat32TimeSpan), v (base64 Float32), and
// tolerance (V) when thinned or buckets: true when reduced by min/max}. At most max_samples are
// kept: a longer record is thinned with the finest of kHtmlThinTolerances that fits; when none
// does, cut into max_samples / 2 buckets that each keep their lowest and highest sample (in time
// order). Non-finite values are written as NaN (drawn as gaps).
nlohmann::ordered_json wave_json(const HtmlWave& w, size_t max_samples);
// The samples a wave of this span may keep within a byte budget (base64 of Float32 values and
// Float32 or Float64 time offsets).
size_t wave_samples_for(size_t bytes, double span);
// The sample indices a record of n samples keeps at most max_samples of (all when n fits): per
// bucket the index of the lowest and of the highest value, in time order.
std::vector<size_t> minmax_keep(std::span<const double> v, size_t max_samples);

// --- pages ---

// A run (a wave equal to an earlier one is embedded once: {direction, same_as: its index}):
// report is report.json's object (run_report_json, with "worst_case" when computed),
// extra: {"bom": {"tx", "rx"}, "cable": text}; waves per direction; eye_png the eye.png file's
// bytes ("" when not drawn).
std::string run_report_html(const nlohmann::ordered_json& report,
                            const nlohmann::ordered_json& extra, const std::vector<HtmlWave>& waves,
                            const std::string& eye_png);
// A sweep: its results (the rows of results.csv as objects), axes and title.
std::string sweep_report_html(const analysis::sweep::SweepSpec& s,
                              const std::vector<analysis::sweep::PointResult>& results);
// A pack: report is report.json's object (pack_report_json); pack_png the diagram's bytes.
std::string pack_report_html(const nlohmann::ordered_json& report, const std::string& pack_png);
// The samples each stress scenario's pin plot keeps at most (per scenario, all pins together).
inline constexpr size_t kStressPinSamples = 8000;
// A scenario's pins for the stress page: {"t" (base64 Float64 times), "pins": {NODE: base64
// Float32}, "samples", "kept"}. A record longer than max_samples keeps, per pin, the lowest and
// highest sample of each of max_samples / (2 x pins) buckets (minmax_keep), the union in time
// order: every peak the report names is on the plot.
nlohmann::ordered_json stress_pins_json(const analysis::StressScenario& s, size_t max_samples);
// A stress run: report is report.json's object (stress_json); stress_png the image's bytes ("" when
// not drawn); each scenario's pins (stress_pins_json) are drawn under its row.
std::string stress_report_html(const nlohmann::ordered_json& report, const std::string& stress_png,
                               const analysis::StressResult& r);

namespace detail {
std::string_view dygraph_js();   // Debian's dygraph.min.js (licence and source-map comments cut)
std::string_view dygraph_css();  // dygraph.min.css
std::string_view page_js();      // reports/html/report.js
std::string_view page_css();     // reports/html/report.css
}  // namespace detail

}  // namespace isolink::reports
