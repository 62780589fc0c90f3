// Reading a waveform (isolink and SPICE CSVs, oscilloscope exports) into a Waveform that holds the
// time axis and one differential column, plus a record of what was read.
//
// Usage:
//   CsvColumns cols;                 // defaults: the time column, the first channel
//   cols.p = "CH1"; cols.n = "CH2";  // or cols.diff = "v(rxp,rxn)"; a column is a name, a
//                                    // channel (CH1 = "Channel 1" = "C1 in V"), #K or K
//   CaptureInfo info;
//   StatusOr<Waveform> w = read_capture({"p.csv", "n.csv"}, cols, &info);  // or one file
//   if (!w) fputs(w.status().message().c_str(), stderr);  // "p.csv:17: error: ..."
//   const std::vector<double>& v = w->columns[0];        // v(t) = P - N at w->time, volts
//   std::puts(capture_text(info).c_str());               // files, columns, samples, scaling
// The layouts read are in eye/scope_formats.h and eye/README.md. Files are streamed in chunks:
// memory is the samples kept (16 bytes each), not the file. Time must increase strictly.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"

namespace isolink::eye {

// Which columns to read; each is a header name (exact, else case-insensitive), a channel name,
// "#K" (1-based index only) or a bare 1-based index K (a name wins; the choice is reported).
struct CsvColumns {
  std::string time;  // "" = the layout's time column (the first column by default)
  std::string diff;  // the differential column; "" = the first channel unless p/n are given
  std::string p;     // P line (with n): the differential is P - N
  std::string n;     // N line
};

// One column used.
struct CaptureColumn {
  std::string role;  // "time", "P", "N" or "diff"
  std::string file;
  std::string name;     // header name ("column K" without one)
  std::string channel;  // canonical channel ("CH1"), "" when none
  size_t index = 0;     // 1-based field
  std::string how;      // "by name", "by channel CH1", "by index 3", "default"
  std::string unit;     // as written, "" when none was given
  double scale = 1;     // applied to reach seconds / volts
};

// What was read, for the summary and the JSON.
struct CaptureInfo {
  std::vector<std::string> files;
  std::vector<std::string> layouts;  // one per file
  std::vector<CaptureColumn> columns;
  std::string time_from;  // "column 1 ('TIME')", "rebuilt: t = Start + X * ..."
  size_t samples = 0;
  double t_begin = 0, t_end = 0;
  double interval = 0;             // median sample interval (s)
  bool uniform = true;             // every interval within 1 % of the median
  std::string alignment;           // two files: how N was put on P's time base
  std::vector<std::string> notes;  // ambiguities resolved, units assumed
};

// Errors ("FILE:LINE: error: ..." where a line applies, nothing returned): an unreadable or
// oversized file, no data rows, a column that is not there, a field that is not a number, time
// that does not increase strictly; with two files, P and N the same column, or captures that do
// not share a time base or span (the message says which). info may be null; when given, it is
// filled on success (its contents are unspecified after an error). The Waveform holds the time axis
// (s) and one column, the differential (V).
StatusOr<Waveform> parse_differential_csv(std::string_view text, const std::string& source,
                                          const CsvColumns& cols = {}, CaptureInfo* info = nullptr);
StatusOr<Waveform> read_differential_csv(const std::string& path, const CsvColumns& cols = {},
                                         CaptureInfo* info = nullptr);
// One file (P - N, or a differential column) or two (P from the first, N from the second; N is
// interpolated onto P's time base where they differ, over the span both cover).
StatusOr<Waveform> read_capture(const std::vector<std::string>& paths, const CsvColumns& cols,
                                CaptureInfo* info = nullptr);

nlohmann::ordered_json capture_json(const CaptureInfo& info);
std::string capture_text(const CaptureInfo& info);

}  // namespace isolink::eye
