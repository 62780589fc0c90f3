#include "protocol/command_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "base/hex.h"
#include "protocol/crc16.h"

namespace isolink {
namespace {

constexpr double kByte = 6.5e-6;     // a byte frame on the wire: 26 half bits of 250 ns
constexpr double kPeriod = 10.3e-6;  // a byte every 10.3 us (3.8 us idle), as the encoder sends

// Bytes sent back to back from t0, a byte every kPeriod.
std::vector<TimedByte> timed(const std::vector<uint8_t>& bytes, double t0 = 1e-6) {
  std::vector<TimedByte> out;
  for (uint8_t b : bytes) {
    out.push_back({t0, t0 + kByte, b});
    t0 += kPeriod;
  }
  return out;
}

// Appends bytes starting idle seconds after the last one ends.
void append_after(std::vector<TimedByte>& to, const std::vector<uint8_t>& bytes, double idle) {
  for (TimedByte b : timed(bytes, to.back().end_s + idle)) to.push_back(b);
}

std::vector<uint8_t> with_crc(std::vector<uint8_t> payload) {
  append_crc16(payload);
  return payload;
}

ParsedFrame only_frame(const std::vector<uint8_t>& bytes) {
  const std::vector<TimedByte> in = timed(bytes);
  std::vector<ParsedFrame> f = parse_frames(in);
  EXPECT_EQ(f.size(), 1u) << to_hex(bytes);
  return f.empty() ? ParsedFrame{} : f[0];
}

// TI's four worked examples, bytes as sent (CRC low byte first).
const std::vector<uint8_t> kSingleRead = {0x80, 0x00, 0x02, 0x15, 0x0B, 0xCB, 0x49};
const std::vector<uint8_t> kSingleWrite = {0x93, 0x00, 0x01, 0x00, 0x02,
                                           0xB7, 0x78, 0xBC, 0x9A, 0x8C};
const std::vector<uint8_t> kStackRead = {0xA0, 0x02, 0x15, 0x0B, 0xCC, 0xB3};
const std::vector<uint8_t> kStackWrite = {0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC, 0x0A, 0x35};

TEST(CommandFrames, TiWorkedExampleSingleRead) {
  const ParsedFrame f = only_frame(kSingleRead);
  EXPECT_EQ(f.kind_name(), "single-read");
  EXPECT_FALSE(f.response);
  EXPECT_EQ(f.device, 0);
  EXPECT_EQ(f.reg, 0x0215);
  EXPECT_EQ(f.read_bytes, 12);
  EXPECT_EQ(f.data, std::vector<uint8_t>{0x0B});
  EXPECT_EQ(f.crc, 0x49CB);
  EXPECT_TRUE(f.crc_ok);
  EXPECT_TRUE(f.ok());
  EXPECT_EQ(f.expected_length, 7u);
  EXPECT_NEAR(f.start_s, 1e-6, 1e-15);
  EXPECT_NEAR(f.end_s, 1e-6 + 6 * kPeriod + kByte, 1e-15);
  EXPECT_EQ(f.text, "single read dev 0 0x0215, 12 bytes, CRC CB49 ok");
}

TEST(CommandFrames, TiWorkedExampleSingleWrite) {
  const ParsedFrame f = only_frame(kSingleWrite);
  EXPECT_EQ(f.kind_name(), "single-write");
  EXPECT_EQ(f.device, 0);
  EXPECT_EQ(f.reg, 0x0100);
  EXPECT_EQ(f.data, (std::vector<uint8_t>{0x02, 0xB7, 0x78, 0xBC}));
  EXPECT_FALSE(f.read_bytes);
  EXPECT_TRUE(f.crc_ok);
  EXPECT_EQ(f.text, "single write dev 0 0x0100 = 02 B7 78 BC, CRC 9A8C ok");
}

TEST(CommandFrames, TiWorkedExampleStackRead) {
  const ParsedFrame f = only_frame(kStackRead);
  EXPECT_EQ(f.kind_name(), "stack-read");
  EXPECT_FALSE(f.device);
  EXPECT_EQ(f.reg, 0x0215);
  EXPECT_EQ(f.read_bytes, 12);
  EXPECT_TRUE(f.crc_ok);
  EXPECT_EQ(f.text, "stack read 0x0215, 12 bytes, CRC CCB3 ok");
}

TEST(CommandFrames, TiWorkedExampleStackWrite) {
  const ParsedFrame f = only_frame(kStackWrite);
  EXPECT_EQ(f.kind_name(), "stack-write");
  EXPECT_FALSE(f.device);
  EXPECT_EQ(f.reg, 0x0100);
  EXPECT_EQ(f.data, (std::vector<uint8_t>{0x02, 0xB7, 0x78, 0xBC}));
  EXPECT_EQ(f.crc, 0x350A);
  EXPECT_EQ(f.crc_expected, 0x350A);
  EXPECT_EQ(f.text, "stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok");
}

TEST(CommandFrames, FramesInOneBurstSplitByTheInitBytesLength) {
  std::vector<uint8_t> all;
  for (const auto* v : {&kSingleRead, &kSingleWrite, &kStackRead, &kStackWrite})
    all.insert(all.end(), v->begin(), v->end());
  const std::vector<TimedByte> in = timed(all);  // no gap anywhere: the length alone splits
  const std::vector<ParsedFrame> f = parse_frames(in);
  ASSERT_EQ(f.size(), 4u);
  const size_t first[] = {0, 7, 17, 23};
  const char* kinds[] = {"single-read", "single-write", "stack-read", "stack-write"};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(f[i].first_byte, first[i]);
    EXPECT_EQ(f[i].kind_name(), kinds[i]);
    EXPECT_TRUE(f[i].ok()) << f[i].text;
  }
  EXPECT_NEAR(f[1].start_s, 1e-6 + 7 * kPeriod, 1e-15);
}

TEST(CommandFrames, BadCrcIsFlaggedWithTheExpectedOne) {
  // The CRC sent high byte first (35 0A instead of 0A 35): a host-side byte-order bug.
  std::vector<uint8_t> b = kStackWrite;
  std::swap(b[7], b[8]);
  ParsedFrame f = only_frame(b);
  EXPECT_FALSE(f.crc_ok);
  ASSERT_EQ(f.flags.size(), 1u);
  EXPECT_EQ(f.flags[0], FrameFlag::kBadCrc);
  EXPECT_EQ(flag_name(f.flags[0]), "bad_crc");
  EXPECT_EQ(f.text, "stack write 0x0100 = 02 B7 78 BC, CRC 350A bad (expected 0A35)");
  // A data byte changed in flight: the CRC sent no longer matches the bytes.
  b = kStackWrite;
  b[6] = 0x79;
  f = only_frame(b);
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kBadCrc});
  EXPECT_EQ(f.crc, 0x350A);
  EXPECT_EQ(f.crc_expected, crc16_ibm(std::span<const uint8_t>(b).first(7)));
  EXPECT_NE(f.crc_expected, 0x350A);
}

