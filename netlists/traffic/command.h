// Daisy-chain command frames (docs/physics.md section 7) from readable text.
//
// Usage:
//   StatusOr<std::vector<uint8_t>> b = command_bytes("stack-write reg=0x0100 data=02B778BC");
//   if (!b) return b.status();          // message names the field, its value and the rule
//   // *b == B3 01 00 02 B7 78 BC 0A 35
//   StatusOr<Command> c = parse_command("single-read dev=0 reg=0x0215 n=12");
//   std::vector<uint8_t> bytes = encode_command(*c);   // 80 00 02 15 0B CB 49
// Text: a keyword, then key=value fields in any order, separated by spaces:
//   single-read dev=D reg=R n=N        single-write dev=D reg=R data=HEX
//   stack-read reg=R n=N               stack-write reg=R data=HEX
//   broadcast-read reg=R n=N           broadcast-write reg=R data=HEX
//   broadcast-write-reverse reg=R data=HEX
//   raw HEX... [nocrc]                 (bytes as given, CRC appended unless nocrc)
// Numbers (dev, reg, n) are decimal or 0x-prefixed hex; HEX is an even count of hex digits,
// optionally 0x-prefixed. Rules: dev 0-63, reg 0x0000-0xFFFF, n 1-128, data 1-8 bytes.
// Keywords are case-insensitive.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"
#include "protocol/command_frames.h"

namespace isolink::traffic {

// The kinds and their init bytes are protocol/command_frames.h's (shared with the parser).
using isolink::command_keyword;
using isolink::CommandKind;
using isolink::has_device;
using isolink::init_byte_base;
using isolink::is_read;
using isolink::is_write;

struct Command {
  CommandKind kind = CommandKind::kRaw;
  int device = 0;             // single-device commands only, 0-63
  uint16_t reg = 0;           // register address, sent high byte first
  int read_bytes = 1;         // reads: bytes wanted, 1-128 (sent as n - 1)
  std::vector<uint8_t> data;  // writes: 1-8 bytes; raw: the bytes as given
  bool crc = true;            // raw only: append the CRC
};

// Parses and range-checks one command text.
StatusOr<Command> parse_command(std::string_view text);
// Checks a Command built in code against the same rules parse_command applies.
Status validate_command(const Command& c);
// Frame bytes including CRC (low byte first); c must be valid (see validate_command).
std::vector<uint8_t> encode_command(const Command& c);
// parse_command + encode_command.
StatusOr<std::vector<uint8_t>> command_bytes(std::string_view text);

// The whitespace-separated words of text (views into it).
std::vector<std::string_view> split_ws(std::string_view text);

// Parses one token of hex digits (optional 0x prefix, an even count) into bytes; field names the
// value in errors. (Bytes print with to_hex, base/hex.h.)
StatusOr<std::vector<uint8_t>> parse_hex_bytes(std::string_view text, std::string_view field);

}  // namespace isolink::traffic
