// TI's start-up and read traffic as stimulus items (netlists/traffic/sequences.h): the
// auto-addressing commands in the order and with the registers of TI's BQ79616-Q1 sample code,
// and response frames whose bytes and CRC are checked against values computed by hand (CRC-16
// with polynomial 0xA001 reflected, init 0xFFFF, as the data sheet's CRC; the stack-write example
// of command.h, B3 01 00 02 B7 78 BC -> 0A 35, computed the same way, checks that computation).
#include "netlists/traffic/sequences.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "netlists/traffic/command.h"
#include "netlists/traffic/stimulus.h"

namespace isolink::traffic {
namespace {

TEST(Sequences, AutoAddressFollowsTisSampleCode) {
  StatusOr<std::vector<std::string>> c = auto_address_commands(3);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_EQ(c->size(), 22u);  // 8 dummy writes, CONTROL1, 3 addresses, COMM_CTRL x2, 8 reads
  EXPECT_EQ((*c)[0], "stack-write reg=0x0343 data=00");
  EXPECT_EQ((*c)[7], "stack-write reg=0x034A data=00");
  EXPECT_EQ((*c)[8], "broadcast-write reg=0x0309 data=01");
  EXPECT_EQ((*c)[9], "broadcast-write reg=0x0306 data=00");
  EXPECT_EQ((*c)[11], "broadcast-write reg=0x0306 data=02");
  EXPECT_EQ((*c)[12], "broadcast-write reg=0x0308 data=02");
  EXPECT_EQ((*c)[13], "single-write dev=2 reg=0x0308 data=03");
  EXPECT_EQ((*c)[14], "stack-read reg=0x0343 n=1");
  EXPECT_EQ((*c)[21], "stack-read reg=0x034A n=1");
  // The broadcast write of CONTROL1 on the wire: D0 03 09 01, CRC 0x740F low byte first.
  StatusOr<std::vector<uint8_t>> b = command_bytes((*c)[8]);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(*b, (std::vector<uint8_t>{0xD0, 0x03, 0x09, 0x01, 0x0F, 0x74}));
  EXPECT_FALSE(auto_address_commands(1).ok());
  EXPECT_FALSE(auto_address_commands(65).ok());
}

TEST(Sequences, ResponseFrameBytesAndCrc) {
  StatusOr<std::vector<uint8_t>> f = response_frame(3, 0x0568, {0x12, 0x34});
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(*f, (std::vector<uint8_t>{0x01, 0x03, 0x05, 0x68, 0x12, 0x34, 0xC9, 0xAD}));
  EXPECT_FALSE(response_frame(64, 0x0568, {0x00}).ok());
  EXPECT_FALSE(response_frame(1, 0x0568, {}).ok());
}

TEST(Sequences, StackReadOfSixteenDevicesAsStimulus) {
  // The host's start-up of a 16-device stack, then the cell-voltage read, down the first hop.
  StatusOr<Drive> down = build_drive("wake; auto-address devices=16; stack-read reg=0x0568 n=32");
  ASSERT_TRUE(down.ok()) << down.status().message();
  // The wake tone, the 35 commands of auto-addressing 16 devices, the read.
  EXPECT_EQ(down->frames.size(), 1u + 8 + 1 + 16 + 2 + 8 + 1);
  // Their answer up the first hop: 15 stack devices x (32 data bytes + 6).
  StatusOr<Drive> up = build_drive("responses reg=0x0568 n=32 devices=15");
  ASSERT_TRUE(up.ok()) << up.status().message();
  ASSERT_EQ(up->frames.size(), 15u);
  for (size_t k = 0; k < up->frames.size(); ++k) {
    ASSERT_EQ(up->frames[k].bytes.size(), 38u);
    EXPECT_EQ(up->frames[k].bytes[0], 31);                           // 32 data bytes
    EXPECT_EQ(up->frames[k].bytes[1], static_cast<uint8_t>(k + 1));  // addresses 1..15
  }
}

TEST(Sequences, BadFieldsNameTheFieldAndTheRule) {
  auto msg = [](const char* script) {
    StatusOr<Drive> d = build_drive(script);
    return d.ok() ? std::string() : d.status().message();
  };
  EXPECT_NE(msg("responses reg=0x0568 n=0 devices=2").find("n=0 must be 1-128"), std::string::npos);
  EXPECT_NE(msg("responses reg=0x0568 n=4 devices=70").find("devices=70"), std::string::npos);
  EXPECT_NE(msg("responses reg=0x0568 n=4").find("expected reg=R n=B devices=D"),
            std::string::npos);
  EXPECT_NE(msg("responses reg=0x0568 n=4 devices=2 colour=1").find("unknown field 'colour'"),
            std::string::npos);
  EXPECT_NE(msg("auto-address devices=1").find("devices=1 must be 2-64"), std::string::npos);
  EXPECT_NE(msg("auto-address devices=x").find("not an integer"), std::string::npos);
  EXPECT_NE(msg("auto-address").find("expected devices=N"), std::string::npos);
}

}  // namespace
}  // namespace isolink::traffic
