#include "eye/check.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "synth.h"

namespace isolink::eye {
namespace {

constexpr double ns = 1e-9;

Rules rules(const char* name = "bq7961x") {
  StatusOr<Rules> r = load_rules(name);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return *r;
}

const std::vector<uint8_t> kCommand = {0x80, 0x00, 0x02, 0x15, 0x0B, 0xCB, 0x49};

TEST(Check, CommandDecodesAndMatchesExpect) {
  Waveform w = synth::ideal_frames(kCommand, FrameFormat{});
  CheckOptions opt;
  opt.expect = kCommand;
  StatusOr<CheckResult> r = check_waveform(w, rules(), opt);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->pass);
  EXPECT_TRUE(r->expect_match);
  EXPECT_EQ(r->bytes, kCommand);
  ASSERT_EQ(r->frames.size(), 7u);
  // frame 0 starts at its preamble's +1.2 V crossing: 1 us + 6 ns
  EXPECT_NEAR(r->frames[0].start, 1e-6 + 6 * ns, 0.01 * ns);
  EXPECT_EQ(r->pulses[0].role, "preamble");
  EXPECT_EQ(r->pulses[0].frame, 0);
  EXPECT_TRUE(r->reasons.empty());
}

TEST(Check, ExpectMismatchFails) {
  Waveform w = synth::ideal_frames(kCommand, FrameFormat{});
  CheckOptions opt;
  opt.expect = kCommand;
  (*opt.expect)[3] = 0x14;
  StatusOr<CheckResult> r = check_waveform(w, rules(), opt);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->pass);
  EXPECT_FALSE(r->expect_match);
  EXPECT_EQ(r->expect_detail, "byte 3: expected 14, decoded 15");
  EXPECT_EQ(r->failing(), 0u);
  opt.expect->pop_back();
  (*opt.expect)[3] = 0x15;
  r = check_waveform(w, rules(), opt);
  EXPECT_FALSE(r->pass);
  EXPECT_EQ(r->expect_detail, "expected 6 bytes, decoded 7");
}

TEST(Check, SofOptionMustMatchTheWaveform) {
  FrameFormat no_sof;
  no_sof.sof = false;
  Waveform w = synth::ideal_frames({0x5A}, no_sof);
  StatusOr<CheckResult> wrong = check_waveform(w, rules());
  ASSERT_TRUE(wrong.ok());
  EXPECT_FALSE(wrong->pass);
  ASSERT_EQ(wrong->frames.size(), 1u);
  EXPECT_FALSE(wrong->frames[0].fault.empty());
  CheckOptions opt;
  opt.sof = false;
  StatusOr<CheckResult> right = check_waveform(w, rules(), opt);
  ASSERT_TRUE(right.ok());
  EXPECT_TRUE(right->pass);
  EXPECT_EQ(right->bytes, std::vector<uint8_t>{0x5A});
}

TEST(Check, NoPulsesFails) {
  Waveform w;
  w.time = {0, 1e-9, 2e-9};
  w.add_column("v", {0.1, 0.5, -0.3});
  StatusOr<CheckResult> r = check_waveform(w, rules());
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->pass);
  ASSERT_EQ(r->reasons.size(), 1u);
  EXPECT_NE(r->reasons[0].find("no pulses"), std::string::npos);
}

TEST(Check, BadSamplesAreErrors) {
  std::vector<double> t = {0, 2e-9, 1e-9};
  std::vector<double> v = {0, 0, 0};
  StatusOr<CheckResult> r = check_samples(t, v, rules());
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("sample 2"), std::string::npos);
  Rules bad = rules();
  bad.vth = -1;
  t = {0, 1e-9};
  v = {0, 0};
  r = check_samples(t, v, bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("vth = -1"), std::string::npos) << r.status().message();
}

