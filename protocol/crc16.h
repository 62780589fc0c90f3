// CRC-16-IBM as the TI daisy-chain devices (BQ7961x, BQ79600, BQ79606A) compute it.
//
// Usage:
//   std::vector<uint8_t> f = {0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC};
//   append_crc16(f);                       // f now ends 0A 35 (low byte first on the wire)
//   bool good = crc16_frame_ok(f);         // true: CRC over the whole frame is 0
// Variant: polynomial x^16+x^15+x^2+1 (0x8005), bits reflected (shift right with 0xA001),
// initial value 0xFFFF, no final XOR ("CRC-16/MODBUS"); check value over "123456789" = 0x4B37.
// It reproduces the four worked examples of docs/physics.md section 7 byte for byte.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace isolink {

// CRC of data (initial value 0xFFFF, reflected polynomial 0xA001).
uint16_t crc16_ibm(std::span<const uint8_t> data);
// Appends the CRC of frame to it, low byte first.
void append_crc16(std::vector<uint8_t>& frame);
// True when frame (payload followed by its CRC, low byte first) checks; needs at least 3 bytes.
bool crc16_frame_ok(std::span<const uint8_t> frame);

}  // namespace isolink
