// compare.png of `isolink compare -o DIR`: the capture and the simulation of the same traffic
// overlaid over the whole record (before the fit, and after it when one was asked for), the
// residual (capture - simulation) below, and zoom panels on the (at most three) frames with the
// largest residual.
//
//   StatusOr<analysis::CompareResult> r = analysis::compare_capture(in, parts, opt);
//   Status s = write_compare_png(*r, dir + "/compare.png");   // temp file + rename
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the
// image plug-in or its fonts not found, a write that fails); the PNG is written to a temporary
// name and renamed, so a failure leaves no file.
#pragma once

#include <string>

#include "analysis/compare.h"
#include "base/status.h"

namespace isolink::reports {

Status write_compare_png(const analysis::CompareResult& r, const std::string& path);

}  // namespace isolink::reports