// A bad sample is found and named wherever it is: in the first samples, inside the blocks the
// check takes without a branch per sample (every lane), and in the tail after the last block.
TEST(Check, BadSamplesAreNamedWhereverTheyAre) {
  const size_t n = 1003;
  for (size_t at : {size_t{0}, size_t{1}, size_t{2}, size_t{3}, size_t{4}, size_t{5}, size_t{8},
                    size_t{500}, size_t{501}, size_t{502}, size_t{503}, size_t{998}, size_t{1000},
                    size_t{1001}, size_t{1002}}) {
    for (int kind = 0; kind < 4; ++kind) {
      std::vector<double> t(n), v(n, 0.0);
      for (size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) * ns;
      std::string want = fmt::format("sample {} is not a finite number", at);
      if (kind == 0) v[at] = std::numeric_limits<double>::quiet_NaN();
      if (kind == 1) v[at] = -std::numeric_limits<double>::infinity();
      if (kind == 2) t[at] = std::numeric_limits<double>::infinity();
      if (kind == 3) {
        if (at == 0) continue;
        t[at] = t[at - 1];  // time stands still
        want = fmt::format("time does not increase at sample {} ", at);
      }
      StatusOr<CheckResult> r = check_samples(t, v, rules());
      ASSERT_FALSE(r.ok()) << "sample " << at << " kind " << kind;
      EXPECT_NE(r.status().message().find(want), std::string::npos)
          << r.status().message() << " (kind " << kind << ")";
    }
  }
}

TEST(Check, RecordCutMidFrameIsTruncatedAndInconclusive) {
  Waveform full = synth::ideal_frames({0x15, 0x0B}, FrameFormat{});
  // start the record in the middle of the first frame's first pulse
  Waveform w;
  const double cut = 1e-6 + 100 * ns;
  for (size_t i = 0; i < full.time.size(); ++i)
    if (full.time[i] >= cut) {
      w.time.push_back(full.time[i]);
    }
  std::vector<double> v(full.columns[0].end() - static_cast<std::ptrdiff_t>(w.time.size()),
                        full.columns[0].end());
  w.add_column("v", v);
  StatusOr<CheckResult> r = check_waveform(w, rules());
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->pulses[0].truncated);
  ASSERT_GE(r->frames.size(), 2u);
  EXPECT_EQ(r->frames[0].fault, "truncated");
  EXPECT_FALSE(r->frames[0].fails());
  EXPECT_EQ(r->bytes, std::vector<uint8_t>{0x0B});
  // the cut pulse cannot be judged: no verdict of pass (issue 14), and no failure either
  EXPECT_FALSE(r->pass);
  EXPECT_TRUE(r->inconclusive);
  EXPECT_EQ(r->failing(), 0u);
}

// Rule 8.4a: an AC-coupled line swings back past the threshold when the driver goes idle after a
// frame ending in a double pulse (error bit 1, postamble). That kickback is no pulse: the receiver
// blanks it (tblank), and the postamble runs into idle instead of being stretched to it.
TEST(Check, KickbackAfterACompleteFrameIsNoPulse) {
  synth::Train tr;
  tr.pulses = synth::pulses_from_half_bits(frame_half_bits(0xF9, FrameFormat{}, true));
  synth::Pwl base;
  synth::append_train(base, tr);
  // +1.5 V from 30 to 200 ns after the frame's end: past +1.2 V from 26 ns to 204 ns (178 ns)
  const double end = tr.end();
  synth::Pwl kick;
  kick.add(end + 10 * ns, 0);
  kick.add(end + 30 * ns, 1.5);
  kick.add(end + 200 * ns, 1.5);
  kick.add(end + 220 * ns, 0);
  const Waveform w = synth::sample(base, 1 * ns, end + 2e-6, {kick});
  StatusOr<CheckResult> r = check_waveform(w, rules());
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->pass) << summary_text(*r);
  EXPECT_EQ(r->bytes, std::vector<uint8_t>{0xF9});
  ASSERT_EQ(r->frames.size(), 1u);
  EXPECT_TRUE(r->frames[0].error_bit);
  ASSERT_EQ(r->ringing.size(), 1u);
  EXPECT_TRUE(r->ringing[0].after_frame);
  EXPECT_EQ(r->ringing[0].sign, +1);
  EXPECT_NEAR(r->ringing[0].peak, 1.5, 1e-9);
  EXPECT_NEAR(r->ringing[0].start, end + 26 * ns, 0.01 * ns);
  EXPECT_NEAR(r->ringing[0].end, end + 204 * ns, 0.01 * ns);
  // the last pulse is the double negative (error bit's second half + postamble): it runs into
  // idle, width b - a = 2 T (its crossings are 6 ns after each boundary, the last at 6 ns before)
  const PulseMetrics& last = r->pulses.back();
  EXPECT_EQ(last.sign, -1);
  EXPECT_TRUE(last.idle);
  EXPECT_NEAR(last.width.value, 500 * ns - 12 * ns, 0.01 * ns);
  EXPECT_FALSE(last.failing());

  // Without SOF a frame has 24 half bits: the 26 before the kickback are no whole frame, so the
  // kickback stays a pulse, joined to the postamble, which is then measured to its start.
  CheckOptions no_sof;
  no_sof.sof = false;
  r = check_waveform(w, rules(), no_sof);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->ringing.empty());
  EXPECT_EQ(r->pulses.back().sign, +1);
  const PulseMetrics& post = r->pulses[r->pulses.size() - 2];
  EXPECT_FALSE(post.idle);
  // from -1.2 V at 494 ns before the frame's end to the kickback's +1.2 V at 26 ns after it
  EXPECT_NEAR(post.width.value, 520 * ns, 0.01 * ns);
}

