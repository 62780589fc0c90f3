// noise.png: the noise-immunity chart of `isolink noise` (analysis/noise.h), three panels over
// frequency (log): the CM -> DM conversion at the receiver pins (worst corner solid, nominal
// dashed), the pins' common mode at the test level against the +/- limit, and the immunity
// curve with the test level drawn; one colour per direction, failing frequencies shaded red.
//
//   Status s = write_noise_png(result, spec.name, dir + "/noise.png");   // temp file + rename
#pragma once

#include <string>

#include "analysis/noise.h"
#include "base/status.h"

namespace isolink::reports {

Status write_noise_png(const analysis::NoiseResult& r, const std::string& title,
                       const std::string& path);

}  // namespace isolink::reports
