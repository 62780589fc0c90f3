// results.csv rows, scoring a run, summary.json and the resume log, without simulating.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "analysis/sweep_run.h"
#include "analysis/sweep_spec.h"
#include "reports/sweep_report.h"

namespace isolink::analysis::sweep {
namespace {

const std::string kSweep = R"(base:
  tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
  rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
  cable: {length: 1}
sweep:
  cable.length: [1, 2, 5, 10]
  rx.isolation.cap: [1n, 4.7n]
)";

SweepSpec spec() {
  StatusOr<SweepSpec> s = read_sweep_text(kSweep, "sweep.yaml");
  if (!s) ADD_FAILURE() << s.status().message();
  return s ? *s : SweepSpec{};
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "isolink_sweep_results_" + name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

PointResult result(size_t index, const SweepSpec& s, const std::string& verdict, double rel) {
  PointResult r;
  r.index = index;
  r.cells = make_point(s, index).point.cells;
  r.verdict = verdict;
  r.worst_metric = verdict == "error" ? "" : "vstart";
  r.worst_rel = verdict == "error" ? NAN : rel;
  if (verdict != "error") r.margin = {rel * 1.6, 0.5, 20e-9, 30e-9};
  if (verdict != "error") r.decoded_ok = verdict == "pass";
  if (verdict != "error") r.path = "edges";
  r.seconds = 1.25;
  if (verdict == "error") r.error = "link.yaml:3:5: error: unknown part 'X, \"Y\"'";
  return r;
}

TEST(SweepResults, HeaderAndRowRoundTrip) {
  const SweepSpec s = spec();
  const std::vector<std::string> h = results_header(s);
  const RowShape shape = row_shape(s);
  EXPECT_EQ(shape.columns(), h.size());
  EXPECT_EQ(h, (std::vector<std::string>{"point", "cable.length", "rx.isolation.cap", "verdict",
                                         "worst_metric", "worst_margin_rel", "margin_vstart_V",
                                         "margin_vend_V", "margin_width_ns", "margin_edge_ns",
                                         "decoded_ok", "fail_reason", "seconds", "error", "path"}));
  PointResult r = result(3, s, "fail", -0.0123456789);
  r.reason = "vstart; decode: weak bit";
  const std::string row = results_row(r);
  EXPECT_EQ(row,
            "3,2,4.7e-09,fail,vstart,-0.0123457,-0.0197531,0.5,20,30,false,vstart; decode: "
            "weak bit,1.25,,edges\n");
  StatusOr<PointResult> back = parse_results_row(row.substr(0, row.size() - 1), shape);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->index, 3u);
  EXPECT_EQ(back->cells, (std::vector<std::string>{"2", "4.7e-09"}));
  EXPECT_EQ(back->verdict, "fail");
  EXPECT_DOUBLE_EQ(back->worst_rel, -0.0123457);
  EXPECT_DOUBLE_EQ(back->margin[2], 20e-9);
  EXPECT_EQ(back->decoded_ok, std::optional<bool>(false));
  EXPECT_EQ(back->reason, "vstart; decode: weak bit");
  EXPECT_EQ(back->path, "edges");
  EXPECT_EQ(results_row(*back), row);  // a fixed point
  // An error row: CSV-quoted message, empty margins.
  const PointResult e = result(5, s, "error", 0);
  const std::string erow = results_row(e);
  EXPECT_EQ(erow,
            "5,5,4.7e-09,error,,,,,,,,,1.25,\"link.yaml:3:5: error: unknown part 'X, "
            "\"\"Y\"\"'\",\n");
  StatusOr<PointResult> eback = parse_results_row(erow.substr(0, erow.size() - 1), shape);
  ASSERT_TRUE(eback.ok()) << eback.status().message();
  EXPECT_EQ(eback->error, e.error);
  EXPECT_TRUE(std::isnan(eback->worst_rel));
  EXPECT_FALSE(eback->decoded_ok.has_value());
  // Malformed rows.
  EXPECT_FALSE(parse_results_row("3,2,4.7e-09,fail", shape).ok());
  EXPECT_FALSE(parse_results_row("x,2,4.7e-09,fail,,,,,,,,,1,,", shape).ok());
  EXPECT_FALSE(parse_results_row("3,2,4.7e-09,maybe,,,,,,,,,1,,", shape).ok());
  EXPECT_EQ(split_csv_line("a,\"b,c\",,\"d\"\"e\""),
            (std::vector<std::string>{"a", "b,c", "", "d\"e"}));
}

// With `outputs: [noise]` the noise columns sit between fail_reason and seconds; an error row
// has them empty; rows read back to the same numbers (6 digits).
TEST(SweepResults, NoiseColumnsRoundTrip) {
  StatusOr<SweepSpec> ns = read_sweep_text(kSweep + "outputs: [noise]\n", "sweep.yaml");
  ASSERT_TRUE(ns.ok()) << ns.status().message();
  const std::vector<std::string> h = results_header(*ns);
  const RowShape shape = row_shape(*ns);
  EXPECT_EQ(shape.columns(), h.size());
  EXPECT_EQ(h, (std::vector<std::string>{"point",
                                         "cable.length",
                                         "rx.isolation.cap",
                                         "verdict",
                                         "worst_metric",
                                         "worst_margin_rel",
                                         "margin_vstart_V",
                                         "margin_vend_V",
                                         "margin_width_ns",
                                         "margin_edge_ns",
                                         "decoded_ok",
                                         "fail_reason",
                                         "noise.verdict",
                                         "noise.immunity_min_db",
                                         "noise.down.immunity_min",
                                         "noise.down.immunity_min_db",
                                         "noise.down.freq_hz",
                                         "noise.up.immunity_min",
                                         "noise.up.immunity_min_db",
                                         "noise.up.freq_hz",
                                         "seconds",
                                         "error",
                                         "path"}));
  PointResult r = result(3, *ns, "pass", 0.25);
  PointResult::Noise n;
  n.verdict = "fail";
  n.immunity_min_db = -13.59751836;
  n.immunity_min[0] = 0.0208989315;
  n.immunity_min_db_dir[0] = -13.59751836;
  n.freq_hz[0] = 8852367.9;
  r.noise = n;
  const std::string row = results_row(r);
  EXPECT_EQ(row,
            "3,2,4.7e-09,pass,vstart,0.25,0.4,0.5,20,30,true,,fail,-13.5975,0.0208989,-13.5975,"
            "8.85237e+06,,,,1.25,,edges\n");
  StatusOr<PointResult> back = parse_results_row(row.substr(0, row.size() - 1), shape);
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_TRUE(back->noise.has_value());
  EXPECT_EQ(back->noise->verdict, "fail");
  EXPECT_DOUBLE_EQ(back->noise->immunity_min[0], 0.0208989);
  EXPECT_DOUBLE_EQ(back->noise->freq_hz[0], 8.85237e6);
  EXPECT_TRUE(std::isnan(back->noise->immunity_min[1]));
  EXPECT_EQ(results_row(*back), row);
  PointResult e = result(5, *ns, "error", 0);
  e.noise.emplace();
  const std::string erow = results_row(e);
  EXPECT_NE(erow.find(",error,,,,,,,,,,,,,,,,,1.25,"), std::string::npos) << erow;
  EXPECT_TRUE(parse_results_row(erow.substr(0, erow.size() - 1), shape).ok());
  // A bad noise verdict is refused.
  EXPECT_FALSE(parse_results_row("3,2,4.7e-09,pass,,,,,,,,,maybe,,,,,,,,1,,", shape).ok());
  // A sweep without the family has no such columns (and reads no such row).
  EXPECT_EQ(results_header(spec()).size() + 8, h.size());
}

// With `outputs: [noise, worst]` the worst.* columns follow the noise columns; rows read back to
// the same numbers (6 digits, widths and edges in ns); an error row has them empty.
TEST(SweepResults, WorstColumnsRoundTrip) {
  StatusOr<SweepSpec> ws = read_sweep_text(kSweep + "outputs: [noise, worst]\n", "sweep.yaml");
  ASSERT_TRUE(ws.ok()) << ws.status().message();
  const std::vector<std::string> h = results_header(*ws);
  const RowShape shape = row_shape(*ws);
  EXPECT_EQ(shape.columns(), h.size());
  ASSERT_EQ(h.size(), 15u + 8u + 13u);
  EXPECT_EQ(h[11], "fail_reason");
  EXPECT_EQ(h[12], "noise.verdict");
  EXPECT_EQ(
      std::vector<std::string>(h.begin() + 20, h.end()),
      (std::vector<std::string>{
          "worst.verdict", "worst.worst_metric", "worst.margin_rel", "worst.down.vstart_margin_V",
          "worst.down.vend_margin_V", "worst.down.width_min_margin_ns",
          "worst.down.width_max_margin_ns", "worst.down.edge_margin_ns", "worst.up.vstart_margin_V",
          "worst.up.vend_margin_V", "worst.up.width_min_margin_ns", "worst.up.width_max_margin_ns",
          "worst.up.edge_margin_ns", "seconds", "error", "path"}));
  // Worst alone: 13 columns more than the plain sweep, in the same place.
  StatusOr<SweepSpec> wo = read_sweep_text(kSweep + "outputs: [worst]\n", "sweep.yaml");
  ASSERT_TRUE(wo.ok()) << wo.status().message();
  EXPECT_EQ(results_header(*wo).size(), results_header(spec()).size() + 13);
  EXPECT_EQ(results_header(*wo)[12], "worst.verdict");

  PointResult r = result(3, *wo, "pass", 0.25);
  PointResult::Worst w;
  w.verdict = "fail";
  w.worst_metric = "width_min";
  w.margin_rel = -10e-9 / 280e-9;
  w.margin[0] = {0.4, 0.3, -10e-9, 200.00004e-9, 15e-9};
  r.worst = w;
  const std::string row = results_row(r);
  EXPECT_EQ(row,
            "3,2,4.7e-09,pass,vstart,0.25,0.4,0.5,20,30,true,,fail,width_min,-0.0357143,0.4,0.3,"
            "-10,200,15,,,,,,1.25,,edges\n");
  StatusOr<PointResult> back = parse_results_row(row.substr(0, row.size() - 1), row_shape(*wo));
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_TRUE(back->worst.has_value());
  EXPECT_FALSE(back->noise.has_value());
  EXPECT_EQ(back->verdict, "pass");  // the spec traffic's, apart from worst.verdict
  EXPECT_EQ(back->worst->verdict, "fail");
  EXPECT_EQ(back->worst->worst_metric, "width_min");
  EXPECT_DOUBLE_EQ(back->worst->margin_rel, -0.0357143);
  EXPECT_DOUBLE_EQ(back->worst->margin[0][2], -10e-9);
  EXPECT_DOUBLE_EQ(back->worst->margin[0][3], 200e-9);
  EXPECT_TRUE(std::isnan(back->worst->margin[1][0]));
  EXPECT_EQ(results_row(*back), row);
  // An error row: every worst cell empty.
  PointResult e = result(5, *wo, "error", 0);
  e.worst.emplace();
  const std::string erow = results_row(e);
  EXPECT_NE(erow.find(",error,,,,,,,,,,,,,,,,,,,,,,1.25,"), std::string::npos) << erow;
  EXPECT_TRUE(parse_results_row(erow.substr(0, erow.size() - 1), row_shape(*wo)).ok());
  // A bad worst.verdict or worst.worst_metric is refused.
  std::string bad = row;
  bad.replace(bad.find(",fail,width_min,"), 16, ",maybe,width_min,");
  EXPECT_FALSE(parse_results_row(bad.substr(0, bad.size() - 1), row_shape(*wo)).ok());
  bad = row;
  bad.replace(bad.find(",fail,width_min,"), 16, ",fail,width,");
  EXPECT_FALSE(parse_results_row(bad.substr(0, bad.size() - 1), row_shape(*wo)).ok());
}

// --resume reads rows with the worst.* columns back (the points are skipped, their numbers kept);
// a row added without them (a point that failed early) is padded with empty cells.
TEST(SweepResults, ResumeReadsTheWorstColumns) {
  StatusOr<SweepSpec> ws = read_sweep_text(kSweep + "outputs: [worst]\n", "sweep.yaml");
  ASSERT_TRUE(ws.ok()) << ws.status().message();
  const std::string dir = temp_dir("resume_worst");
  std::string header;
  for (const std::string& h : results_header(*ws)) header += (header.empty() ? "" : ",") + h;
  PointResult r2 = result(2, *ws, "pass", 0.2), r6 = result(6, *ws, "fail", -0.1);
  r2.worst.emplace();
  r2.worst->verdict = "fail";
  r2.worst->worst_metric = "vend";
  r2.worst->margin_rel = -0.05;
  r2.worst->margin[0] = {0.2, -0.06, 30e-9, 100e-9, 20e-9};
  r6.worst.emplace();
  r6.worst->verdict = "pass";
  r6.worst->worst_metric = "edge";
  r6.worst->margin_rel = 0.1;
  r6.worst->margin[0] = {0.5, 0.4, 60e-9, 150e-9, 6e-9};
  const std::string row2 = results_row(r2), row6 = results_row(r6);
  {
    std::ofstream out(dir + "/results.csv");
    out << header << "\n" << row2 << row6;
  }
  SweepOptions opt;
  opt.out_dir = dir;
  opt.resume = true;
  opt.quiet = true;
  {
    StatusOr<std::unique_ptr<ResultLog>> log = ResultLog::open(*ws, opt);
    ASSERT_TRUE(log.ok()) << log.status().message();
    EXPECT_EQ((*log)->skipped(), 2u);
    EXPECT_EQ((*log)->todo(), (std::vector<size_t>{0, 1, 3, 4, 5, 7}));
    const std::vector<PointResult> kept = (*log)->results();
    ASSERT_EQ(kept.size(), 2u);
    ASSERT_TRUE(kept[0].worst.has_value());
    EXPECT_EQ(kept[0].worst->verdict, "fail");
    EXPECT_DOUBLE_EQ(kept[0].worst->margin[0][1], -0.06);
    EXPECT_DOUBLE_EQ(kept[1].worst->margin[0][4], 6e-9);
    (*log)->add(result(4, *ws, "error", 0));  // no worst cells: padded
    EXPECT_TRUE((*log)->results()[1].worst.has_value());
    // summary.json: the worst-case verdicts and the point with the smallest worst.margin_rel.
    const nlohmann::ordered_json j = reports::sweep_summary_json(*ws, (*log)->results());
    EXPECT_EQ(j["worst_case"]["pass"], 1);
    EXPECT_EQ(j["worst_case"]["fail"], 1);
    EXPECT_EQ(j["worst_case"]["worst"]["point"], 2);
    EXPECT_EQ(j["worst_case"]["worst"]["worst_metric"], "vend");
    EXPECT_DOUBLE_EQ(j["worst_case"]["worst"]["margin_rel"].get<double>(), -0.05);
    EXPECT_EQ(j["worst"]["point"], 6);  // the spec traffic's worst point is another
    EXPECT_FALSE(reports::sweep_summary_json(spec(), (*log)->results()).contains("worst_case"));
  }
  const std::string all = slurp(dir + "/results.csv");
  EXPECT_NE(all.find("\n4,5,1e-09,error,,,,,,,,,,,,,,,,,,,,,,"), std::string::npos) << all;
}

eye::WorstMargin wm(const std::string& metric, double value, double limit, double margin) {
  eye::WorstMargin w;
  w.metric = metric;
  w.j.value = value;
  w.j.limit = limit;
  w.j.margin = margin;
  return w;
}

TEST(SweepResults, ScoreTakesTheWorstOverDirectionsAndChecks) {
  LinkRun run;
  run.pass = false;
  DirectionRun down, up;
  eye::CheckResult a;
  a.pass = true;
  a.worst = {wm("vstart", 2.0, 1.6, 0.4), wm("vend", 1.5, 1.2, 0.3),
             wm("width", 270e-9, 280e-9, 10e-9), wm("droop", 0.5, 1.0, 0.5)};
  a.frames.resize(1);
  a.pulses.resize(1);
  down.data = a;
  eye::CheckResult b = a;
  b.pass = false;
  b.worst = {wm("vstart", 1.7, 1.6, 0.1), wm("edge", 50e-9, 60e-9, 10e-9)};
  b.pulses[0].fails = {"dip: 3.0 ns below 1.20 V"};
  b.frames[0].fault = "weak bit";
  up.data = b;
  eye::CheckResult t;
  t.tone = true;
  t.pass = true;
  t.worst = {wm("width", 1.05e-6, 1.08e-6, 30e-9)};
  up.tones = t;
  run.directions = {down, up};
  const PointResult r = score_run(run);
  EXPECT_EQ(r.verdict, "fail");
  EXPECT_DOUBLE_EQ(r.margin[0], 0.1);    // vstart: up
  EXPECT_DOUBLE_EQ(r.margin[1], 0.3);    // vend: down
  EXPECT_DOUBLE_EQ(r.margin[2], 10e-9);  // width: data, not the tone's 30 ns
  EXPECT_DOUBLE_EQ(r.margin[3], 10e-9);  // edge
  // Relative: vstart 0.1/1.6 = 0.0625, vend 0.25, width 10/280 = 0.0357, edge 10/60.
  EXPECT_EQ(r.worst_metric, "width");
  EXPECT_DOUBLE_EQ(r.worst_rel, 10e-9 / 280e-9);
  EXPECT_EQ(r.decoded_ok, std::optional<bool>(false));
  EXPECT_EQ(r.reason, "dip; decode: weak bit");
  // Nothing judged on a failing run: -1, "none".
  LinkRun dead;
  DirectionRun d;
  eye::CheckResult empty;
  empty.pass = false;
  d.data = empty;
  dead.directions = {d};
  const PointResult z = score_run(dead);
  EXPECT_EQ(z.worst_metric, "none");
  EXPECT_DOUBLE_EQ(z.worst_rel, -1.0);
  EXPECT_EQ(z.reason, "no signal");
  EXPECT_EQ(z.decoded_ok, std::optional<bool>(false));
}

TEST(SweepResults, SummaryCountsYieldAndBoundary) {
  const SweepSpec s = spec();
  // cap 1n passes up to 5 m (margin 0.1 at 5, -0.1 at 10: crossing 7.5 m); 4.7n up to 2 m.
  const double m1[4] = {0.3, 0.2, 0.1, -0.1}, m2[4] = {0.2, 0.05, -0.05, -0.2};
  std::vector<PointResult> rs;
  for (size_t i = 0; i < 4; ++i) {
    rs.push_back(result(2 * i, s, m1[i] >= 0 ? "pass" : "fail", m1[i]));
    if (i != 3) rs.push_back(result(2 * i + 1, s, m2[i] >= 0 ? "pass" : "fail", m2[i]));
  }
  rs.push_back(result(7, s, "error", 0));
  const nlohmann::ordered_json j = reports::sweep_summary_json(s, rs);
  EXPECT_EQ(j["points"], 8);
  EXPECT_EQ(j["done"], 8);
  EXPECT_EQ(j["pass"], 5);
  EXPECT_EQ(j["fail"], 2);
  EXPECT_EQ(j["error"], 1);
  EXPECT_DOUBLE_EQ(j["pass_yield"].get<double>(), 5.0 / 8.0);
  EXPECT_EQ(j["worst"]["point"], 6);
  EXPECT_EQ(j["worst"]["cable.length"], "10");
  EXPECT_DOUBLE_EQ(j["worst"]["worst_margin_rel"].get<double>(), -0.1);
  const auto& along = j["boundary"]["along"];
  EXPECT_EQ(j["boundary"]["axis"], "cable.length");
  ASSERT_EQ(along.size(), 2u);
  EXPECT_EQ(along[0]["at"]["rx.isolation.cap"], "1e-09");
  EXPECT_EQ(along[0]["pass"], nlohmann::ordered_json({"1", "2", "5"}));
  ASSERT_EQ(along[0]["transitions"].size(), 1u);
  EXPECT_EQ(along[0]["transitions"][0]["from"], "5");
  EXPECT_EQ(along[0]["transitions"][0]["to"], "10");
  EXPECT_DOUBLE_EQ(along[0]["transitions"][0]["margin_crossing"].get<double>(), 7.5);
  // 4.7n: pass at 1, 2; fail at 5 (crossing 2 + 3 * 0.05 / 0.1 = 3.5); error at 10.
  ASSERT_EQ(along[1]["transitions"].size(), 2u);
  EXPECT_DOUBLE_EQ(along[1]["transitions"][0]["margin_crossing"].get<double>(), 3.5);
  EXPECT_EQ(along[1]["transitions"][1]["to_verdict"], "error");
  EXPECT_TRUE(along[1]["transitions"][1]["margin_crossing"].is_null());
}

TEST(SweepResults, ResumeKeepsGoodRowsAndDropsACutRow) {
  const SweepSpec s = spec();
  const std::string dir = temp_dir("resume");
  std::string header;
  for (const std::string& h : results_header(s)) header += (header.empty() ? "" : ",") + h;
  const std::string row2 = results_row(result(2, s, "pass", 0.2));
  const std::string row6 = results_row(result(6, s, "fail", -0.1));
  {
    std::ofstream out(dir + "/results.csv");
    out << header << "\n" << row2 << row6 << "4,5,1e-09,pa";  // the last row was cut short
  }
  SweepOptions opt;
  opt.out_dir = dir;
  opt.resume = true;
  opt.quiet = true;
  {
    StatusOr<std::unique_ptr<ResultLog>> log = ResultLog::open(s, opt);
    ASSERT_TRUE(log.ok()) << log.status().message();
    EXPECT_EQ((*log)->skipped(), 2u);
    EXPECT_EQ((*log)->todo(), (std::vector<size_t>{0, 1, 3, 4, 5, 7}));
    EXPECT_EQ(slurp(dir + "/results.csv"), header + "\n" + row2 + row6);
    (*log)->add(result(4, s, "pass", 0.05));
    (*log)->add(result(4, s, "pass", 0.05));  // a second time: ignored
    EXPECT_EQ((*log)->results().size(), 3u);
    EXPECT_EQ((*log)->results()[1].index, 4u);  // by index
  }
  EXPECT_EQ(slurp(dir + "/results.csv"),
            header + "\n" + row2 + row6 + results_row(result(4, s, "pass", 0.05)));
  // A row whose values are not this sweep's point is refused.
  {
    std::ofstream out(dir + "/results.csv");
    out << header << "\n"
        << "2,7,1e-09,pass,vstart,0.2,0.32,0.5,20,30,true,,1.25,,edges\n";
  }
  StatusOr<std::unique_ptr<ResultLog>> changed = ResultLog::open(s, opt);
  ASSERT_FALSE(changed.ok());
  EXPECT_NE(changed.status().message().find(
                "results.csv:2: error: --resume: point 2 is 2,1e-09 in this sweep but 7,1e-09 in "
                "the file"),
            std::string::npos)
      << changed.status().message();
  // Without --resume the file starts again.
  opt.resume = false;
  {
    StatusOr<std::unique_ptr<ResultLog>> log = ResultLog::open(s, opt);
    ASSERT_TRUE(log.ok());
    EXPECT_EQ((*log)->todo().size(), 8u);
  }
  EXPECT_EQ(slurp(dir + "/results.csv"), header + "\n");
  // Another sweep's file is refused.
  {
    std::ofstream out(dir + "/results.csv");
    out << "point,cable.length,verdict\n0,1,pass\n";
  }
  opt.resume = true;
  StatusOr<std::unique_ptr<ResultLog>> bad = ResultLog::open(s, opt);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("results.csv:1: error: --resume: the columns differ"),
            std::string::npos)
      << bad.status().message();
}

}  // namespace
}  // namespace isolink::analysis::sweep
