// The capture's column options, declared once for every command that reads a scope capture
// (`isolink check`, `isolink compare`): --time, --diff, --p, --n into an eye::CsvColumns, with
// --diff excluding --p and --n. The reader (eye/waveform_csv.h, eye::read_capture) resolves them.
//
//   eye::CsvColumns cols;
//   add_capture_column_options(*cmd, cols);   // cols is filled when the command line is parsed
#pragma once

#include <CLI/CLI.hpp>

#include "eye/waveform_csv.h"

namespace isolink::cli {

inline void add_capture_column_options(CLI::App& cmd, eye::CsvColumns& cols) {
  cmd.add_option("--time", cols.time,
                 "time column (name, channel, #K or 1-based index; default: the time column)");
  auto* diff = cmd.add_option("--diff", cols.diff,
                              "differential column (name, channel such as CH1, #K or 1-based "
                              "index; default: the first channel)");
  auto* p = cmd.add_option("--p", cols.p,
                           "P column: the differential is P - N (with two files: P's column in "
                           "the first)");
  auto* n = cmd.add_option("--n", cols.n, "N column (with two files: in the second)");
  diff->excludes(p)->excludes(n);
}

}  // namespace isolink::cli
