// The traffic of TI's daisy-chain start-up and reads, as stimulus items (stimulus.h):
//
//   auto-address devices=N             what the host sends to address a stack of N devices
//   responses reg=R n=B devices=D [first=A]
//                                      the response frames D devices send back to a read
//
//   StatusOr<std::vector<std::string>> cmds = auto_address_commands(16);   // 35 command texts
//   StatusOr<std::vector<uint8_t>> f = response_frame(3, 0x0568, data);     // 01 03 05 68 .. CRC
//
// Auto-addressing, as TI's BQ79616-Q1 sample code does it (bq79616.c, AutoAddress(); register
// addresses from its header, the BQ79616-Q1 register map), devices = every device addressed,
// the base (or the BQ79600 bridge) being address 0:
//   1. eight stack writes of 0x00 to OTP_ECC_DATAIN1..8 (0x0343-0x034A): dummy writes that
//      synchronise the devices' DLLs;
//   2. broadcast write CONTROL1 (0x0309) = 0x01: auto-addressing mode (ADDR_WR);
//   3. broadcast writes DIR0_ADDR (0x0306) = 0, 1, ..., N-1: each device takes the next address;
//   4. broadcast write COMM_CTRL (0x0308) = 0x02: every device a stack device;
//   5. single write to device N-1 COMM_CTRL = 0x03: the top of the stack;
//   6. eight stack reads of one byte of OTP_ECC_DATAIN1..8: throw-away reads (DLL sync).
// A response frame (BQ79616-Q1 data sheet, response frame format): init byte (bit 7 = 0,
// bits 6-0 = data bytes - 1), device address, register address (high, low), the data, CRC-16
// (low byte first), as protocol/command_frames.h parses it.
// The data of `responses` is the PRBS-7 sequence (patterns.h), n bytes, the same for every
// device: what travels is the frame structure and its length; the worst case over all traffic
// (isolink worst) covers every data content.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink::traffic {

// Register addresses of the BQ79616-Q1 register map that the sequences use.
inline constexpr uint16_t kRegDir0Addr = 0x0306;
inline constexpr uint16_t kRegCommCtrl = 0x0308;
inline constexpr uint16_t kRegControl1 = 0x0309;
inline constexpr uint16_t kRegOtpEccDataIn1 = 0x0343;  // ..8: 0x034A
inline constexpr uint16_t kRegVcell16Hi = 0x0568;      // 32 bytes: cells 16 .. 1, high byte first
inline constexpr int kMaxStackDevices = 64;            // addresses 0-63

// The command texts (command.h syntax) of auto-addressing N devices (2-64), in order.
StatusOr<std::vector<std::string>> auto_address_commands(int devices);
// The same from the item's fields after `auto-address` (["devices=16"]); errors name the field.
StatusOr<std::vector<std::string>> auto_address_item(const std::vector<std::string_view>& fields);
// One response frame: device 0-63, 1-128 data bytes, CRC appended.
StatusOr<std::vector<uint8_t>> response_frame(int device, uint16_t reg,
                                              const std::vector<uint8_t>& data);
// The frames of `responses reg=R n=B devices=D [first=A]` (fields as in the item), in order of
// address; errors name the field, its value and the rule.
StatusOr<std::vector<std::vector<uint8_t>>> response_frames(
    const std::vector<std::string_view>& fields);

}  // namespace isolink::traffic
