// Shared by the scope layout and binary capture tests (issue 14): the known daisy-chain record
// (synth::ideal_frames of known bytes, so the verdict is pass and the decoded bytes are known),
// its rows as text, and a fixture that writes files into a fresh folder and expects a pass.
#pragma once

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "eye/check.h"
#include "eye/waveform_csv.h"
#include "synth.h"

namespace isolink::eye::scope_test {

namespace fs = std::filesystem;
inline const std::vector<uint8_t> kBytes = {0x80, 0x15};
constexpr double kDt = 2e-9;  // sampling step of the record
constexpr double kCm = 2.5;   // common mode on each leg (V)

// The record: frames of kBytes, v = P - N with P = kCm + v/2, N = kCm - v/2.
inline const Waveform& record() {
  static const Waveform w = synth::ideal_frames(kBytes, FrameFormat{}, 2e-6, kDt);
  return w;
}

inline std::string num(double x, bool comma = false) {
  char b[40];
  std::snprintf(b, sizeof b, "%.9g", x);
  std::string s = b;
  if (comma)
    for (char& c : s)
      if (c == '.') c = ',';
  return s;
}

// Rows of the record: row(i, t, p, n) returns one line (without its end).
inline std::string rows(const std::function<std::string(size_t, double, double, double)>& row,
                        const char* eol = "\n") {
  const Waveform& w = record();
  std::string out;
  for (size_t i = 0; i < w.time.size(); ++i) {
    const double v = w.columns[0][i];
    out += row(i, w.time[i], kCm + v / 2, kCm - v / 2) + eol;
  }
  return out;
}

class Layout : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("isolink_scope_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // Reads, checks, and expects a pass decoding kBytes.
  CheckResult expect_pass(const std::vector<std::string>& files, const CsvColumns& cols,
                          CaptureInfo* info, double tol = 1e-6) {
    StatusOr<Waveform> w = read_capture(files, cols, info);
    EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.status().message());
    if (!w.ok()) return {};
    EXPECT_EQ(w->samples(), record().samples());
    StatusOr<CheckResult> r = check_waveform(*w, *load_rules("bq7961x"));
    EXPECT_TRUE(r.ok());
    EXPECT_TRUE(r->pass) << summary_text(*r);
    EXPECT_EQ(r->bytes, kBytes);
    // v = P - N to the writer's 9 digits: the 2 V levels come back within 1 uV (binary
    // formats: within their quantization, tol)
    EXPECT_NEAR(*r->vstart_min(), 2.0, tol);
    return *r;
  }
  fs::path dir_;
};

// A real capture under tests/eye/data/real (SOURCES.md says where each comes from).
inline std::string real(const char* name) {
  return std::string(ISOLINK_EYE_DATA "/real/") + name;
}

}  // namespace isolink::eye::scope_test
