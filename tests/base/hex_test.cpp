// The one hex formatter and parser for byte strings (base/hex.h).
#include "base/hex.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace isolink {
namespace {

TEST(Hex, ParseAndFormatByteStrings) {
  auto a = parse_hex_bytes("80 00 02 15 0B CB 49");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(*a, (std::vector<uint8_t>{0x80, 0x00, 0x02, 0x15, 0x0B, 0xCB, 0x49}));
  auto b = parse_hex_bytes("0x93,0x00 cb49");
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(*b, (std::vector<uint8_t>{0x93, 0x00, 0xCB, 0x49}));
  EXPECT_EQ(to_hex(*a), "80 00 02 15 0B CB 49");
  auto bad = parse_hex_bytes("80 0G");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("'0G'"), std::string::npos);
  EXPECT_FALSE(parse_hex_bytes("  ").ok());
  EXPECT_FALSE(parse_hex_bytes("123").ok());
}

TEST(Hex, FormatterSeparatorsAndDigits) {
  const std::vector<uint8_t> b = {0x00, 0x0A, 0xF0, 0xFF};
  EXPECT_EQ(to_hex(b), "00 0A F0 FF");
  EXPECT_EQ(to_hex(b, ""), "000AF0FF");
  EXPECT_EQ(to_hex(std::vector<uint8_t>{}), "");
  EXPECT_EQ(hex_digit('0'), 0);
  EXPECT_EQ(hex_digit('9'), 9);
  EXPECT_EQ(hex_digit('a'), 10);
  EXPECT_EQ(hex_digit('F'), 15);
  EXPECT_EQ(hex_digit('g'), -1);
  EXPECT_EQ(hex_digit('x'), -1);
  // Every byte round-trips through the formatter and the parser.
  std::vector<uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[i] = static_cast<uint8_t>(i);
  auto back = parse_hex_bytes(to_hex(all));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(*back, all);
}

}  // namespace
}  // namespace isolink
