// One test per oscilloscope export layout (issue 14): each file carries a known daisy-chain record
// (scope_fixture.h: synth::ideal_frames of known bytes, so the verdict is pass and the decoded
// bytes are known), written here in that layout as the instrument's documentation and public
// example exports show it. Then the hazards: units, swapped columns, truncated pulses, a flat
// record, long pulses. Binary captures are in scope_binary_test.cpp.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "scope_fixture.h"

namespace isolink::eye {
namespace {

using namespace scope_test;  // NOLINT: the record and the fixture
TEST_F(Layout, TektronixClassicOneFilePerChannel) {
  // TDS/TBS: metadata in fields 1-3 of the first rows, time and value in 4-5, a trailing comma
  auto tek = [](const char* src, bool p) {
    const char* meta[][3] = {{"Record Length", "8.501000e+03", "Points"},
                             {"Sample Interval", "2.000000e-09", "s"},
                             {"Trigger Point", "0.000000000000e+00", "Samples"},
                             {"", "", ""},
                             {"", "", ""},
                             {"", "", ""},
                             {"Source", src, ""},
                             {"Vertical Units", "V", ""},
                             {"Vertical Scale", "1.000000e+00", ""},
                             {"Vertical Offset", "0.000000e+00", ""},
                             {"Horizontal Units", "s", ""},
                             {"Horizontal Scale", "2.500000e-06", ""},
                             {"Pt Fmt", "Y", ""},
                             {"Yzero", "0.000000e+00", ""},
                             {"Probe Atten", "1.000000e+00", ""},
                             {"Model Number", "TDS2024B", ""},
                             {"Serial Number", "C012345", ""},
                             {"Firmware Version", "FV:v22.01", ""}};
    return rows(
        [&](size_t i, double t, double pv, double nv) {
          const auto& m = meta[std::min<size_t>(i, 17)];
          const bool has = i < 18;
          return std::string(has ? m[0] : "") + "," + (has ? m[1] : "") + "," + (has ? m[2] : "") +
                 "," + num(t) + "," + num(p ? pv : nv) + ",";
        },
        "\r\n");
  };
  const std::string a = write("F0000CH1.CSV", tek("CH1", true));
  const std::string b = write("F0000CH2.CSV", tek("CH2", false));
  CaptureInfo info;
  expect_pass({a, b}, {}, &info);
  EXPECT_EQ(info.layouts, (std::vector<std::string>{"tektronix classic", "tektronix classic"}));
  ASSERT_EQ(info.columns.size(), 3u);
  EXPECT_EQ(info.columns[1].channel, "CH1");
  EXPECT_EQ(info.columns[1].index, 5u);
  EXPECT_EQ(info.columns[2].channel, "CH2");
  EXPECT_EQ(info.alignment, "the two files share one time base");
  EXPECT_NEAR(info.interval, kDt, 1e-15);
}

TEST_F(Layout, TektronixMdoWithDigitalChannels) {
  // an empty separator column, then a second TIME column and digital channels
  const std::string text =
      "Model,MDO3024\nFirmware Version,1.26\n\nWaveform Type,ANALOG\nPoint Format,Y\n"
      "Horizontal Units,s\nRecord Length," +
      std::to_string(record().samples()) + "\nLabel,,,,,,\nTIME,CH1,CH2,,TIME,D0,D1\n" +
      rows([](size_t i, double t, double p, double n) {
        return num(t) + "," + num(p) + "," + num(n) + ",," + num(t) + "," + std::to_string(i % 2) +
               ",1";
      });
  const std::string f = write("tek0000ALL.csv", text);
  CsvColumns c;
  c.p = "CH1";
  c.n = "CH2";
  CaptureInfo info;
  expect_pass({f}, c, &info);
  EXPECT_EQ(info.layouts[0], "header");
  // the second TIME column is a time column: refused as N
  c.n = "5";
  StatusOr<Waveform> w = read_capture({f}, c);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find(":9: error: N column '5' is column 5 ('TIME'), a time "
                                      "column"),
            std::string::npos)
      << w.status().message();
}

TEST_F(Layout, KeysightInfiniiVisionUnitsRowAndNumericNames) {
  const std::string text =
      "x-axis,1,2\nsecond,Volt,Volt\n" + rows([](size_t, double t, double p, double n) {
        return num(t) + "," + num(p) + "," + num(n);
      });
  const std::string f = write("scope_0.csv", text);
  CsvColumns c;
  c.p = "1";  // the column named 1 (channel 1), not column 1 (time)
  c.n = "2";
  CaptureInfo info;
  expect_pass({f}, c, &info);
  EXPECT_EQ(info.layouts[0], "header + units row");
  EXPECT_EQ(info.columns[1].index, 2u);
  EXPECT_EQ(info.columns[2].index, 3u);
  ASSERT_FALSE(info.notes.empty());
  EXPECT_NE(info.notes[0].find("P column '1' is both column 2's name or channel and the index of "
                               "column 1 ('x-axis'): used column 2 ('1'); write #1 for the index"),
            std::string::npos)
      << info.notes[0];
  c.p = "#1";  // the index: the time column, refused
  StatusOr<Waveform> w = read_capture({f}, c);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("a time column"), std::string::npos);
}

