#include "netlists/traffic/command.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "base/hex.h"
#include "protocol/command_frames.h"

namespace isolink::traffic {
namespace {

std::string hex_of(const std::string& text) {
  StatusOr<std::vector<uint8_t>> b = command_bytes(text);
  if (!b) return "ERROR: " + b.status().message();
  return to_hex(*b);
}

std::string error_of(const std::string& text) {
  StatusOr<std::vector<uint8_t>> b = command_bytes(text);
  return b ? std::string("(no error)") : b.status().message();
}

TEST(Command, WorkedExamplesByteExact) {
  EXPECT_EQ(hex_of("single-read dev=0 reg=0x0215 n=12"), "80 00 02 15 0B CB 49");
  EXPECT_EQ(hex_of("single-write dev=0 reg=0x0100 data=02B778BC"), "93 00 01 00 02 B7 78 BC 9A 8C");
  EXPECT_EQ(hex_of("stack-read reg=0x0215 n=12"), "A0 02 15 0B CC B3");
  EXPECT_EQ(hex_of("stack-write reg=0x0100 data=02B778BC"), "B3 01 00 02 B7 78 BC 0A 35");
}

TEST(Command, FieldOrderCaseAndNumberBasesDoNotMatter) {
  EXPECT_EQ(hex_of("SINGLE-READ n=0x0C reg=533 dev=0"), "80 00 02 15 0B CB 49");
  EXPECT_EQ(hex_of("  stack-write   data=0x02b778bc reg=256 "), "B3 01 00 02 B7 78 BC 0A 35");
}

TEST(Command, InitByteRules) {
  auto first = [](const std::string& text) -> int {
    StatusOr<std::vector<uint8_t>> b = command_bytes(text);
    return b ? (*b)[0] : -1;
  };
  EXPECT_EQ(first("single-read dev=1 reg=0 n=1"), 0x80);
  EXPECT_EQ(first("single-write dev=1 reg=0 data=AA"), 0x90);                // 1 byte: +0
  EXPECT_EQ(first("single-write dev=1 reg=0 data=0102030405060708"), 0x97);  // 8 bytes: +7
  EXPECT_EQ(first("stack-read reg=0 n=128"), 0xA0);
  EXPECT_EQ(first("stack-write reg=0 data=0102"), 0xB1);
  EXPECT_EQ(first("broadcast-read reg=0 n=5"), 0xC0);
  EXPECT_EQ(first("broadcast-write reg=0 data=010203"), 0xD2);
  EXPECT_EQ(first("broadcast-write-reverse reg=0 data=0102"), 0xE1);
}

TEST(Command, LayoutOfEachKind) {
  // read: data byte n - 1; single: device byte after init; register high byte first.
  Command c;
  c.kind = CommandKind::kSingleRead;
  c.device = 63;
  c.reg = 0xABCD;
  c.read_bytes = 128;
  std::vector<uint8_t> b = encode_command(c);
  ASSERT_EQ(b.size(), 7u);
  EXPECT_EQ(b[0], 0x80);
  EXPECT_EQ(b[1], 63);
  EXPECT_EQ(b[2], 0xAB);
  EXPECT_EQ(b[3], 0xCD);
  EXPECT_EQ(b[4], 0x7F);
  StatusOr<std::vector<uint8_t>> br = command_bytes("broadcast-read reg=0x0001 n=1");
  ASSERT_TRUE(br.ok());
  ASSERT_EQ(br->size(), 6u);  // init, reg hi, reg lo, n-1, crc lo, crc hi
  EXPECT_EQ((*br)[3], 0x00);
  StatusOr<std::vector<uint8_t>> bw = command_bytes("broadcast-write-reverse reg=0x0309 data=42");
  ASSERT_TRUE(bw.ok());
  ASSERT_EQ(bw->size(), 6u);  // E0 03 09 42 + crc
  EXPECT_EQ((*bw)[0], 0xE0);
  EXPECT_EQ((*bw)[1], 0x03);
  EXPECT_EQ((*bw)[2], 0x09);
  EXPECT_EQ((*bw)[3], 0x42);
}

TEST(Command, RawBytesGetCrcUnlessNocrc) {
  EXPECT_EQ(hex_of("raw 80 00 02 15 0B"), "80 00 02 15 0B CB 49");
  EXPECT_EQ(hex_of("raw 800002150B"), "80 00 02 15 0B CB 49");
  EXPECT_EQ(hex_of("raw 80 00 02 15 0B nocrc"), "80 00 02 15 0B");
  EXPECT_EQ(hex_of("raw NOCRC 0xFF"), "FF");
}

TEST(Command, OutOfRangeFieldsNameFieldValueAndRule) {
  std::string e = error_of("single-read dev=64 reg=0x0215 n=12");
  EXPECT_NE(e.find("dev=64"), std::string::npos) << e;
  EXPECT_NE(e.find("0-63"), std::string::npos) << e;

  e = error_of("stack-read reg=0x0215 n=0");
  EXPECT_NE(e.find("n=0"), std::string::npos) << e;
  EXPECT_NE(e.find("1-128"), std::string::npos) << e;
  e = error_of("stack-read reg=0x0215 n=129");
  EXPECT_NE(e.find("n=129"), std::string::npos) << e;
  EXPECT_NE(e.find("1-128"), std::string::npos) << e;

  e = error_of("stack-write reg=0x10000 data=01");
  EXPECT_NE(e.find("reg=0x10000"), std::string::npos) << e;
  EXPECT_NE(e.find("16 bits"), std::string::npos) << e;

  e = error_of("stack-write reg=0x0100 data=010203040506070809");
  EXPECT_NE(e.find("data=010203040506070809"), std::string::npos) << e;
  EXPECT_NE(e.find("9 bytes"), std::string::npos) << e;
  EXPECT_NE(e.find("1-8"), std::string::npos) << e;

  e = error_of("stack-write reg=0x0100 data=2B7");
  EXPECT_NE(e.find("data=2B7"), std::string::npos) << e;
  EXPECT_NE(e.find("odd number of hex digits"), std::string::npos) << e;

  e = error_of("stack-write reg=0x0100 data=0G");
  EXPECT_NE(e.find("'G' is not a hex digit"), std::string::npos) << e;

  e = error_of("raw 80 0");
  EXPECT_NE(e.find("odd number of hex digits"), std::string::npos) << e;
}

TEST(Command, MalformedCommandsAreNamed) {
  std::string e = error_of("stack-wrte reg=0x0100 data=01");
  EXPECT_NE(e.find("unknown command 'stack-wrte'"), std::string::npos) << e;
  e = error_of("stack-write dev=1 reg=0x0100 data=01");  // stack commands carry no device
  EXPECT_NE(e.find("unknown field 'dev'"), std::string::npos) << e;
  e = error_of("single-read dev=1 reg=0x0100");
  EXPECT_NE(e.find("missing field 'n='"), std::string::npos) << e;
  e = error_of("stack-read reg=1 reg=2 n=1");
  EXPECT_NE(e.find("'reg' given twice"), std::string::npos) << e;
  e = error_of("stack-read reg=1 n=twelve");
  EXPECT_NE(e.find("n=twelve is not a number"), std::string::npos) << e;
  e = error_of("stack-read reg=1 12");
  EXPECT_NE(e.find("'12' is not a key=value field"), std::string::npos) << e;
  EXPECT_NE(error_of("raw nocrc").find("no bytes"), std::string::npos);
  EXPECT_NE(error_of("   ").find("empty command"), std::string::npos);
}

TEST(Command, ValidateCatchesCodeBuiltCommands) {
  Command c;
  c.kind = CommandKind::kStackWrite;
  EXPECT_FALSE(validate_command(c).ok());  // no data
  c.data = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_TRUE(validate_command(c).ok());
  c.kind = CommandKind::kSingleRead;
  c.device = -1;
  EXPECT_FALSE(validate_command(c).ok());
}

// Round trip: what the encoder (`isolink frame`) builds, the parser (protocol/command_frames.h,
// which `isolink check` runs on decoded bytes) reads back field for field, for every kind, every
// write length (1-8 bytes) and read counts 1..128; the frames are sent back to back as one burst
// of bytes 10.3 us apart, so the init bytes' length fields alone split them.
TEST(Command, EncodeThenParseGivesTheSameFields) {
  const CommandKind kinds[] = {
      CommandKind::kSingleRead,           CommandKind::kSingleWrite,   CommandKind::kStackRead,
      CommandKind::kStackWrite,           CommandKind::kBroadcastRead, CommandKind::kBroadcastWrite,
      CommandKind::kBroadcastWriteReverse};
  std::vector<Command> sent;
  for (CommandKind k : kinds) {
    for (int len = 1; len <= 8; ++len) {
      Command c;
      c.kind = k;
      c.device = has_device(k) ? 7 * len : 0;  // 7..56
      c.reg = static_cast<uint16_t>(0x1234 * len + 0x0100 * static_cast<int>(k));
      c.read_bytes = 1 + (len - 1) * 127 / 7;  // 1 .. 128
      for (int i = 0; i < len; ++i) c.data.push_back(static_cast<uint8_t>(0x11 * i + len));
      if (is_read(k)) c.data.clear();
      ASSERT_TRUE(validate_command(c).ok());
      sent.push_back(c);
    }
  }
  std::vector<TimedByte> wire;
  double t = 0;
  for (const Command& c : sent)
    for (uint8_t b : encode_command(c)) {
      wire.push_back({t, t + 6.5e-6, b});
      t += 10.3e-6;
    }
  const std::vector<ParsedFrame> got = parse_frames(wire);
  ASSERT_EQ(got.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) {
    const Command& c = sent[i];
    const ParsedFrame& f = got[i];
    SCOPED_TRACE(f.text);
    EXPECT_TRUE(f.ok());
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.command, c.kind);
    EXPECT_EQ(f.kind_name(), command_keyword(c.kind));
    EXPECT_EQ(f.device, has_device(c.kind) ? std::optional<int>(c.device) : std::nullopt);
    EXPECT_EQ(f.reg, c.reg);
    EXPECT_EQ(f.bytes, encode_command(c));
    if (is_read(c.kind)) {
      EXPECT_EQ(f.read_bytes, c.read_bytes);
    } else {
      EXPECT_EQ(f.data, c.data);
    }
  }
}

}  // namespace
}  // namespace isolink::traffic
