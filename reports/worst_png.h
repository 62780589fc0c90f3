// The images of `isolink worst` (and of the worst-case section of `isolink run`): per direction and
// metric, the waveform of the traffic that produces the worst value, with the worst pulse marked.
//
//   std::vector<std::string> files;
//   Status s = render_worst_pngs(worst, spec.name, {}, dir, &files);  // worst_down_vstart.png ...
// Each image is one wave.png panel (wave_png.h) of the replayed record (superposition of the edge
// response, the same waveform the search scored), titled with the metric, its value and margin,
// and the reproduce stimulus as the second title line.
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the
// image plug-in or its fonts not found, a write that fails); the PNG is written to a temporary
// name and renamed, so a failure leaves no file.
#pragma once

#include <string>
#include <vector>

#include "analysis/worst.h"
#include "base/status.h"
#include "netlists/traffic/encoding.h"

namespace isolink::reports {

// Writes dir/worst_<direction>_<metric>.png for every metric of every direction and appends the
// file names (without dir) to *files.
Status render_worst_pngs(const analysis::WorstResult& r, const std::string& spec_name,
                         const traffic::EncodingOptions& enc, const std::string& dir,
                         std::vector<std::string>* files);

}  // namespace isolink::reports
