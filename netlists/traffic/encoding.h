// Byte -> half-bits: the daisy-chain byte frame of docs/physics.md section 2 and rule 8.12.
//
// Usage:
//   EncodingOptions opt;                               // 250 ns pulses, SOF 1, LSB first, error 0
//   std::vector<int> h = byte_half_bits(0xB3, opt);    // 26 signs (+1/-1), 13 bit times
//   std::string s = byte_bit_string(0xB3, opt);        // "+ 00 1 11001101 0 -"
//   double t = byte_duration(opt);                     // 6.5e-6 s
// A byte frame on the wire: preamble (one + half bit), sync 00, SOF (default 1), 8 data bits
// (default LSB first), error bit (default 0), postamble (one - half bit). A 0 is the couplet
// (-, +), a 1 is (+, -). Adjacent same-sign half bits form one longer pulse ("double bit");
// DriveBuilder (drive.h) merges them into segments. The frame layout, the bit order and the
// encoder itself are protocol/frame.h, which eye/ decodes with; this file adds the timing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "base/status.h"
#include "protocol/frame.h"

namespace isolink::traffic {

// The frame layout (sof, sof_value: our reading 1, see docs/physics.md section 2; bit_order) plus
// the timing and the error bit of the bytes sent.
struct EncodingOptions : FrameFormat {
  double half_bit = 250e-9;  // pulse (half-bit) width, s
  int error_bit = 0;         // byte-error bit (1 asks the sender to resend)
};

// Ok, or an error naming the bad option (half_bit > 0, sof_value and error_bit 0 or 1).
Status validate(const EncodingOptions& opt);

// The bits sent for one byte, in wire order: sync 0, 0, [SOF], 8 data bits, error bit.
std::vector<int> byte_wire_bits(uint8_t byte, const EncodingOptions& opt);
// Half-bit signs for one byte: +1 preamble, couplets of the wire bits, -1 postamble.
std::vector<int> byte_half_bits(uint8_t byte, const EncodingOptions& opt);
// Half bits per byte frame: 26 with SOF (13 bit times), 24 without.
int byte_half_bit_count(const EncodingOptions& opt);
// Length of one byte frame on the wire: byte_half_bit_count * half_bit (6.5 us by default).
double byte_duration(const EncodingOptions& opt);
// Readable wire order: "+ 00 1 11001101 0 -" (preamble, sync, SOF, data, error, postamble).
std::string byte_bit_string(uint8_t byte, const EncodingOptions& opt);
// Number of double-length pulses (two touching same-sign half bits) in the byte's frame.
int double_pulse_count(uint8_t byte, const EncodingOptions& opt);

}  // namespace isolink::traffic