TEST_F(Layout, KeysightInfiniiumKeyValueHeaderYOnly) {
  // "Key: value" lines ending in "Data:", one value per line; time from XOrg + i * XInc
  const Waveform& w = record();
  std::string text = "Revision: 0\nType: raw\nStart: 0\nPoints: " + std::to_string(w.samples()) +
                     "\nCount: 1\nXDispRange: 2.0E-05\nXInc: 2E-09\nXOrg: 0\nXUnits: second\n"
                     "YUnits: Volt\nSource: CHANnel1\nData:\n";
  for (double v : w.columns[0]) text += num(v) + "\n";
  CaptureInfo info;
  expect_pass({write("infiniium.txt", text)}, {}, &info);
  EXPECT_EQ(info.layouts[0], "key: value header");
  EXPECT_EQ(info.columns[0].channel, "CH1");  // Source: CHANnel1
  EXPECT_NE(info.time_from.find("XOrg + row * XInc"), std::string::npos) << info.time_from;
}

TEST_F(Layout, NoHeaderAtAll) {
  // Infiniium without a header, R&S .Wfm.csv with time: two numeric columns
  const std::string text =
      rows([](size_t, double t, double p, double n) { return num(t) + "," + num(p - n); });
  CaptureInfo info;
  expect_pass({write("bare.csv", text)}, {}, &info);
  EXPECT_EQ(info.layouts[0], "no header");
  EXPECT_EQ(info.columns[1].name, "column 2");
}

TEST_F(Layout, RohdeSchwarzWfmCsvValuesWithHeaderFile) {
  // RTP/RTO: NAME.Wfm.csv holds values only; NAME.csv holds "Key:value:" lines
  const Waveform& w = record();
  std::string data;
  for (double v : w.columns[0]) data += num(v) + "\n";
  write("RefCurve.csv",
        "FileFormat:ASCII:\nSignalFormat:FLOAT:\nXStart:0:\nXStop:" + num(w.time.back()) +
            ":\nResolution:2E-09:\nRecordLength:" + std::to_string(w.samples()) + ":\n");
  CaptureInfo info;
  expect_pass({write("RefCurve.Wfm.csv", data)}, {}, &info);
  EXPECT_NE(info.time_from.find("XStart + row * Resolution"), std::string::npos) << info.time_from;
  // without its header file: refused with what to do
  fs::remove(dir_ / "RefCurve.csv");
  StatusOr<Waveform> r = read_capture({(dir_ / "RefCurve.Wfm.csv").string()}, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find(":1: error: one column of values and no time"),
            std::string::npos)
      << r.status().message();
}