TEST(CommandFrames, AnIdleGapCutsATruncatedFrame) {
  std::vector<TimedByte> in = timed({0xB3, 0x01, 0x00, 0x02, 0xB7});
  append_after(in, kStackRead, 20e-6);
  const std::vector<ParsedFrame> f = parse_frames(in);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].flags, std::vector<FrameFlag>{FrameFlag::kTruncated});
  EXPECT_EQ(f[0].byte_count, 5u);
  EXPECT_EQ(f[0].expected_length, 9u);
  EXPECT_EQ(f[0].reg, 0x0100);
  EXPECT_EQ(f[0].data, (std::vector<uint8_t>{0x02, 0xB7}));
  EXPECT_FALSE(f[0].crc);
  EXPECT_FALSE(f[0].crc_ok);
  EXPECT_EQ(f[0].text,
            "stack write 0x0100 = 02 B7: truncated: 5 of 9 bytes before an idle gap of more "
            "than 8 us");
  EXPECT_EQ(f[1].first_byte, 5u);
  EXPECT_TRUE(f[1].ok());
}

TEST(CommandFrames, TheIdleThresholdDecidesWhereTheNextFrameStarts) {
  // 7.9 us of idle (under 8 us): still one burst, so the stack read's bytes complete the cut
  // write (whose CRC then fails) and the rest is a fragment. 8.1 us: the write is truncated and
  // the read parses.
  for (double idle : {7.9e-6, 8.1e-6}) {
    std::vector<TimedByte> in = timed({0xB3, 0x01, 0x00, 0x02, 0xB7});
    append_after(in, kStackRead, idle);
    const std::vector<ParsedFrame> f = parse_frames(in);
    ASSERT_EQ(f.size(), 2u) << idle;
    if (idle < 8e-6) {
      EXPECT_EQ(f[0].byte_count, 9u);
      EXPECT_EQ(f[0].flags, std::vector<FrameFlag>{FrameFlag::kBadCrc});
      EXPECT_FALSE(f[1].ok());
    } else {
      EXPECT_EQ(f[0].flags, std::vector<FrameFlag>{FrameFlag::kTruncated});
      EXPECT_TRUE(f[1].ok()) << f[1].text;
    }
  }
  // The threshold is an option.
  std::vector<TimedByte> in = timed({0xB3, 0x01, 0x00, 0x02, 0xB7});
  append_after(in, kStackRead, 7.9e-6);
  FrameSplitOptions opt;
  opt.max_idle_s = 5e-6;
  EXPECT_TRUE(parse_frames(in, opt).at(1).ok());
}

