#include "eye/commands.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "synth.h"

namespace isolink::eye {
namespace {

// TI's worked example: stack write of 02 B7 78 BC to 0x0100, CRC 0A 35.
const std::vector<uint8_t> kStackWrite = {0xB3, 0x01, 0x00, 0x02, 0xB7, 0x78, 0xBC, 0x0A, 0x35};

Rules rules(const char* name = "bq7961x") {
  StatusOr<Rules> r = load_rules(name);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return *r;
}

// The bytes as one ideal waveform, 3.8 us of idle between bytes (a byte every 10.3 us, as the
// bridge forwards them), amplitude amp, the first byte `lead` into the record.
CheckResult check_bytes(const std::vector<uint8_t>& bytes, const char* rule_set = "bq7961x",
                        double amp = 2.0, double lead = 20e-6, const CheckOptions& opt = {}) {
  Waveform w = synth::ideal_frames(bytes, FrameFormat{}, 3.8e-6);
  for (double& x : w.columns[0]) x *= amp / 2.0;
  if (lead > 1e-6) {
    for (double& t : w.time) t += lead - 1e-6;  // ideal_frames starts the first byte at 1 us
    w.time.insert(w.time.begin(), 0.0);         // idle (0 V) from 0
    w.columns[0].insert(w.columns[0].begin(), 0.0);
  }
  StatusOr<CheckResult> r = check_waveform(w, rules(rule_set), opt);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return *r;
}

TEST(Commands, ACleanCommandIsListedWithItsFields) {
  const CheckResult r = check_bytes(kStackWrite);
  ASSERT_TRUE(r.pass);
  ASSERT_EQ(r.commands.size(), 1u);
  const ParsedFrame& c = r.commands[0];
  EXPECT_EQ(c.kind_name(), "stack-write");
  EXPECT_TRUE(c.crc_ok);
  EXPECT_EQ(c.byte_count, 9u);
  // It starts at its first byte's preamble and ends with the last byte's postamble: 8 byte
  // periods of 6.5 + 3.8 us and one byte of 6.5 us after the first crossing (+6 ns), within the
  // synthetic edges' few ns.
  EXPECT_NEAR(c.start_s, r.frames[0].start, 1e-15);
  EXPECT_NEAR(c.end_s - c.start_s, 8 * 10.3e-6 + 6.5e-6, 20e-9);
  EXPECT_EQ(commands_note(r), "");
  const std::string s = summary_text(r);
  EXPECT_NE(s.find("commands (1, 0 malformed):"), std::string::npos) << s;
  EXPECT_NE(s.find("stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok"), std::string::npos) << s;

  const nlohmann::ordered_json j = to_json(r);
  ASSERT_EQ(j["commands"].size(), 1u);
  const auto& jc = j["commands"][0];
  EXPECT_EQ(jc["kind"], "stack-write");
  EXPECT_TRUE(jc["device"].is_null());
  EXPECT_EQ(jc["register"], "0x0100");
  EXPECT_EQ(jc["data"], "02 B7 78 BC");
  EXPECT_EQ(jc["crc"], "0A35");
  EXPECT_EQ(jc["crc_ok"], true);
  EXPECT_EQ(jc["flags"].size(), 0u);
  EXPECT_EQ(jc["text"], "stack write 0x0100 = 02 B7 78 BC, CRC 0A35 ok");
  EXPECT_NEAR(jc["start_s"].get<double>(), c.start_s, 1e-18);
  EXPECT_TRUE(j["commands_note"].is_null());
}

TEST(Commands, ABadCrcOnACleanWaveformPointsAtTheFirmware) {
  std::vector<uint8_t> b = kStackWrite;
  b[8] = 0x36;
  const CheckResult r = check_bytes(b);
  ASSERT_TRUE(r.pass);  // the command does not change the verdict
  ASSERT_EQ(r.commands.size(), 1u);
  const std::string note = commands_note(r);
  EXPECT_EQ(note,
            "the waveform meets every receiver rule, but command 0 has a bad CRC: a firmware or "
            "host problem, not the link");
  EXPECT_NE(summary_text(r).find(note), std::string::npos);
  EXPECT_NE(summary_text(r).find("CRC 0A36 bad (expected 0A35)"), std::string::npos);
  const nlohmann::ordered_json j = to_json(r);
  EXPECT_EQ(j["commands_note"], note);
  EXPECT_EQ(j["commands"][0]["flags"][0], "bad_crc");
  EXPECT_EQ(j["commands"][0]["crc_expected"], "0A35");
}

TEST(Commands, ACommandAtTheRecordsStartGetsACaveat) {
  std::vector<uint8_t> b = kStackWrite;
  b[8] = 0x36;
  const CheckResult r = check_bytes(b, "bq7961x", 2.0, 1e-6);
  ASSERT_TRUE(r.pass);
  ASSERT_TRUE(r.commands.at(0).at_record_start);
  EXPECT_EQ(commands_note(r),
            "the waveform meets every receiver rule, but command 0 has a bad CRC (it starts 1.0 "
            "us into the record: if its first bytes came before, capture from earlier): a "
            "firmware or host problem, not the link");
}

TEST(Commands, OnAFailingWaveformTheLinkComesFirst) {
  std::vector<uint8_t> b = kStackWrite;
  b[8] = 0x36;
  // Every byte decodes, but they are not the bytes expected: the waveform fails.
  CheckOptions opt;
  opt.expect = kStackWrite;
  CheckResult r = check_bytes(b, "bq7961x", 2.0, 20e-6, opt);
  ASSERT_FALSE(r.pass);
  ASSERT_EQ(r.commands.size(), 1u);
  EXPECT_EQ(commands_note(r),
            "command 0 has a bad CRC; the waveform does not pass the receiver rules either: fix "
            "the link first, then look at the firmware if the command stays malformed");
  // 1.65 V pulses: short of the bridge's 1.8 V VSTART, no byte decodes (weak bits).
  r = check_bytes(b, "bq79600", 1.65);
  ASSERT_FALSE(r.pass);
  ASSERT_EQ(r.commands.size(), 1u);
  EXPECT_EQ(r.commands[0].flags, std::vector<FrameFlag>{FrameFlag::kUndecoded});
  EXPECT_EQ(commands_note(r).rfind("command 0 holds a byte that did not decode; the waveform", 0),
            0u)
      << commands_note(r);
}

TEST(Commands, ACommandTheRecordCutsIsNotBlamedOnTheFirmware) {
  // The record ends 1 us after the fifth of nine bytes: every pulse is whole (pass), the command
  // is truncated by the record, not by its sender.
  Waveform w = synth::ideal_frames({0xB3, 0x01, 0x00, 0x02, 0xB7}, FrameFormat{}, 3.8e-6);
  StatusOr<CheckResult> r = check_waveform(w, rules());
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(r->pass);
  ASSERT_EQ(r->commands.size(), 1u);
  EXPECT_TRUE(r->commands[0].cut_by_record);
  EXPECT_EQ(r->commands[0].flags, std::vector<FrameFlag>{FrameFlag::kTruncated});
  EXPECT_NE(r->commands[0].text.find("before the record ends"), std::string::npos);
  EXPECT_EQ(commands_note(*r), "");
}

TEST(Commands, TimedBytesCarryEachFramesSpan) {
  const CheckResult r = check_bytes({0xA0, 0x02});
  const std::vector<TimedByte> t = timed_bytes(r);
  ASSERT_EQ(t.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(t[i].start_s, r.frames[i].start);
    EXPECT_EQ(t[i].end_s, r.pulses[r.frames[i].last_pulse].b);
    EXPECT_NEAR(t[i].end_s - t[i].start_s, 6.5e-6, 20e-9);  // 26 half bits of 250 ns
    EXPECT_EQ(t[i].value, r.bytes[i]);
  }
  // The idle between them is the 3.8 us written, within the edges' few ns.
  EXPECT_NEAR(t[1].start_s - t[0].end_s, 3.8e-6, 20e-9);
}

TEST(Commands, ToneRulesParseNothing) {
  Waveform w = synth::ideal_frames(kStackWrite, FrameFormat{}, 3.8e-6);
  StatusOr<CheckResult> r = check_waveform(w, rules("tone"));
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->commands.empty());
  EXPECT_EQ(to_json(*r)["commands"].size(), 0u);
}

TEST(Commands, TheIdleThresholdIsAnOption) {
  Waveform w = synth::ideal_frames(kStackWrite, FrameFormat{}, 3.8e-6);
  CheckOptions opt;
  opt.command_idle = 3e-6;  // under the 3.8 us between bytes: every byte alone, truncated
  StatusOr<CheckResult> r = check_waveform(w, rules(), opt);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->commands.size(), 9u);
  opt.command_idle = -1;
  EXPECT_FALSE(check_waveform(w, rules(), opt).ok());
}

}  // namespace
}  // namespace isolink::eye