// Tone rules: 1 us pulses +/- 8 % (920..1080 ns); nothing is decoded.
TEST(Check, ToneWidthLimits) {
  for (double d : {79.0, 81.0}) {
    synth::Train t;
    t.T = 1e-6;
    for (int i = 0; i < 8; ++i) {
      synth::Pulse p;
      p.sign = i % 2 ? -1 : +1;
      t.pulses.push_back(p);
    }
    t.pulses[3].shift = d * ns;
    synth::Pwl pw;
    synth::append_train(pw, t);
    Waveform w = synth::sample(pw, 1 * ns, t.end() + 5e-6);
    StatusOr<CheckResult> r = check_waveform(w, rules("tone"));
    ASSERT_TRUE(r.ok());
    ASSERT_EQ(r->pulses.size(), 8u);
    EXPECT_NEAR(r->pulses[3].width.value, (1000 + d) * ns, 0.01 * ns);
    EXPECT_NEAR(r->pulses[4].width.value, (1000 - d) * ns, 0.01 * ns);
    EXPECT_EQ(r->pass, d < 80) << d;
    EXPECT_TRUE(r->tone);
    ASSERT_EQ(r->frames.size(), 1u);
    EXPECT_FALSE(r->frames[0].byte.has_value());
    EXPECT_TRUE(r->bytes.empty());
  }
}

