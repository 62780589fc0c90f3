// TI's daisy-chain frames above the byte layer, both ways: the command kinds and their init
// bytes (which traffic/ encodes) and the parser that turns decoded bytes, with their times, back
// into command and response frames (which eye/ reports and `compare` uses).
//
// Usage:
//   std::vector<TimedByte> in = {{0.0, 6.5e-6, 0xB3}, {10.3e-6, 16.8e-6, 0x01}, ...};
//   std::vector<ParsedFrame> f = parse_frames(in);   // f[0].kind_name() == "stack-write"
//   f[0].crc_ok;  f[0].text;                         // true, "stack write 0x0100 = 02 B7 78 BC,
//                                                    //  CRC 0A35 ok"
// Frame formats (TI BQ7961x / BQ79600 / BQ79606A):
//   command:  init, [device (single-device commands only)], register high, register low,
//             data (reads: one byte, bytes wanted - 1; writes: 1-8 bytes), CRC low, CRC high.
//   init:     bit 7 frame type (1 = command), bits 6-4 request type (0 single read, 1 single
//             write, 2 stack read, 3 stack write, 4 broadcast read, 5 broadcast write, 6 broadcast
//             write reverse; 7 is none), bit 3 reserved (0), bits 2-0 data bytes - 1 (0 for reads).
//   response: init (bit 7 = 0, bits 6-0 data bytes - 1: 1-128 bytes), device, register high,
//             register low, data, CRC low, CRC high.
// The frame type bit alone tells a response from a command: a record probed on a cable that
// carries both (commands going up, responses coming down) is parsed without knowing the
// direction.
//
// How a stream of bytes splits into frames (the rule parse_frames applies):
//   1. Bursts: consecutive bytes belong to one burst while the idle between them (the next
//      byte's start minus this one's end) is at most max_idle_s (default 8 us: the encoder's idle
//      between the bytes of one command is 3.8 us, a byte every 10.3 us as the bridge forwards
//      at 1 Mbps, and between commands 12 us). A longer idle always ends a frame.
//   2. Within a burst, the init byte's length field gives the frame's length; the byte after a
//      complete frame starts the next frame.
//   3. A burst that ends before its frame is complete: "truncated" (the idle or the record's end
//      cut it), unless the bytes it holds end in a valid CRC of their own: then the host sent a
//      different count of bytes than its init byte says ("length"). Likewise a frame whose CRC
//      fails at the announced length, in a burst whose remaining bytes (134 at most, the longest
//      frame) end in a valid CRC, is one frame of the burst's length with the flag "length".
//   4. A byte that did not decode (TimedByte::value empty) makes the frame it falls in, and the
//      rest of its burst, one frame flagged "undecoded": where the next frame starts is unknown.
//   5. An init byte 0xF0-0xFF (request type 7) has no length: the rest of the burst is one frame
//      flagged "unknown_init".
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace isolink {

// The request types of TI's command frames, plus kRaw: bytes sent as given (the stimulus's
// escape hatch, `raw 80 00 02`; parse_frames never returns it).
enum class CommandKind {
  kSingleRead,
  kSingleWrite,
  kStackRead,
  kStackWrite,
  kBroadcastRead,
  kBroadcastWrite,
  kBroadcastWriteReverse,
  kRaw,
};

// Init byte base for the kind: 0x80 single read ... 0xE0 broadcast write reverse; 0 for raw.
uint8_t init_byte_base(CommandKind kind);
// The text keyword of the kind, e.g. "stack-write" (the stimulus's command syntax).
std::string_view command_keyword(CommandKind kind);
// The kind of a keyword (exact, lower case), or nullopt.
std::optional<CommandKind> command_kind_of(std::string_view keyword);
// The kind a command's init byte names: nullopt for a response (bit 7 = 0) or 0xF0-0xFF.
std::optional<CommandKind> command_kind_of_init(uint8_t init);
bool is_read(CommandKind kind);
bool is_write(CommandKind kind);
bool has_device(CommandKind kind);

// One byte as the decoder delivered it, with its time on the wire.
struct TimedByte {
  double start_s = 0;            // its frame's preamble (s)
  double end_s = 0;              // the end of its last pulse (s)
  std::optional<uint8_t> value;  // empty: a byte frame that did not decode
};

struct FrameSplitOptions {
  double max_idle_s = 8e-6;  // a longer idle between two bytes ends a frame (rule 1)
  // The record's span (s), when known (NaN: unknown): a frame within max_idle_s of its start or
  // end may have been cut by the record rather than by its sender (ParsedFrame::cut_by_record,
  // at_record_start).
  double record_begin_s = std::numeric_limits<double>::quiet_NaN();
  double record_end_s = std::numeric_limits<double>::quiet_NaN();
};

// What is wrong with a frame; an empty list is a well-formed frame with a valid CRC.
enum class FrameFlag {
  kBadCrc,       // "bad_crc": the CRC does not match the bytes before it
  kTruncated,    // "truncated": fewer bytes than the init byte announces, no valid CRC
  kLength,       // "length": a valid CRC at a byte count the init byte does not announce
  kUndecoded,    // "undecoded": a byte of it did not decode
  kUnknownInit,  // "unknown_init": init byte 0xF0-0xFF, no request type
  kReserved,     // "reserved": a reserved bit set (init bit 3; a read's data-size bits)
  kRange,        // "range": a device address over 63, a read of more than 128 bytes
};
std::string_view flag_name(FrameFlag f);

struct ParsedFrame {
  double start_s = 0, end_s = 0;       // its first byte's start, its last byte's end
  size_t first_byte = 0;               // index of its first byte in parse_frames' input
  bool response = false;               // frame type bit 0
  std::optional<CommandKind> command;  // the request type (commands with a known init byte)
  std::optional<int> device;           // single-device commands and responses
  std::optional<uint16_t> reg;         // when its bytes reach it
  std::vector<uint8_t> data;           // write or response data; a read's count byte
  std::optional<int> read_bytes;       // reads: bytes wanted (count byte + 1)
  std::vector<uint8_t> bytes;          // its bytes as received, up to the first that did not decode
  size_t byte_count = 0;               // bytes of the input it spans (decoded or not)
  size_t expected_length = 0;          // what the init byte announces (0: unknown)
  std::optional<uint16_t> crc;         // the received CRC (low byte first on the wire)
  std::optional<uint16_t> crc_expected;  // the CRC of the bytes before it
  bool crc_ok = false;
  std::vector<FrameFlag> flags;
  bool cut_by_record = false;  // truncated within max_idle_s of the record's end: not the sender's
  bool at_record_start = false;  // starts within max_idle_s of the record's start: its first
                                 // bytes may precede the record
  std::string text;              // one line: "stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok"

  bool ok() const { return flags.empty(); }
  // "single-read" ... "broadcast-write-reverse" (command_keyword), "response" or "unknown".
  std::string_view kind_name() const;
};

// Splits bytes (in time order) into frames by the rule above and parses each; every input byte
// lands in exactly one frame, in order. Times are only compared: a NaN idle ends a burst.
std::vector<ParsedFrame> parse_frames(std::span<const TimedByte> bytes,
                                      const FrameSplitOptions& opt = {});

// The CRC as its bytes appear on the wire, low byte first: 0x350A -> "0A35".
std::string crc_wire_hex(uint16_t crc);

}  // namespace isolink
