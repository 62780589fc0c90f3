// Reading a waveform CSV (isolink, ngspice/LTspice exports, scope captures) into a Waveform that
// holds the time axis and one differential column.
//
// Usage:
//   CsvColumns cols;                 // defaults: time = 1st column, differential = 2nd
//   cols.p = "CH1"; cols.n = "CH2";  // or cols.diff = "v(rxp,rxn)"; a column is a name or a
//   1-based index StatusOr<Waveform> w = read_differential_csv("scope.csv", cols); if (!w)
//   fputs(w.status().message().c_str(), stderr);  // "scope.csv:17: error: ..." const
//   std::vector<double>& v = w->columns[0];        // v(t) = P - N at w->time
// Leading metadata lines are skipped up to the header (the first non-numeric line followed by a
// numeric row with as many fields); delimiters: comma, tab, semicolon or blanks; quoted names;
// scientific notation; non-uniform steps. Time must increase strictly.
#pragma once

#include <string>
#include <string_view>

#include "base/status.h"
#include "base/waveform.h"

namespace isolink::eye {

// Which columns to read; each is a header name (exact, else case-insensitive) or a 1-based index.
struct CsvColumns {
  std::string time;  // "" = the first column
  std::string diff;  // the differential column; "" = the second column unless p/n are given
  std::string p;     // P line (with n): the differential is P - N
  std::string n;     // N line
};

// Parses CSV text; source names it in errors ("FILE:LINE: error: ...").
StatusOr<Waveform> parse_differential_csv(std::string_view text, const std::string& source,
                                          const CsvColumns& cols = {});
// Reads the file at path.
StatusOr<Waveform> read_differential_csv(const std::string& path, const CsvColumns& cols = {});

}  // namespace isolink::eye
