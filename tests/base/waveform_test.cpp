#include "base/waveform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

// The rows are formatted in blocks on several threads: every row comes back, in order, exactly as
// printf's %.12g (time) and %.9g (values) write it, across block edges and a last partial block.
TEST(Waveform, CsvRowsInOrderAsPrintfWritesThemAcrossBlocks) {
  Waveform w;
  const size_t rows = 3 * 8192 + 1234;
  for (size_t i = 0; i < rows; ++i) w.time.push_back(1e-10 * static_cast<double>(i) / 3.0);
  std::vector<double> a, b;
  for (size_t i = 0; i < rows; ++i) {
    a.push_back(std::sin(0.001 * static_cast<double>(i)) * 4.7);
    b.push_back(-1e-7 * static_cast<double>(i) / 7.0);
  }
  w.add_column("a", a);
  w.add_column("b", b);
  const std::string path = ::testing::TempDir() + "/blocks.csv";
  ASSERT_TRUE(write_waveform_csv(w, path).ok());
  std::ifstream in(path);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "time,a,b");
  char expected[128];
  for (size_t i = 0; i < rows; ++i) {
    ASSERT_TRUE(std::getline(in, line)) << "row " << i << " missing";
    std::snprintf(expected, sizeof expected, "%.12g,%.9g,%.9g", w.time[i], a[i], b[i]);
    ASSERT_EQ(line, expected) << "row " << i;
  }
  EXPECT_FALSE(std::getline(in, line)) << "a row too many: " << line;
}

}  // namespace
}  // namespace isolink
