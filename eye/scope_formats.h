// Oscilloscope export layouts: where the names, the units and the data start, which field is
// time, how time is rebuilt when the file gives sample numbers or nothing, and the scale a units
// row applies. Detected from the file's first lines; the rows are then streamed by
// eye/waveform_csv.cpp. The tokenizer underneath is eye/csv_lines.h.
//
// Usage:
//   std::vector<std::string> head = ...;          // first lines, BOM and line ends removed
//   StatusOr<ScopeLayout> l = detect_layout(head, "scope.csv", 1);
//   l->columns[l->time].scale;                    // 1e-6 for a "(us)" units row
//   StatusOr<ColumnPick> p = pick_column(*l, "CH1", "--p", "scope.csv");
//
// Layouts (eye/README.md lists an example of each): a header of names, optionally a units row
// under it (Keysight InfiniiVision, Rigol, Siglent, PicoScope), units inside the names ("Time (s)",
// "C1 in V", "Time [s]"), Rigol X/Start/Increment, Tektronix TDS/TBS classic (metadata in fields
// 1-3, time and value in 4-5), a "Key: value" header ending in "Data:" (Keysight Infiniium), and
// no header at all (R&S .Wfm.csv, time in field 1 or rebuilt from a sample interval).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "base/status.h"

namespace isolink::eye {

enum class UnitKind { kNone, kTime, kVolt, kIndex, kOther };

struct Unit {
  UnitKind kind = UnitKind::kNone;
  double scale = 1;  // to seconds or volts
  std::string text;  // as written
};
// "s", "(us)", "[ms]", "ns", "Second", "Volt", "mV", "uV", "kV", "Sequence", "A", ...;
// nullopt for a word that is not a unit.
std::optional<Unit> parse_unit(std::string_view token);

// The canonical channel a name stands for: "CH1" for CH1, C1, Channel 1, CHAN1, 1, "C1 in V";
// "CHA" for Channel A, Canal A, Kanal A; "MATH1" for M1, MATH1, F1; "MATH" for MATH; "REF1" for R1,
// REF1; "D0" for D0; "" when the name is no channel.
std::string canonical_channel(std::string_view name);

struct ScopeColumn {
  std::string name;          // as in the header; "column K" when there is none
  std::string channel;       // canonical channel, "" when none
  Unit unit;                 // from a units row, from the name ("Time (s)") or from the preamble
  size_t field = 0;          // 0-based field in a data row
  bool time_like = false;    // a time or sample-number column (never P or N)
  bool meta = false;         // Rigol Start/Increment: not a signal
  double probe_factor = 0;   // Rigol DS1052E "Attenuation" row (10 for 10X); 0 when none
  double volts_per_div = 0;  // its "Scale (V/DIV)" row, before the probe; 0 when none
};

struct ScopeLayout {
  std::string name;  // "header", "header + units row", "units row", "rigol start/increment",
                     // "tektronix classic", "key: value header", "no header"
  char delim = ',';  // ' ' = runs of blanks
  bool decimal_comma = false;
  int header_line = 0;  // 1-based; 0 when none
  int units_line = 0;
  int data_line = 0;       // first data row
  size_t data_fields = 0;  // fields in a data row
  std::vector<ScopeColumn> columns;
  int time = -1;               // column holding time (or sample numbers); -1: t = t0 + row * dt
  bool time_is_index = false;  // that column counts samples: t = t0 + x * dt
  double t0 = 0, dt = 0;
  std::string time_from;                                      // how time is obtained, in words
  std::vector<std::pair<std::string, std::string>> preamble;  // key, value as read
  int probe_line = 0;  // 1-based line of the "Attenuation" row; 0 when none
  const std::string* find(std::string_view key) const;  // preamble value, case-insensitive
};

// head: the file's first lines (BOM and line ends removed), head[0] being line first_line.
// The sibling header of an R&S .Wfm.csv (a "Key:value:" file) is read by the caller and passed
// as extra_preamble.
StatusOr<ScopeLayout> detect_layout(
    const std::vector<std::string>& head, const std::string& source, bool more_lines,
    const std::vector<std::pair<std::string, std::string>>& extra_preamble = {});

// A column chosen by the user: by name (exact, then ignoring case), by channel ("CH1" matches
// "Channel 1", "1", "C1 in V"), by "#K" (1-based index only) or by a bare index K.
struct ColumnPick {
  size_t column = 0;  // into layout.columns
  std::string how;    // "by name", "by channel CH1", "by index 3"
  std::string note;   // set when the reference was ambiguous: which reading was used
};
StatusOr<ColumnPick> pick_column(const ScopeLayout& l, const std::string& ref, const char* flag,
                                 const std::string& source);
// A column with a probe factor (ScopeColumn::probe_factor > 0): step is the smallest change
// between consecutive values over the record (0 when it never changes). Refused ("FILE:LINE:
// error: ...", the Attenuation row's line) when the values step by the scale without the probe,
// which contradicts the row; otherwise a note for the read block, "" when there is no factor.
StatusOr<std::string> check_probe_step(const ScopeLayout& l, const ScopeColumn& c, double step,
                                       const std::string& source);
// The first signal column (not time, not Start/Increment).
std::optional<size_t> first_channel(const ScopeLayout& l);

}  // namespace isolink::eye