TEST_F(Layout, RigolStartIncrement) {
  // X counts samples; time = Start + X * Increment, both given in the units row
  const std::string text =
      "X,CH1,CH2,Start,Increment,\nSequence,Volt,Volt,0.000000e+00,2.000000e-09\n" +
      rows([](size_t i, double, double p, double n) {
        return std::to_string(i) + "," + num(p) + "," + num(n) + ",";
      });
  CsvColumns c;
  c.p = "CH1";
  c.n = "CH2";
  CaptureInfo info;
  expect_pass({write("NewFile1.csv", text)}, c, &info);
  EXPECT_EQ(info.layouts[0], "rigol start/increment");
  EXPECT_NE(info.time_from.find("Start + X * Increment"), std::string::npos);
}

TEST_F(Layout, RigolSiglentUnitsRowUnderSource) {
  const std::string text =
      "Source,CH1,CH2\nSecond,Volt,Volt\n" + rows([](size_t, double t, double p, double n) {
        return num(t) + "," + num(p) + "," + num(n);
      });
  CsvColumns c;
  c.p = "CH1";
  c.n = "CH2";
  CaptureInfo info;
  expect_pass({write("DS1000E.csv", text)}, c, &info);
  EXPECT_EQ(info.columns[0].name, "Source");  // time by its unit
  EXPECT_EQ(info.columns[0].unit, "Second");
  // units only, no names; the channel is in mV: scaled by 1e-3
  const std::string mv = "Second,mV\n" + rows([](size_t, double t, double p, double n) {
                           return num(t) + "," + num((p - n) * 1e3);
                         });
  CaptureInfo info2;
  expect_pass({write("siglent.csv", mv)}, {}, &info2);
  EXPECT_EQ(info2.layouts[0], "units row");
  EXPECT_EQ(info2.columns[1].unit, "mV");
  EXPECT_DOUBLE_EQ(info2.columns[1].scale, 1e-3);
}

TEST_F(Layout, RigolDs1052eQuotedPreambleAndTrailingCommas) {
  const std::string text =
      "\"Vertical Scale\",\"1.00V\"\n\"Sampling Rate\",\"500MSa/s\"\n\"Memory Depth\",\"16k\"\n"
      "\"Time (s)\",\"Voltage (V)\"\n" +
      rows([](size_t, double t, double p, double n) {
        return "\"" + num(t) + "\",\"" + num(p - n) + "\"";
      }) +
      ",,\n";
  CaptureInfo info;
  expect_pass({write("DS1052E.csv", text)}, {}, &info);
  EXPECT_EQ(info.columns[1].name, "Voltage (V)");
  EXPECT_EQ(info.columns[1].unit, "(V)");
}

// The DS1052E's full preamble, keys and order as the scope writes them (the real export
// tests/eye/data/real/DS1052E.csv, from RigolWFM tests/files/wfm/DS1052E.csv; SOURCES.md): the
// "Channel Data" row names the channels over a header that says only "Voltage (V)", and the
// "Attenuation" row gives each probe's factor. The values are probe-tip volts, in steps of the
// 8-bit count: Scale (V/DIV) x Attenuation / 25. `step_p` / `step_n` quantize P and N.
std::string ds1052e_text(const std::string& attenuation, double step_p, double step_n) {
  std::string s = "\"Number of Data points =\"," + std::to_string(record().samples()) +
                  ",\n\"Time Scale (s/DIV) =\",2E-6,\n\"Time Delay (s) =\",0,\n"
                  "\"Sampling Frequency (Hz)=\",500000000,\n\"Trigger Mode = \",0,\n"
                  "\"Trigger Source = \",1,\n\"Channel Data\",\"CH 1\",\"CH 2\"\n"
                  "\"Attenuation = \"," +
                  attenuation +
                  "\n\"Pos (V) = \",0,0\n\"PosOrig (V) = \",0,0\n"
                  "\"Scale (V/DIV) = \",0.2,0.2\n\"ScaleOrig (V) = \",0.2,0.2\n"
                  "\"Minimum (V) = \",1.52,1.52\n\"Maximum (V) = \",3.52,3.52\n"
                  "\"Inverted = \",\"NO\",\"NO\"\n\"Time (s)\",\"Voltage (V)\",\"Voltage (V)\"\n";
  s += rows([&](size_t, double t, double p, double n) {
    return num(t) + "," + num(step_p * std::round(p / step_p)) + "," +
           num(step_n * std::round(n / step_n));
  });
  return s + ",,\n";
}

