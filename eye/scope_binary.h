// Binary oscilloscope captures, read from their published format descriptions. One reader per
// format over one shared byte cursor (eye/scope_binary.cpp: BinFile, Fields): every header is
// read in its own byte order, every count is checked against the file's length before anything
// is reserved (memory is the samples the file holds, never what a header claims), and every
// field that cannot be honoured is refused as "FILE:byte OFFSET: error: WHY" (exit 2).
//  - Tektronix .isf: the WFMOutpre preamble as text (";"-separated "KEY value" pairs: BYT_NR,
//    BN_FMT, BYT_OR, NR_PT, XINCR, XZERO, PT_OFF, YMULT, YOFF, YZERO, WFID, XUNIT, YUNIT) and
//    ":CURVE #<n><length><data>"; t = XZERO + (i - PT_OFF) * XINCR, v = (raw - YOFF) * YMULT +
//    YZERO (Tektronix "MSO/DPO/TDS Series Programmer Manual", WFMOutpre and CURVe commands).
//  - Tektronix .wfm (WFM#001, #002, #003, either byte order): static file info, waveform header,
//    curve buffer with pre- and post-charge (skipped); v = exp_dim1.scale * adc + exp_dim1.offset,
//    t = imp_dim1.offset + (TT offset + i) * imp_dim1.scale from the first point after the
//    precharge (Tektronix "Reference Waveform File Format", 077-0220-xx / 001-1378-03, and
//    Tektronix's own reader tekwfm.py in Programmatic-Control-Examples).
//  - Keysight/Agilent .bin ("AG" cookie) and Rigol .bin ("RG01": MSO5000, MSO7000, MSO8000, the
//    same layout; MSO7000/8000 waveform headers are 128 bytes, not 140): file header, per
//    waveform a header (points, x increment, x origin, units, label) and data buffers of float32
//    volts; t = XOrigin + i * XIncrement, for Rigol t = -XOrigin + i * XIncrement (Keysight
//    InfiniiVision/Infiniium user's guides, "Binary Data File Format"; Rigol MSO5000 programming
//    guide, ":SAVE:WAVeform"; RigolWFM's rigol_mso5000_bin.ksy and rigol_7000_8000_bin.ksy).
//  - LeCroy .trc (WAVEDESC, template LECROY_2_3, optionally after a "#9nnnnnnnnn" block header):
//    byte order from COMM_ORDER, 8- or 16-bit samples from COMM_TYPE; v = VERTICAL_GAIN * raw -
//    VERTICAL_OFFSET, t = HORIZ_OFFSET + i * HORIZ_INTERVAL (Teledyne LeCroy remote control
//    manuals, "Waveform template LECROY_2_3").
//  - Rigol .wfm of the DS1000E/D family (magic A5 A5 00 00): 276-byte header, CH1 then CH2 as
//    8-bit counts; v = (125 - raw) * scale/25 - shift * scale/25, scale in uV/div times the probe,
//    t = offset - points * dt / 2 + i * dt, dt = 1 / sample rate (Rigol "DS1000E/D WFM structure
//    instruction"; the Kaitai description rigol_1000e_wfm.ksy of the RigolWFM project).
// Other Rigol .wfm families (DS1000Z, DS2000, DS4000, DS1000B/C, DHO) and other .bin layouts
// (Rigol DHO "RG03", Siglent, R&S .Wfm.bin) are refused with a message saying to export CSV.
//
// Usage:
//   if (std::optional<std::string> kind = binary_kind("c1.isf")) {
//     StatusOr<std::vector<BinaryTrace>> tr = read_binary("c1.isf");
//     tr->at(0).v;   // volts at tr->at(0).t seconds
//   }
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink::eye {

struct BinaryTrace {
  std::string name;  // "CH1", "Channel 1", "C2", the WFID or label
  std::vector<double> t, v;
  std::string time_from;  // "t = XZERO + (i - PT_OFF) * XINCR (...)"
  std::string y_unit;     // "V": every reader gives volts or refuses the trace
};

// "tektronix isf", "tektronix wfm", "keysight bin", "rigol bin", "lecroy trc", "rigol wfm", or one
// that is refused ("wfm", "binary (.bin)", "binary (.trc)"), from the extension and the first
// bytes; nullopt for text.
std::optional<std::string> binary_kind(const std::string& path);
// The same from the file's name and its first bytes (at least 64 when the file has them).
std::optional<std::string> binary_kind_of(const std::string& path, std::string_view head);
// Every trace of the file, t in seconds and v in volts, owned by the result. Errors
// ("FILE:byte OFFSET: error: WHY"): an unreadable file, a format that is refused (above), a
// header field that cannot be honoured, a count beyond the file's length, non-finite scaling.
StatusOr<std::vector<BinaryTrace>> read_binary(const std::string& path);

}  // namespace isolink::eye
