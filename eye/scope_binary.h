// Binary oscilloscope captures, read from their published format descriptions:
//  - Tektronix .isf: the WFMOutpre preamble as text (";"-separated "KEY value" pairs: BYT_NR,
//    BN_FMT, BYT_OR, NR_PT, XINCR, XZERO, PT_OFF, YMULT, YOFF, YZERO, WFID, XUNIT, YUNIT) and
//    ":CURVE #<n><length><data>"; t = XZERO + (i - PT_OFF) * XINCR, v = (raw - YOFF) * YMULT +
//    YZERO (Tektronix "MSO/DPO/TDS Series Programmer Manual", WFMOutpre and CURVe commands).
//  - Keysight/Agilent .bin: "AG" cookie, version, file size, waveform count; per waveform a
//    header (points, x increment, x origin, units, label) and data buffers of float32 volts;
//    t = XOrigin + i * XIncrement (Keysight InfiniiVision/Infiniium "Binary data file format"
//    appendix of the oscilloscope user's guides).
// Other binary formats (.wfm, .trc, Rigol .bin) are refused with a message saying to export CSV.
//
// Usage:
//   if (std::optional<std::string> kind = binary_kind("c1.isf")) {
//     StatusOr<std::vector<BinaryTrace>> tr = read_binary("c1.isf");
//     tr->at(0).v;   // volts at tr->at(0).t seconds
//   }
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "base/status.h"

namespace isolink::eye {

struct BinaryTrace {
  std::string name;  // "CH1", "Channel 1", the WFID or label
  std::vector<double> t, v;
  std::string time_from;  // "t = XZERO + (i - PT_OFF) * XINCR (...)"
  std::string y_unit;     // as written ("V")
};

// "tektronix isf", "keysight bin", or one that is refused ("tektronix wfm", "lecroy trc",
// "rigol binary"), from the extension and the first bytes; nullopt for text.
std::optional<std::string> binary_kind(const std::string& path);
StatusOr<std::vector<BinaryTrace>> read_binary(const std::string& path);

}  // namespace isolink::eye
