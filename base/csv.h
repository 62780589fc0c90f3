// CSV as RFC 4180 reads it, for every CSV file isolink writes (wave.csv, `isolink sim` output,
// pulses.csv, results.csv, sweep point lists) and the ones it reads back (results.csv --resume):
// fields separated by commas; a field that contains a comma, a double quote, a CR or an LF, or
// starts or ends with a space, is enclosed in double quotes with its quotes doubled. Records end
// with LF (RFC 4180 writes CRLF; every reader this project targets, Python's csv module, pandas,
// spreadsheets, accepts LF, and LF keeps the files diff- and grep-friendly).
//
//   std::string line = csv_row({"time", "down v(rxp,rxn)"});  // time,"down v(rxp,rxn)"\n
//   std::vector<std::string> f = split_csv_line(R"(a,"b,c")");  // {"a", "b,c"}
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace isolink {

// One field, quoted when it must be.
std::string csv_field(std::string_view s);
// Fields joined by commas, each through csv_field, and a final "\n".
std::string csv_row(const std::vector<std::string>& fields);
// One record (no line end) back into its fields: quotes removed, doubled quotes undone.
std::vector<std::string> split_csv_line(std::string_view line);

}  // namespace isolink