TEST_F(Layout, RigolDs1052eChannelDataRowNamesTheChannels) {
  // 10X probes at 0.2 V/div: 0.08 V steps; P - N keeps its 2 V levels (25 steps)
  const std::string f = write("DS1052E.csv", ds1052e_text("10,10", 0.08, 0.08));
  CsvColumns c;
  c.p = "CH 1";
  c.n = "CH 2";
  CaptureInfo info;
  expect_pass({f}, c, &info, 1e-6);
  ASSERT_EQ(info.columns.size(), 3u);
  EXPECT_EQ(info.columns[1].name, "CH 1");
  EXPECT_EQ(info.columns[1].channel, "CH1");
  EXPECT_EQ(info.columns[1].index, 2u);
  EXPECT_EQ(info.columns[2].name, "CH 2");
  EXPECT_EQ(info.columns[2].index, 3u);
  // the record's edges move a leg 0.16 V a sample: its smallest step, 2 x 0.08 V
  const std::string note =
      "CH 1: probe attenuation 10X (line 8): the values are probe-tip volts as written (the "
      "smallest step between values, 0.16 V, is a multiple of 0.08 V = 0.2 V/div x 10 / 25)";
  EXPECT_NE(std::find(info.notes.begin(), info.notes.end(), note), info.notes.end())
      << fmt::format("{}", fmt::join(info.notes, "\n"));
  // the channel names as the other layouts take them
  c.p = "CH1";
  c.n = "2";
  expect_pass({f}, c, nullptr, 1e-6);
  // "1X" / "10X" as written by other firmware: CH 1 at 1X steps by 0.008 V
  CaptureInfo info2;
  c.p = "CH 1";
  c.n = "CH 2";
  expect_pass({write("DS1052E_x.csv", ds1052e_text("\"1X\",\"10X\"", 0.008, 0.08))}, c, &info2,
              0.03);
  EXPECT_EQ(info2.notes.size(), 2u) << fmt::format("{}", fmt::join(info2.notes, "\n"));
}

TEST_F(Layout, RigolDs1052eAttenuationContradictingTheDataIsRefused) {
  // the row says 10X, but CH 2 steps by 0.008 V = 0.2 V/div / 25: volts at the scope's input
  const std::string f = write("DS1052E.csv", ds1052e_text("10,10", 0.08, 0.008));
  CsvColumns c;
  c.p = "CH 1";
  c.n = "CH 2";
  StatusOr<Waveform> w = read_capture({f}, c);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(),
            f + ":8: error: CH 2: Attenuation 10X, so its values should step by 0.08 V (0.2 V/div "
                "x 10 / 25), but they step by 0.008 V, the scale without the probe: the file "
                "contradicts its data (volts at the scope's input, not at the probe tip?), so "
                "which volts it holds cannot be told; export it again from the scope");
  // a "Channel Data" row naming fewer channels than the data hold
  std::string text = ds1052e_text("10,10", 0.08, 0.08);
  const std::string row = "\"Channel Data\",\"CH 1\",\"CH 2\"";
  text.replace(text.find(row), row.size(), "\"Channel Data\",\"CH 1\"");
  w = read_capture({write("DS1052E_2.csv", text)}, c);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("DS1052E_2.csv:7: error: the \"Channel Data\" row names 1 "
                                      "channel but the data rows hold 2 value columns"),
            std::string::npos)
      << w.status().message();
}

