// The daisy-chain byte frame, both ways: the one encoder (byte -> wire bits -> half bits) and
// decoder (half bits -> couplets -> bits -> bytes) that traffic/ (stimulus) and eye/ (decoding a
// measured waveform) share, with the one bit-order type.
//
// Usage:
//   FrameFormat fmt;                                  // preamble +, sync 00, SOF 1, LSB first
//   std::vector<int> w = frame_wire_bits(0x80, fmt);  // 0 0 1 00000001 0 (sync, SOF, data, err)
//   std::vector<int> h = frame_half_bits(0x80, fmt);  // +1/-1 per half bit (26 with SOF)
//   std::vector<DecodedByte> d = decode_half_bits(h, fmt);   // d[0].byte == 0x80
// Encoding (docs/physics.md rule 8.12 and section 2): 0 = (-, +), 1 = (+, -); frame = preamble
// (+), sync 0 0, [SOF], 8 data bits, error bit, postamble (-).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace isolink {

enum class BitOrder { kLsbFirst, kMsbFirst };

// Frame layout options.
struct FrameFormat {
  bool sof = true;                           // a start-of-frame bit follows the sync pair
  int sof_value = 1;                         // its value (0 or 1)
  BitOrder bit_order = BitOrder::kLsbFirst;  // data bit order on the wire

  size_t bits() const { return 2 + (sof ? 1 : 0) + 8 + 1; }  // sync, SOF, data, error bit
  size_t half_bits() const { return 2 * bits() + 2; }        // plus preamble and postamble
};

// The bits sent for one byte, in wire order: sync 0, 0, [SOF], 8 data bits, error bit.
std::vector<int> frame_wire_bits(uint8_t byte, const FrameFormat& fmt, bool error_bit = false);
// The half bits (+1 / -1) of one frame carrying byte: +1 preamble, the couplets of the wire
// bits, -1 postamble.
std::vector<int> frame_half_bits(uint8_t byte, const FrameFormat& fmt, bool error_bit = false);

// One decoded byte (or the place where decoding stopped) inside a run of half bits.
struct DecodedByte {
  size_t first_half = 0;        // index of its preamble half bit in the run
  size_t half_count = 0;        // half bits it covers (the rest of the run when it failed)
  std::optional<uint8_t> byte;  // the byte, when the structure decoded
  bool error_bit = false;       // the byte-error bit (a resend request)
  std::string fault;            // "" or "sync", "weak bit", "length"
  std::string detail;           // what exactly, in words
};

// Decodes a run of half bits into consecutive frames; stops at the first structural fault.
std::vector<DecodedByte> decode_half_bits(std::span<const int> half_bits, const FrameFormat& fmt);

// The role of half bit h (0-based from the preamble) in a frame: "preamble", "sync 0",
// "sync 1", "SOF", "bit 0".."bit 7" (data bit number), "error bit", "postamble".
std::string half_bit_role(size_t h, const FrameFormat& fmt);

}  // namespace isolink
