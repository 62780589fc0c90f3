// noise.png: the noise-immunity chart of `isolink noise` (analysis/noise.h), three panels over
// frequency (log): the CM -> DM conversion at the receiver pins (worst corner solid, nominal
// dashed), the pins' common mode at the test level against the +/- limit, and the immunity
// curve with the test level drawn; one colour per direction, failing frequencies shaded red.
//
//   Status s = write_noise_png(result, spec.name, dir + "/noise.png");   // temp file + rename
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the
// image plug-in or its fonts not found, a write that fails); the PNG is written to a temporary
// name and renamed, so a failure leaves no file.
#pragma once

#include <string>

#include "analysis/noise.h"
#include "base/status.h"

namespace isolink::reports {

Status write_noise_png(const analysis::NoiseResult& r, const std::string& title,
                       const std::string& path);

}  // namespace isolink::reports