TEST_F(Layout, RohdeSchwarzRtbOneChannelPerFile) {
  auto rtb = [](const char* name, bool p) {
    return std::string("in s,") + name + "\n" + rows([&](size_t, double t, double pv, double nv) {
             return num(t) + "," + num(p ? pv : nv);
           });
  };
  const std::string a = write("RTB_C1.csv", rtb("C1 in V", true));
  // the N file is sampled half a step later: N is interpolated onto P's time base
  const Waveform& w = record();
  std::string shifted = "in s,C2 in V\n";
  for (size_t i = 0; i + 1 < w.samples(); ++i) {
    const double t = w.time[i] + kDt / 2;
    const double v = 0.5 * (w.columns[0][i] + w.columns[0][i + 1]);  // linear between samples
    shifted += num(t) + "," + num(kCm - v / 2) + "\n";
  }
  const std::string b = write("RTB_C2.csv", shifted);
  CsvColumns c;
  c.p = "C1";
  c.n = "CH2";  // channel 2 by its canonical name
  CaptureInfo info;
  StatusOr<Waveform> r = read_capture({a, b}, c, &info);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(info.columns[2].how, "by channel CH2");
  EXPECT_NE(info.alignment.find("N interpolated onto P's samples"), std::string::npos);
  // inside the common span every P sample is kept but the first (before N's first sample)
  EXPECT_EQ(r->samples(), w.samples() - 2);
  StatusOr<CheckResult> chk = check_waveform(*r, *load_rules("bq7961x"));
  ASSERT_TRUE(chk.ok());
  EXPECT_TRUE(chk->pass) << summary_text(*chk);
  EXPECT_EQ(chk->bytes, kBytes);
  CaptureInfo same;
  expect_pass({a, write("RTB_C2b.csv", rtb("C2 in V", false))}, {}, &same);
}

TEST_F(Layout, PicoScopeUnitsRowAndFrenchLocale) {
  // "(us)" time, channel B in mV, ';' separators, decimal commas, a blank line before the data
  const std::string text =
      "Temps;Canal A;Canal B\n(us);(V);(mV)\n\n" + rows([](size_t, double t, double p, double n) {
        return num(t * 1e6, true) + ";" + num(p, true) + ";" + num(n * 1e3, true);
      });
  CsvColumns c;
  c.p = "Channel A";  // canonical CHA = "Canal A"
  c.n = "B";
  CaptureInfo info;
  expect_pass({write("pico.csv", text)}, c, &info);
  EXPECT_DOUBLE_EQ(info.columns[0].scale, 1e-6);
  EXPECT_DOUBLE_EQ(info.columns[2].scale, 1e-3);
  EXPECT_NEAR(info.t_end, record().time.back(), 1e-12);
  // tab separated with decimal commas, English names
  const std::string tab = "Time\tChannel A\tChannel B\n(ms)\t(V)\t(V)\n" +
                          rows([](size_t, double t, double p, double n) {
                            return num(t * 1e3, true) + "\t" + num(p, true) + "\t" + num(n, true);
                          });
  CaptureInfo info2;
  expect_pass({write("pico_tab.txt", tab)}, c, &info2);
  EXPECT_DOUBLE_EQ(info2.columns[0].scale, 1e-3);
}

TEST_F(Layout, SaleaeLogic2Analog) {
  const std::string text =
      "Time [s],Channel 0,Channel 1,Channel 2\n" + rows([](size_t, double t, double p, double n) {
        return num(t) + "," + num(p) + "," + num(n) + ",0.0";
      });
  CsvColumns c;
  c.p = "Channel 0";
  c.n = "CH1";
  CaptureInfo info;
  expect_pass({write("analog.csv", text)}, c, &info);
  EXPECT_EQ(info.columns[0].unit, "[s]");
}

