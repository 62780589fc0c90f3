#include "protocol/crc16.h"

namespace isolink {

uint16_t crc16_ibm(std::span<const uint8_t> data) {
  uint16_t crc = 0xFFFF;
  for (uint8_t byte : data) {
    crc ^= byte;
    for (int k = 0; k < 8; ++k) {
      crc = (crc & 1u) ? static_cast<uint16_t>((crc >> 1) ^ 0xA001u)
                       : static_cast<uint16_t>(crc >> 1);
    }
  }
  return crc;
}

void append_crc16(std::vector<uint8_t>& frame) {
  const uint16_t crc = crc16_ibm(frame);
  frame.push_back(static_cast<uint8_t>(crc & 0xFFu));
  frame.push_back(static_cast<uint8_t>(crc >> 8));
}

bool crc16_frame_ok(std::span<const uint8_t> frame) {
  // A reflected CRC run over data plus its own CRC (low byte first) leaves residue 0.
  return frame.size() >= 3 && crc16_ibm(frame) == 0;
}

}  // namespace isolink