TEST(CommandFrames, TheRecordsEndCutsAFrame) {
  const std::vector<TimedByte> in = timed({0xB3, 0x01, 0x00, 0x02, 0xB7});
  FrameSplitOptions opt;
  opt.record_begin_s = 0;
  opt.record_end_s = in.back().end_s + 1e-6;
  const std::vector<ParsedFrame> f = parse_frames(in, opt);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(f[0].cut_by_record);
  EXPECT_TRUE(f[0].at_record_start);
  EXPECT_EQ(f[0].text,
            "stack write 0x0100 = 02 B7: truncated: 5 of 9 bytes before the record ends (it starts "
            "at the record's start: bytes before the record are not seen)");
  // Far from both ends: neither.
  opt.record_begin_s = -1;
  opt.record_end_s = 1;
  EXPECT_FALSE(parse_frames(in, opt).at(0).cut_by_record);
  EXPECT_FALSE(parse_frames(in, opt).at(0).at_record_start);
  // A complete frame near the end is not cut, whatever its CRC.
  std::vector<uint8_t> b = kStackWrite;
  b[8] ^= 1;
  const std::vector<TimedByte> whole = timed(b);
  opt.record_end_s = whole.back().end_s;
  EXPECT_FALSE(parse_frames(whole, opt).at(0).cut_by_record);
}

TEST(CommandFrames, AByteCountThatDisagreesWithTheInitByte) {
  // Init B3 announces 4 data bytes; the host sent 3 and a valid CRC over what it sent.
  ParsedFrame f = only_frame(with_crc({0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78}));
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kLength});
  EXPECT_TRUE(f.crc_ok);
  EXPECT_EQ(f.byte_count, 8u);
  EXPECT_EQ(f.expected_length, 9u);
  EXPECT_EQ(f.data, (std::vector<uint8_t>{0x02, 0xB7, 0x78}));
  EXPECT_NE(f.text.find("the init byte announces 9 bytes, the frame has 8 with a valid CRC"),
            std::string::npos)
      << f.text;
  // Init B2 announces 3 data bytes; the host sent 4: one frame of 9 bytes, not a bad CRC plus
  // a fragment.
  f = only_frame(with_crc({0xB2, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC}));
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kLength});
  EXPECT_EQ(f.byte_count, 9u);
  EXPECT_EQ(f.expected_length, 8u);
  EXPECT_EQ(f.data.size(), 4u);
}

TEST(CommandFrames, ResponsesByTheFrameTypeBit) {
  // A stack read of 2 bytes, then the answers of devices 2 and 1, back to back (init 0x01:
  // bit 7 clear = response, 2 data bytes).
  std::vector<TimedByte> in = timed(with_crc({0xA0, 0x02, 0x15, 0x01}));
  append_after(in, with_crc({0x01, 0x02, 0x02, 0x15, 0x12, 0x34}), 3.8e-6);
  for (TimedByte b :
       timed(with_crc({0x01, 0x01, 0x02, 0x15, 0xAB, 0xCD}), in.back().start_s + kPeriod))
    in.push_back(b);
  const std::vector<ParsedFrame> f = parse_frames(in);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].kind_name(), "stack-read");
  EXPECT_EQ(f[0].read_bytes, 2);
  for (size_t i = 1; i < 3; ++i) {
    EXPECT_TRUE(f[i].response);
    EXPECT_EQ(f[i].kind_name(), "response");
    EXPECT_EQ(f[i].expected_length, 8u);
    EXPECT_EQ(f[i].reg, 0x0215);
    EXPECT_TRUE(f[i].ok()) << f[i].text;
  }
  EXPECT_EQ(f[1].device, 2);
  EXPECT_EQ(f[1].data, (std::vector<uint8_t>{0x12, 0x34}));
  EXPECT_EQ(f[2].device, 1);
  EXPECT_EQ(f[2].text.rfind("response dev 1 0x0215 = AB CD, CRC ", 0), 0u) << f[2].text;
  // The longest response: init 0x7F, 128 data bytes, 134 bytes in all.
  std::vector<uint8_t> big = {0x7F, 0x00, 0x05, 0x00};
  for (int i = 0; i < 128; ++i) big.push_back(static_cast<uint8_t>(i));
  const ParsedFrame g = only_frame(with_crc(big));
  EXPECT_EQ(g.expected_length, 134u);
  EXPECT_EQ(g.data.size(), 128u);
  EXPECT_TRUE(g.ok());
  EXPECT_NE(g.text.find("... (128 bytes)"), std::string::npos) << g.text;
}