TEST_F(Layout, BomCrOnlyBlankLinesAndFooter) {
  const std::string text = "\xEF\xBB\xBFTIME,CH1,CH2\r\r" +
                           rows([](size_t, double t, double p,
                                   double n) { return num(t) + "," + num(p) + "," + num(n); },
                                "\r") +
                           "\rEnd of data\r";
  CsvColumns c;
  c.p = "CH1";
  c.n = "CH2";
  CaptureInfo info;
  expect_pass({write("bom_cr.csv", text)}, c, &info);
  // data after a footer is refused with both lines named
  StatusOr<Waveform> w = parse_differential_csv("time,v\n0,0\n1,1\nEnd\n2,2\n", "f.csv");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(),
            "f.csv:5: error: data after line 4 ('End'), which is no data row: expected the data "
            "to end there (a footer) or to go on as numbers");
}

// ---- real exports (tests/eye/data/real/SOURCES.md) ----

struct RealCsv {
  const char* file;
  CsvColumns cols;
  const char* layout;
  size_t samples;
  double t0, dt;
  double first, last;  // volts, as the file's first and last data rows print them
};

TEST(RealCsvExports, ReadAsTheFilesPrintThemAndNeverPass) {
  auto diff = [](const char* c) {
    CsvColumns cols;
    cols.diff = c;
    return cols;
  };
  const RealCsv cases[] = {
      // Rigol DS1054Z: X,CH1..CH4,Start,Increment then Sequence,Volt..,-3e-07,5e-10
      {"DS1054Z-A.csv", {}, "rigol start/increment", 1200, -3e-7, 5e-10, 3.28, 4.08},
      {"DS1054Z-A.csv", diff("CH4"), "rigol start/increment", 1200, -3e-7, 5e-10, 0.0, -0.2},
      // Rigol DS1102E: X,CH1, then Second,Volt,
      {"DS1102E-B.csv", {}, "header + units row", 600, -5.9999998e-06, 2e-8, 4.40, -1.36},
      // Rigol DS1102D: X,CH 1 (V),CH 2 (V); no time unit (read as seconds, noted)
      {"DS1102D-A.csv", diff("CH2"), "header", 1024, -0.004688, 1.001e-5, 8.40, 0.16},
      // Rigol DS1052E: quoted preamble, "Time (s)","Voltage (V)","Voltage (V)", a ",," last line
      {"DS1052E.csv", {}, "header", 8192, 0.0, 2e-9, 1.72, -0.04},
      {"DS1052E.csv", diff("#3"), "header", 8192, 0.0, 2e-9, 9.92, 4.96},
      // the same by the names of its "Channel Data" row: CH 1 at 10X, CH 2 at 1X
      {"DS1052E.csv", diff("CH 2"), "header", 8192, 0.0, 2e-9, 9.92, 4.96},
      // R&S RTP: values only; the XML header rs_rtp_01.bin beside it gives XStart -2.5 ms and
      // Resolution 1.25 us (RigolWFM tests/test_rohde_schwarz.py: times[0] = -0.0025)
      {"rs_rtp_01.Wfm.csv", {}, "no header", 4000, -0.0025, 1.25e-6, -0.031620555, 1.027668},
  };
  for (const RealCsv& c : cases) {
    SCOPED_TRACE(fmt::format("{} {}", c.file, c.cols.diff));
    CaptureInfo info;
    StatusOr<Waveform> w = read_capture({real(c.file)}, c.cols, &info);
    ASSERT_TRUE(w.ok()) << w.status().message();
    EXPECT_EQ(info.layouts[0], c.layout);
    ASSERT_EQ(w->samples(), c.samples);
    EXPECT_NEAR(w->time.front(), c.t0, 1e-9 * std::abs(c.t0) + 1e-18);
    EXPECT_NEAR(info.interval, c.dt, 1e-4 * c.dt);
    EXPECT_NEAR(w->columns[0].front(), c.first, 1e-9);
    EXPECT_NEAR(w->columns[0].back(), c.last, 1e-9);
    StatusOr<CheckResult> r = check_waveform(*w, *load_rules("bq7961x"));
    ASSERT_TRUE(r.ok());
    EXPECT_FALSE(r->pass);
    EXPECT_TRUE(r->inconclusive) << summary_text(*r);
  }
  // DS1052E.csv's Attenuation row (10, 1) holds: CH 1 steps by 0.1 V/div x 10 / 25 = 0.04 V
  CsvColumns pn;
  pn.p = "CH 1";
  pn.n = "CH 2";
  CaptureInfo info;
  StatusOr<Waveform> w = read_capture({real("DS1052E.csv")}, pn, &info);
  ASSERT_TRUE(w.ok()) << w.status().message();
  EXPECT_NEAR(w->columns[0].front(), 1.72 - 9.92, 1e-9);
  const std::string want[] = {
      "CH 1: probe attenuation 10X (line 8): the values are probe-tip volts as written (the "
      "smallest step between values, 0.04 V, is a multiple of 0.04 V = 0.1 V/div x 10 / 25)",
      "CH 2: probe attenuation 1X (line 8): the values are probe-tip volts as written (the "
      "smallest step between values, 0.08 V, is a multiple of 0.08 V = 2 V/div x 1 / 25)"};
  for (const std::string& n : want)
    EXPECT_NE(std::find(info.notes.begin(), info.notes.end(), n), info.notes.end())
        << fmt::format("{}", fmt::join(info.notes, "\n"));
}

