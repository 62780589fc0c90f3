#include "protocol/crc16.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace isolink {
namespace {

TEST(Crc16, CheckValueOf123456789) {
  const std::string s = "123456789";
  const std::vector<uint8_t> b(s.begin(), s.end());
  EXPECT_EQ(crc16_ibm(b), 0x4B37);  // CRC-16/MODBUS catalogue check value
}

TEST(Crc16, EmptyInputIsInitialValue) {
  EXPECT_EQ(crc16_ibm({}), 0xFFFF);
}

TEST(Crc16, SingleZeroByteByHand) {
  // 0xFFFF ^ 0x00, eight shifts with 0xA001: 0x40BF (hand-stepped).
  const std::vector<uint8_t> b = {0x00};
  EXPECT_EQ(crc16_ibm(b), 0x40BF);
}

TEST(Crc16, WorkedExamplesFromDomainSection7) {
  struct Case {
    std::vector<uint8_t> payload;
    uint8_t lo, hi;
  };
  const Case cases[] = {
      {{0x80, 0x00, 0x02, 0x15, 0x0B}, 0xCB, 0x49},
      {{0x93, 0x00, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC}, 0x9A, 0x8C},
      {{0xA0, 0x02, 0x15, 0x0B}, 0xCC, 0xB3},
      {{0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC}, 0x0A, 0x35},
  };
  for (const Case& c : cases) {
    std::vector<uint8_t> f = c.payload;
    append_crc16(f);
    ASSERT_EQ(f.size(), c.payload.size() + 2);
    EXPECT_EQ(f[f.size() - 2], c.lo);  // low byte first on the wire
    EXPECT_EQ(f[f.size() - 1], c.hi);
    EXPECT_TRUE(crc16_frame_ok(f));
  }
}

TEST(Crc16, FrameCheckRejectsCorruption) {
  std::vector<uint8_t> f = {0xA0, 0x02, 0x15, 0x0B, 0xCC, 0xB3};
  EXPECT_TRUE(crc16_frame_ok(f));
  f[2] ^= 0x01;
  EXPECT_FALSE(crc16_frame_ok(f));
  const std::vector<uint8_t> swapped = {0xA0, 0x02, 0x15, 0x0B, 0xB3, 0xCC};  // high byte first
  EXPECT_FALSE(crc16_frame_ok(swapped));
  const std::vector<uint8_t> too_short = {0xFF, 0xFF};
  EXPECT_FALSE(crc16_frame_ok(too_short));
}

}  // namespace
}  // namespace isolink
