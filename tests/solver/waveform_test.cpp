#include "base/waveform.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace isolink {
namespace {

TEST(Waveform, ResampleInterpolatesLinearly) {
  Waveform w;
  w.time = {0, 1, 3};
  w.add_column("v", {0, 2, 6});
  Waveform r = w.resampled(0.5);
  ASSERT_EQ(r.samples(), 7u);
  EXPECT_DOUBLE_EQ(r.columns[0][1], 1.0);
  EXPECT_DOUBLE_EQ(r.columns[0][5], 5.0);
  EXPECT_DOUBLE_EQ(w.value_at(0, 2.0), 4.0);
}

TEST(Waveform, CsvHasHeaderAndRows) {
  Waveform w;
  w.time = {0, 1e-9};
  w.add_column("v(a,b)", {1.5, -2});
  std::string path = ::testing::TempDir() + "/w.csv";
  ASSERT_TRUE(write_waveform_csv(w, path).ok());
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "time,\"v(a,b)\"\n0,1.5\n1e-09,-2\n");  // RFC 4180 quoting
  EXPECT_FALSE(write_waveform_csv(w, "/nonexistent-dir/x.csv").ok());
}

}  // namespace
}  // namespace isolink
