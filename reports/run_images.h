// The images of the `isolink run` bundle: eye.png and wave.png, one panel per direction, drawn
// by reports/ from each direction's waveform and check.
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