// ---- hazards ----

CheckResult check_text(const std::string& text, const CsvColumns& c = {}) {
  StatusOr<Waveform> w = parse_differential_csv(text, "h.csv", c);
  EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.status().message());
  StatusOr<CheckResult> r = check_waveform(*w, *load_rules("bq7961x"));
  EXPECT_TRUE(r.ok());
  return *r;
}

TEST(ScopeHazard, MillivoltsWithoutUnitsAreInconclusiveWithAHint) {
  // the column is in mV but nothing says so: 2000 "V" pulses
  const CheckResult r = check_text("time,CH1\n" + rows([](size_t, double t, double p, double n) {
                                     return num(t) + "," + num((p - n) * 1e3);
                                   }));
  EXPECT_FALSE(r.pass);
  EXPECT_TRUE(r.inconclusive);
  EXPECT_EQ(r.reasons[0], "levels up to 2000 V: no daisy-chain signal as read");
  ASSERT_FALSE(r.hints.empty());
  EXPECT_NE(r.hints[0].find("a column in mV read as volts?"), std::string::npos) << r.hints[0];
}

TEST(ScopeHazard, MicrosecondsWithoutUnitsAreInconclusive) {
  // time in us read as s: 250 ns half bits become 0.25 s pulses; nothing decodes
  const CheckResult r = check_text("time,CH1\n" + rows([](size_t, double t, double p, double n) {
                                     return num(t * 1e6) + "," + num(p - n);
                                   }));
  EXPECT_FALSE(r.pass);
  EXPECT_TRUE(r.inconclusive);
  EXPECT_STREQ(r.verdict(), "inconclusive");
  bool time_hint = false;
  for (const std::string& h : r.hints)
    time_hint = time_hint || h.find("time in us") != std::string::npos;
  EXPECT_TRUE(time_hint) << summary_text(r);
}

TEST(ScopeHazard, SwappedColumnsAreInconclusiveNotPass) {
  CsvColumns c;
  c.p = "CH2";
  c.n = "CH1";
  const CheckResult r =
      check_text("TIME,CH1,CH2\n" + rows([](size_t, double t, double p, double n) {
                   return num(t) + "," + num(p) + "," + num(n);
                 }),
                 c);
  EXPECT_FALSE(r.pass);
  EXPECT_TRUE(r.inconclusive);
  EXPECT_TRUE(r.bytes.empty());
  ASSERT_FALSE(r.hints.empty());
  EXPECT_NE(r.hints.back().find("decode with the signs flipped: P and N swapped"),
            std::string::npos)
      << r.hints.back();
}