TEST(Check, JsonFields) {
  synth::Train t;
  t.pulses = synth::pulses_from_half_bits(frame_half_bits(0x80, FrameFormat{}));
  t.pulses[2].vstart = 1.59;
  t.pulses[2].vend = 1.35;
  synth::Pwl pw;
  synth::append_train(pw, t);
  Waveform w = synth::sample(pw, 1 * ns, t.end() + 5e-6);
  StatusOr<CheckResult> r = check_waveform(w, rules());
  ASSERT_TRUE(r.ok());
  nlohmann::ordered_json j = to_json(*r);
  EXPECT_EQ(j["verdict"], "fail");
  EXPECT_EQ(j["rules"], "bq7961x");
  const auto& s = j["summary"];
  EXPECT_EQ(s["pulses"], t.pulses.size());
  EXPECT_EQ(s["failing"], 1);
  EXPECT_NEAR(s["vstart_min"].get<double>(), 1.59, 1e-3);
  EXPECT_NEAR(s["vend_min"].get<double>(), 1.35, 1e-3);
  EXPECT_NEAR(s["width_max_ns"].get<double>(), 500, 0.01);
  // slowest edge: pulse 2's fall from 1.35 V to -2 V in 20 ns, 2.4 V of it: 2.4 / 3.35 * 20 ns
  EXPECT_NEAR(s["edge_max_ns"].get<double>(), 2.4 / 3.35 * 20, 0.01);
  EXPECT_NEAR(s["worst"]["vstart"]["margin"].get<double>(), -0.01, 1e-3);
  EXPECT_EQ(s["worst"]["vstart"]["pulse"], 2);
  EXPECT_EQ(s["worst"]["vstart"]["bit"], "sync 0");
  EXPECT_EQ(s["worst"]["width"]["unit"], "ns");
  const auto& p = j["pulses"];
  ASSERT_EQ(p.size(), t.pulses.size());
  for (const char* key : {"index", "sign", "start_s", "end_s", "width_ns", "class", "edge_ns",
                          "vstart", "vend", "fails", "warnings"})
    EXPECT_TRUE(p[0].contains(key)) << key;
  EXPECT_EQ(p[0]["class"], 1);
  EXPECT_TRUE(p[0]["edge_ns"].is_null());
  EXPECT_EQ(p[4]["class"], 2);
  EXPECT_EQ(p.back()["class"], "idle");
  EXPECT_EQ(p[2]["fails"].size(), 1u);
  EXPECT_TRUE(j["ringing"].is_array());
  EXPECT_TRUE(j["idle"].is_array());
  EXPECT_EQ(j["decoded"]["bytes"], "");
  ASSERT_EQ(j["decoded"]["frames"].size(), 1u);
  EXPECT_TRUE(j["decoded"]["frames"][0]["byte"].is_null());
  EXPECT_EQ(j["decoded"]["frames"][0]["fault"], "weak bit");
  EXPECT_TRUE(j["decoded"]["frames"][0].contains("start_s"));
}

TEST(Check, SummaryTextAndPulsesCsv) {
  Waveform w = synth::ideal_frames({0x80, 0x00}, FrameFormat{});
  StatusOr<CheckResult> r = check_waveform(w, rules());
  ASSERT_TRUE(r.ok());
  const std::string text = summary_text(*r, "wave.csv");
  EXPECT_EQ(text.rfind("wave.csv: PASS (rules bq7961x)\n", 0), 0u) << text;
  EXPECT_NE(text.find("decoded: 80 00"), std::string::npos);
  EXPECT_NE(text.find("vstart"), std::string::npos);
  EXPECT_NE(text.find("counts: " + std::to_string(r->pulses.size()) + " pulses (0 failing)"),
            std::string::npos)
      << text;

  const auto dir = std::filesystem::temp_directory_path() / "isolink_eye_check_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "pulses.csv").string();
  ASSERT_TRUE(write_pulses_csv(*r, path).ok());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  std::ifstream in(path);
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  EXPECT_EQ(header.rfind("index,sign,start_s,end_s,width_ns,class,edge_ns,vstart,vend", 0), 0u);
  EXPECT_EQ(first.rfind("0,1,", 0), 0u) << first;
  size_t rows = 1;
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_EQ(rows, r->pulses.size());
  std::filesystem::remove_all(dir);
}

// check --json on a capture with millions of pulses used 3.6 GB (issue 15): the JSON lists at
// most kMaxJsonPulses of them and counts the rest.
TEST(CheckJson, PulseDetailsAreCapped) {
  CheckResult r;
  r.pulses.resize(kMaxJsonPulses + 5);
  for (size_t i = 0; i < r.pulses.size(); ++i) r.pulses[i].index = i;
  const nlohmann::ordered_json j = to_json(r);
  ASSERT_EQ(j["pulses"].size(), kMaxJsonPulses);
  EXPECT_EQ(j["pulses"].back()["index"], kMaxJsonPulses - 1);
  EXPECT_EQ(j["pulses_omitted"], 5);
  EXPECT_EQ(j["summary"]["pulses"], kMaxJsonPulses + 5);  // the summary still counts them all
}

}  // namespace
}  // namespace isolink::eye