TEST(CommandFrames, AnUndecodedByteTakesTheRestOfItsBurst) {
  std::vector<TimedByte> in = timed(kStackWrite);
  in[3].value.reset();
  append_after(in, kStackRead, 20e-6);
  const std::vector<ParsedFrame> f = parse_frames(in);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].flags, std::vector<FrameFlag>{FrameFlag::kUndecoded});
  EXPECT_EQ(f[0].byte_count, 9u);
  EXPECT_EQ(f[0].bytes, (std::vector<uint8_t>{0xB3, 0x01, 0x00}));
  EXPECT_EQ(f[0].reg, 0x0100);
  EXPECT_TRUE(f[1].ok());
  // The first byte itself: nothing is known.
  in = timed(kStackRead);
  in[0].value.reset();
  const ParsedFrame g = parse_frames(in).at(0);
  EXPECT_EQ(g.kind_name(), "unknown");
  EXPECT_EQ(g.flags, std::vector<FrameFlag>{FrameFlag::kUndecoded});
  EXPECT_TRUE(g.bytes.empty());
}

TEST(CommandFrames, InitByteWithoutARequestType) {
  const ParsedFrame f = only_frame(with_crc({0xF0, 0x01, 0x02}));
  EXPECT_EQ(f.kind_name(), "unknown");
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kUnknownInit});
  EXPECT_TRUE(f.crc_ok);  // the burst's CRC is read at its end
  EXPECT_EQ(f.text.rfind("unknown: F0 01 02 ", 0), 0u) << f.text;
}

TEST(CommandFrames, ReservedBitsAndRanges) {
  // Bit 3 of the init byte set: still parsed by the length bits.
  ParsedFrame f = only_frame(with_crc({0xB8, 0x01, 0x00, 0xAA}));
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kReserved});
  EXPECT_EQ(f.data, std::vector<uint8_t>{0xAA});
  // A read whose data-size bits say 2 bytes: 7 bytes in all, the first data byte is the count.
  f = only_frame(with_crc({0xA1, 0x02, 0x15, 0x0B, 0x00}));
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kReserved});
  EXPECT_EQ(f.expected_length, 7u);
  EXPECT_EQ(f.read_bytes, 12);
  // Device 64 and a read of 129 bytes.
  f = only_frame(with_crc({0x80, 0x40, 0x02, 0x15, 0x0B}));
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kRange});
  EXPECT_NE(f.text.find("device address over 63"), std::string::npos) << f.text;
  f = only_frame(with_crc({0xA0, 0x02, 0x15, 0x80}));
  EXPECT_EQ(f.flags, std::vector<FrameFlag>{FrameFlag::kRange});
  EXPECT_EQ(f.read_bytes, 129);
}

TEST(CommandFrames, InitByteTable) {
  const CommandKind kinds[] = {
      CommandKind::kSingleRead,           CommandKind::kSingleWrite,   CommandKind::kStackRead,
      CommandKind::kStackWrite,           CommandKind::kBroadcastRead, CommandKind::kBroadcastWrite,
      CommandKind::kBroadcastWriteReverse};
  for (int t = 0; t < 7; ++t) {
    EXPECT_EQ(init_byte_base(kinds[t]), 0x80 + 0x10 * t);
    for (int low = 0; low < 16; ++low)
      EXPECT_EQ(command_kind_of_init(static_cast<uint8_t>(0x80 + 0x10 * t + low)), kinds[t]);
  }
  EXPECT_EQ(init_byte_base(CommandKind::kRaw), 0x00);
  EXPECT_EQ(command_kind_of_init(0x00), std::nullopt);
  EXPECT_EQ(command_kind_of_init(0x7F), std::nullopt);
  EXPECT_EQ(command_kind_of_init(0xF0), std::nullopt);
  EXPECT_EQ(command_kind_of("broadcast-write-reverse"), CommandKind::kBroadcastWriteReverse);
  EXPECT_EQ(command_kind_of("stack write"), std::nullopt);
  EXPECT_EQ(crc_wire_hex(0x350A), "0A35");
}

TEST(CommandFrames, EveryByteLandsInExactlyOneFrame) {
  // A byte soup of 200k bytes in one burst (a long pattern record): frames tile the input with
  // no gap or overlap, in linear time (a frame is at most 134 bytes: no search to the burst's end).
  std::vector<uint8_t> soup;
  uint32_t s = 0x1234567u;
  for (int i = 0; i < 200'000; ++i) {
    s = s * 1103515245u + 12345u;
    soup.push_back(static_cast<uint8_t>(s >> 16));
  }
  const std::vector<TimedByte> in = timed(soup);
  const std::vector<ParsedFrame> f = parse_frames(in);
  size_t next = 0;
  for (const ParsedFrame& x : f) {
    EXPECT_EQ(x.first_byte, next);
    EXPECT_GE(x.byte_count, 1u);
    next += x.byte_count;
  }
  EXPECT_EQ(next, soup.size());
}

}  // namespace
}  // namespace isolink