TEST(ScopeHazard, FlatRecordIsInconclusive) {
  std::string text = "time,CH1\n";
  for (int i = 0; i < 1000; ++i) text += num(i * 1e-9) + "," + num(0.003 * (i % 2)) + "\n";
  const CheckResult r = check_text(text);
  EXPECT_FALSE(r.pass);
  EXPECT_TRUE(r.inconclusive);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons[0],
            "no pulses: nothing stays past +/-1.2 V for 100 ns (largest |v| 0.003 V)");
  ASSERT_EQ(r.hints.size(), 1u);
  EXPECT_NE(r.hints[0].find("1/100 of the threshold: the wrong column"), std::string::npos)
      << r.hints[0];
}

TEST(ScopeHazard, RecordCuttingAPulseIsInconclusive) {
  // the record starts inside the first frame's preamble: the other frame decodes, but no pass
  std::string text = "time,CH1\n";
  const Waveform& w = record();
  for (size_t i = 0; i < w.samples(); ++i)
    if (w.time[i] >= 1.1e-6) text += num(w.time[i]) + "," + num(w.columns[0][i]) + "\n";
  const CheckResult r = check_text(text);
  EXPECT_FALSE(r.pass);
  EXPECT_TRUE(r.inconclusive);
  EXPECT_EQ(r.bytes, std::vector<uint8_t>{0x15});
  ASSERT_EQ(r.reasons.size(), 1u);
  EXPECT_EQ(r.reasons[0].rfind("the record cuts 1 pulse (first: pulse 0 (+ at", 0), 0u)
      << r.reasons[0];
}

TEST(ScopeHazard, TenSecondPulsesInSevenRowsStayBounded) {
  // was 0.9 GB: every pulse's half-bit count was expanded; now capped at kMaxHalfBits
  const std::string text =
      "time,v\n0,0\n1e-9,2\n10,2\n10.000000001,-2\n20,-2\n20.000000001,0\n30,0\n";
  const CheckResult r = check_text(text);
  EXPECT_FALSE(r.pass);
  ASSERT_EQ(r.pulses.size(), 2u);
  for (const PulseMetrics& p : r.pulses) EXPECT_EQ(p.half_bits, kMaxHalfBits);
  EXPECT_EQ(r.pulses[0].k, 40000000);  // the class is still reported as measured
}

TEST(ScopeHazard, ColumnChoicesRefused) {
  const std::string text = "TIME,CH1,CH2\n0,0,0\n1e-9,1,0\n2e-9,0,1\n";
  CsvColumns c;
  c.p = "CH1";
  c.n = "1";  // channel 1 again
  StatusOr<Waveform> w = parse_differential_csv(text, "c.csv", c);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(),
            "c.csv:1: error: P and N are both column 2 ('CH1'): P - N would be zero; choose two "
            "different columns");
  c.n = "TIME";
  w = parse_differential_csv(text, "c.csv", c);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(),
            "c.csv:1: error: N column 'TIME' is column 1 ('TIME'), a time column: choose a signal "
            "column");
  // an overrange marker (Tektronix 9.9E37) is refused, not scored
  w = parse_differential_csv("time,v\n0,0\n1e-9,9.9E37\n", "o.csv");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(),
            "o.csv:3: error: field 2: 9.9E37 is the scope's overrange marker: the channel "
            "clipped; capture again with more volts/div");
  w = parse_differential_csv("Model,X\nSerial,1\n", "m.csv");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().message(),
            "m.csv:2: error: no data found: expected rows of numbers (e.g. \"-1.0e-06,0.52\"), "
            "optionally under a line of names (e.g. \"TIME,CH1,CH2\") and a units row (e.g. "
            "\"s,V,V\"); the last line read was 'Serial,1'");
}

}  // namespace
}  // namespace isolink::eye
