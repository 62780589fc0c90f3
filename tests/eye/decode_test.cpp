#include <gtest/gtest.h>

#include "eye/check.h"
#include "eye/rules.h"
#include "protocol/frame.h"
#include "synth.h"

namespace isolink::eye {
namespace {

std::string signs(const std::vector<int>& h) {
  std::string s;
  for (int x : h) s += x > 0 ? '+' : '-';
  return s;
}

std::vector<int> from_signs(const std::string& s) {
  std::vector<int> h;
  for (char c : s) h.push_back(c == '+' ? 1 : -1);
  return h;
}

TEST(Decode, HalfBitsOf0x80ByHand) {
  // preamble + | sync 0 0 = -+ -+ | SOF 1 = +- | 0x80 LSB first: 0000000 1 | error 0 | postamble -
  EXPECT_EQ(signs(frame_half_bits(0x80, FrameFormat{})),
            "+"
            "-+-+"
            "+-"
            "-+-+-+-+-+-+-+"
            "+-"
            "-+"
            "-");
  EXPECT_EQ(frame_half_bits(0x80, FrameFormat{}).size(), 26u);
}

TEST(Decode, HalfBitsMsbFirstNoSofErrorBit) {
  FrameFormat f;
  f.sof = false;
  f.bit_order = BitOrder::kMsbFirst;
  // 0x80 MSB first: 1 0000000; error bit 1
  EXPECT_EQ(signs(frame_half_bits(0x80, f, true)),
            "+"
            "-+-+"
            "+-"
            "-+-+-+-+-+-+-+"
            "+-"
            "-");
  EXPECT_EQ(f.half_bits(), 24u);
}

TEST(Decode, DecodesHandWrittenFrame) {
  // 0x15 = 0001 0101: LSB first 1,0,1,0,1,0,0,0
  auto h = from_signs(
      "+"
      "-+-+"
      "+-"
      "+-"
      "-+"
      "+-"
      "-+"
      "+-"
      "-+"
      "-+"
      "-+"
      "-+"
      "-");
  std::vector<DecodedByte> d = decode_half_bits(h, FrameFormat{});
  ASSERT_EQ(d.size(), 1u);
  ASSERT_TRUE(d[0].byte.has_value());
  EXPECT_EQ(*d[0].byte, 0x15);
  EXPECT_FALSE(d[0].error_bit);
  EXPECT_EQ(d[0].fault, "");
  EXPECT_EQ(d[0].half_count, 26u);
}

TEST(Decode, AllBytesBothOrdersWithAndWithoutSofAndErrorBit) {
  for (bool sof : {true, false})
    for (BitOrder o : {BitOrder::kLsbFirst, BitOrder::kMsbFirst})
      for (int err = 0; err < 2; ++err)
        for (int b = 0; b < 256; ++b) {
          FrameFormat f;
          f.sof = sof;
          f.bit_order = o;
          auto d = decode_half_bits(frame_half_bits(static_cast<uint8_t>(b), f, err), f);
          ASSERT_EQ(d.size(), 1u);
          ASSERT_TRUE(d[0].byte.has_value()) << b << " " << d[0].fault << " " << d[0].detail;
          EXPECT_EQ(*d[0].byte, b);
          EXPECT_EQ(d[0].error_bit, err == 1);
        }
}

TEST(Decode, TwoFramesBackToBackInOneRun) {
  auto h = frame_half_bits(0xCB, FrameFormat{});
  auto h2 = frame_half_bits(0x49, FrameFormat{});
  h.insert(h.end(), h2.begin(), h2.end());
  auto d = decode_half_bits(h, FrameFormat{});
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(*d[0].byte, 0xCB);
  EXPECT_EQ(*d[1].byte, 0x49);
  EXPECT_EQ(d[1].first_half, 26u);
}

TEST(Decode, Faults) {
  FrameFormat f;
  auto good = frame_half_bits(0x5A, f);
  {  // preamble negative
    auto h = good;
    h[0] = -1;
    auto d = decode_half_bits(h, f);
    ASSERT_EQ(d.size(), 1u);
    EXPECT_EQ(d[0].fault, "sync");
    EXPECT_FALSE(d[0].byte.has_value());
  }
  {  // sync 1 sent as a 1
    auto h = good;
    h[3] = +1;
    h[4] = -1;
    auto d = decode_half_bits(h, f);
    EXPECT_EQ(d[0].fault, "sync");
    EXPECT_NE(d[0].detail.find("sync 1"), std::string::npos) << d[0].detail;
  }
  {  // SOF 0 while 1 is expected
    auto h = good;
    h[5] = -1;
    h[6] = +1;
    auto d = decode_half_bits(h, f);
    EXPECT_EQ(d[0].fault, "sync");
    EXPECT_NE(d[0].detail.find("SOF"), std::string::npos);
  }
  {  // data couplet (+, +): neither 0 nor 1
    auto h = good;
    h[7] = +1;
    h[8] = +1;
    auto d = decode_half_bits(h, f);
    EXPECT_EQ(d[0].fault, "weak bit");
    EXPECT_NE(d[0].detail.find("bit 0"), std::string::npos) << d[0].detail;
  }
  {  // cut short
    auto h = good;
    h.resize(20);
    auto d = decode_half_bits(h, f);
    EXPECT_EQ(d[0].fault, "length");
    EXPECT_EQ(d[0].half_count, 20u);
  }
  {  // postamble positive
    auto h = good;
    h.back() = +1;
    auto d = decode_half_bits(h, f);
    EXPECT_EQ(d[0].fault, "sync");
    EXPECT_NE(d[0].detail.find("postamble"), std::string::npos);
  }
}

TEST(Decode, Roles) {
  FrameFormat f;
  EXPECT_EQ(half_bit_role(0, f), "preamble");
  EXPECT_EQ(half_bit_role(1, f), "sync 0");
  EXPECT_EQ(half_bit_role(4, f), "sync 1");
  EXPECT_EQ(half_bit_role(5, f), "SOF");
  EXPECT_EQ(half_bit_role(7, f), "bit 0");
  EXPECT_EQ(half_bit_role(22, f), "bit 7");
  EXPECT_EQ(half_bit_role(23, f), "error bit");
  EXPECT_EQ(half_bit_role(25, f), "postamble");
  f.bit_order = BitOrder::kMsbFirst;
  f.sof = false;
  EXPECT_EQ(half_bit_role(5, f), "bit 7");
  EXPECT_EQ(half_bit_role(23, f), "postamble");
}

// bytes -> ideal waveform -> check -> the same bytes: all 256 values, both orders, SOF or not.
TEST(Decode, WaveformRoundTripAllBytes) {
  StatusOr<Rules> rules = load_rules("bq7961x");
  ASSERT_TRUE(rules.ok()) << rules.status().message();
  std::vector<uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[i] = static_cast<uint8_t>(i);
  for (bool sof : {true, false})
    for (BitOrder o : {BitOrder::kLsbFirst, BitOrder::kMsbFirst}) {
      FrameFormat f;
      f.sof = sof;
      f.bit_order = o;
      Waveform w = synth::ideal_frames(all, f, 2e-6, 2e-9);
      CheckOptions opt;
      opt.sof = sof;
      opt.bit_order = o;
      opt.expect = all;
      StatusOr<CheckResult> r = check_waveform(w, *rules, opt);
      ASSERT_TRUE(r.ok()) << r.status().message();
      EXPECT_EQ(r->bytes, all) << "sof " << sof << " msb " << (o == BitOrder::kMsbFirst);
      EXPECT_TRUE(r->expect_match);
      EXPECT_TRUE(r->pass) << (r->reasons.empty() ? "" : r->reasons[0]);
      EXPECT_EQ(r->frames.size(), 256u);
      // decoding with the other bit order gives the bit-reversed bytes
      CheckOptions swapped = opt;
      swapped.bit_order = o == BitOrder::kLsbFirst ? BitOrder::kMsbFirst : BitOrder::kLsbFirst;
      swapped.expect.reset();
      StatusOr<CheckResult> r2 = check_waveform(w, *rules, swapped);
      ASSERT_TRUE(r2.ok());
      ASSERT_EQ(r2->bytes.size(), 256u);
      EXPECT_EQ(r2->bytes[0x01], 0x80);
      EXPECT_EQ(r2->bytes[0x0B], 0xD0);
    }
}

}  // namespace
}  // namespace isolink::eye
