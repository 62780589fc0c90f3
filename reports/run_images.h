// The images of the `isolink run` bundle: eye.png and wave.png, one panel per direction, drawn
// by reports/ from each direction's waveform and check.
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the
// image plug-in or its fonts not found, a write that fails); the PNG is written to a temporary
// name and renamed, so a failure leaves no file.
#pragma once

#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "netlists/link/link_spec.h"

namespace isolink::reports {

using analysis::DirectionRun;
using analysis::LinkRun;

// Writes dir/eye.png and dir/wave.png; appends the file names written to *images.
Status render_run_images(const link::LinkSpec& spec, const LinkRun& run, const std::string& dir,
                         std::vector<std::string>* images);

}  // namespace isolink::reports
