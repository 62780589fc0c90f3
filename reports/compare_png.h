// compare.png of `isolink compare -o DIR`: the capture and the simulation of the same traffic
// overlaid over the whole record (before the fit, and after it when one was asked for), the
// residual (capture - simulation) below, and zoom panels on the (at most three) frames with the
// largest residual.
//
//   StatusOr<analysis::CompareResult> r = analysis::compare_capture(in, parts, opt);
//   Status s = write_compare_png(*r, dir + "/compare.png");   // temp file + rename
#pragma once

#include <string>

#include "analysis/compare.h"
#include "base/status.h"

namespace isolink::reports {

Status write_compare_png(const analysis::CompareResult& r, const std::string& path);

}  // namespace isolink::reports
