#include "eye/waveform_csv.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace isolink::eye {
namespace {

std::string msg(const StatusOr<Waveform>& w) {
  return w.ok() ? "" : w.status().message();
}

TEST(WaveformCsv, DefaultColumnsIsolinkStyle) {
  // the solver's writer puts SPICE probe names with commas in the header, unquoted
  StatusOr<Waveform> w =
      parse_differential_csv("time,v(rxp,rxn)\n0,0\n1e-9,1.5\n2e-9,2.0\n", "w.csv");
  ASSERT_TRUE(w.ok()) << msg(w);
  EXPECT_EQ(w->names[0], "v(rxp,rxn)");
  w = parse_differential_csv("time,\"a,b\"\n0,0\n1e-9,1.5\n2e-9,2.0\n", "w.csv");
  ASSERT_TRUE(w.ok()) << msg(w);
  EXPECT_EQ(w->names[0], "a,b");
  EXPECT_EQ(w->time, (std::vector<double>{0, 1e-9, 2e-9}));
  ASSERT_EQ(w->columns.size(), 1u);
  EXPECT_EQ(w->columns[0], (std::vector<double>{0, 1.5, 2.0}));
}

TEST(WaveformCsv, ScopeExportMetadataSkippedSciNotationNonUniform) {
  const char* text =
      "Model,MDO3034\n"
      "Firmware Version,1.26\n"
      "\n"
      "Waveform Type,ANALOG\n"
      "Record Length,4\n"
      "Sample Interval,2.0E-10\n"
      "TIME,CH1,CH2\n"
      "-1.0000E-09,2.5E+00,2.5E+00\n"
      "-8.0000E-10,4.0E+00,1.0E+00\r\n"
      "-5.0000E-10,+5.0E+00,0.0E+00\n"
      "1.5000E-09,2.5,2.5\n";
  CsvColumns cols;
  cols.p = "CH1";
  cols.n = "ch2";  // case-insensitive match
  StatusOr<Waveform> w = parse_differential_csv(text, "scope.csv", cols);
  ASSERT_TRUE(w.ok()) << msg(w);
  ASSERT_EQ(w->samples(), 4u);
  EXPECT_DOUBLE_EQ(w->time[0], -1e-9);
  EXPECT_DOUBLE_EQ(w->time[3], 1.5e-9);
  EXPECT_EQ(w->columns[0], (std::vector<double>{0.0, 3.0, 5.0, 0.0}));
  EXPECT_EQ(w->names[0], "CH1-CH2");
}

TEST(WaveformCsv, ColumnsByIndexAndName) {
  const char* text = "a;b;c\n0;1;2\n1;3;5\n";  // semicolons
  CsvColumns c;
  c.time = "1";
  c.diff = "c";
  StatusOr<Waveform> w = parse_differential_csv(text, "x.csv", c);
  ASSERT_TRUE(w.ok()) << msg(w);
  EXPECT_EQ(w->columns[0], (std::vector<double>{2, 5}));
  c.diff = "2";
  w = parse_differential_csv(text, "x.csv", c);
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(w->columns[0], (std::vector<double>{1, 3}));
  c.diff = "zz";
  w = parse_differential_csv(text, "x.csv", c);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(msg(w),
            "x.csv:1: error: differential column 'zz': no such column (columns: 1 'a' (CHA), "
            "2 'b' (CHB), 3 'c' (CHC); or a 1-based index up to 3)");
}

TEST(WaveformCsv, LtspiceTabsAndQuotedNames) {
  const char* text =
      "\"time\"\t\"V(rxp)\"\t\"V(rxn)\"\n0.000000000000000e+000\t1\t0.5\n1e-9\t2\t-1\n";
  CsvColumns c;
  c.p = "V(rxp)";
  c.n = "V(rxn)";
  StatusOr<Waveform> w = parse_differential_csv(text, "lt.txt", c);
  ASSERT_TRUE(w.ok()) << msg(w);
  EXPECT_EQ(w->columns[0], (std::vector<double>{0.5, 3}));
}

TEST(WaveformCsv, BadLineReportedWithItsNumber) {
  const char* text = "# capture\ntime,v\n0,0\n1e-9,1.2\n2e-9,abc\n3e-9,0\n";
  StatusOr<Waveform> w = parse_differential_csv(text, "bad.csv");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(msg(w), "bad.csv:5: error: column 2 ('v'): expected a number, found 'abc'");
  w = parse_differential_csv("time,v\n0,0\n1e-9\n", "short.csv");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(msg(w), "short.csv:3: error: expected 2 fields like the header (line 1), found 1");
  w = parse_differential_csv("time,v\n0,0\n1e-9,1\n1e-9,2\n", "dup.csv");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(msg(w),
            "dup.csv:4: error: time 1e-09 is not after 1e-09 on line 3: time must increase "
            "from row to row");
}

TEST(WaveformCsv, NoHeaderOrNoDataOrBadFlags) {
  // no header: the first column is time
  StatusOr<Waveform> bare = parse_differential_csv("0,1\n1,2\n", "n.csv");
  ASSERT_TRUE(bare.ok()) << msg(bare);
  EXPECT_EQ(bare->columns[0], (std::vector<double>{1, 2}));
  EXPECT_EQ(msg(parse_differential_csv("time,v\n", "e.csv")),
            "e.csv:1: error: no data found: expected rows of numbers (e.g. \"-1.0e-06,0.52\"), "
            "optionally under a line of names (e.g. \"TIME,CH1,CH2\") and a units row (e.g. "
            "\"s,V,V\"); the last line read was 'time,v'");
  CsvColumns c;
  c.p = "a";
  EXPECT_NE(
      msg(parse_differential_csv("t,a,b\n0,1,2\n1,1,2\n", "f.csv", c)).find("needs an N column"),
      std::string::npos);
  c.n = "b";
  c.diff = "a";
  EXPECT_NE(msg(parse_differential_csv("t,a,b\n0,1,2\n1,1,2\n", "f.csv", c)).find("not both"),
            std::string::npos);
}

TEST(WaveformCsv, ReadsAFileWrittenByTheSolverWriter) {
  Waveform src;
  src.time = {0, 1e-9, 2.5e-9};
  src.add_column("vdiff", {0.25, -1.5, 3e-3});
  const auto path = (std::filesystem::temp_directory_path() / "isolink_eye_csv_test.csv").string();
  ASSERT_TRUE(write_waveform_csv(src, path).ok());
  StatusOr<Waveform> w = read_differential_csv(path);
  ASSERT_TRUE(w.ok()) << msg(w);
  EXPECT_EQ(w->time, src.time);
  EXPECT_EQ(w->columns[0], src.columns[0]);
  std::filesystem::remove(path);
  StatusOr<Waveform> missing = read_differential_csv("/nonexistent/x.csv");
  EXPECT_EQ(msg(missing), "/nonexistent/x.csv: error: cannot open the file");
}

}  // namespace
}  // namespace isolink::eye
