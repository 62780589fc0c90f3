// stress.png: the pin voltages of `isolink stress` (analysis/stress.h) over time, one panel per
// scenario that breaks something (at most kStressPanels; report.md lists the rest), each with the
// pin limit drawn at +/- pin_abs_max, the disturbance's window shaded and the first limit broken
// as the panel's title. When nothing breaks, one panel: the scenario whose pins came closest to
// their limit, so the picture still shows the margin.
//
//   Status s = write_stress_png(result, spec.name, dir + "/stress.png");  // temp file + rename
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the image
// plug-in or its fonts not found, a write that fails, a result with no pin waveform); the PNG is
// written to a temporary name and renamed, so a failure leaves no file.
#pragma once

#include <string>
#include <vector>

#include "analysis/stress.h"
#include "base/status.h"
#include "reports/plot.h"

namespace isolink::reports {

inline constexpr int kStressPanels = 6;

// The layout, for the tests: the image size and each panel's plot area (data -> pixels).
struct StressPngLayout {
  int width = 0, height = 0;
  std::vector<size_t> scenarios;  // the scenarios drawn, in panel order (indices into r.scenarios)
  std::vector<PlotArea> areas;    // their plot areas
  double pin_limit_v = 0;         // the +/- line drawn in each panel
};
// Which scenarios get a panel and where (pure; no drawing).
StressPngLayout stress_png_layout(const analysis::StressResult& r);

// A pin's trace colour by its node name (txp, txn, rxp, rxn; any other pin a grey), and the limit
// line's colour.
Color stress_pin_color(const std::string& node);
inline constexpr Color kStressLimit = rgb(0xE00000);

Status write_stress_png(const analysis::StressResult& r, const std::string& title,
                        const std::string& path);

}  // namespace isolink::reports
