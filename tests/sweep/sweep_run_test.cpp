// Small real sweeps through the isolink binary (short links, one frame, one direction): rows and
// columns of results.csv, verdicts equal to `isolink run` on the same spec, a point that cannot
// run, --resume, Monte Carlo, and the MPI run with 2 ranks against the threaded one. Every test
// here simulates: the names carry "Sim" (ctest label sweep-sim).
#include "analysis/sweep_run.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/noise.h"
#include "analysis/sweep_spec.h"
#include "analysis/worst.h"
#include "netlists/link/parts.h"

namespace isolink::analysis::sweep {
namespace {

namespace fs = std::filesystem;

const std::string kBinary = ISOLINK_BINARY;
const std::string kMpiexec = ISOLINK_MPIEXEC;

std::string fmt_length(double l) {
  std::ostringstream o;
  o << l;
  return o.str();
}

// A capacitor link with one short frame, down only.
std::string cap_link(double length) {
  return "name: t\n"
         "tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}\n"
         "rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}\n"
         "cable: {length: " +
         fmt_length(length) +
         ", material: pp}\n"
         "stimulus: {frames: [\"single-read dev=1 reg=0x0215 n=1\"], direction: down}\n";
}

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "isolink_sweep_run_" + name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs a shell command; its exit status.
int run(const std::string& cmd) {
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // sorted by point
  size_t col(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name;
    return static_cast<size_t>(it - header.begin());
  }
};

Csv read_csv(const std::string& path) {
  Csv c;
  std::ifstream in(path);
  std::string line;
  if (std::getline(in, line)) c.header = split_csv_line(line);
  while (std::getline(in, line))
    if (!line.empty()) c.rows.push_back(split_csv_line(line));
  std::sort(c.rows.begin(), c.rows.end(),
            [](const auto& a, const auto& b) { return std::stoul(a[0]) < std::stoul(b[0]); });
  return c;
}

TEST(SweepSim, ResultsMatchIsolinkRunPointByPoint) {
  const std::string dir = temp_dir("match");
  write(dir + "/link.yaml", cap_link(1));
  write(dir + "/sweep.yaml", "base: link.yaml\nsweep:\n  cable.length: [0.5, 1, 2]\n");
  const int rc = run(kBinary + " sweep " + dir + "/sweep.yaml -o " + dir + "/out -j 2 -q");
  const Csv csv = read_csv(dir + "/out/results.csv");
  EXPECT_EQ(csv.header, (std::vector<std::string>{
                            "point", "cable.length", "verdict", "worst_metric", "worst_margin_rel",
                            "margin_vstart_V", "margin_vend_V", "margin_width_ns", "margin_edge_ns",
                            "decoded_ok", "fail_reason", "seconds", "error", "path"}));
  ASSERT_EQ(csv.rows.size(), 3u);
  const std::vector<std::string> lengths = {"0.5", "1", "2"};
  bool all_pass = true;
  for (size_t i = 0; i < 3; ++i) {
    const std::vector<std::string>& r = csv.rows[i];
    ASSERT_EQ(r.size(), csv.header.size());
    EXPECT_EQ(r[0], std::to_string(i));
    EXPECT_EQ(r[1], lengths[i]);
    EXPECT_EQ(r[csv.col("error")], "");
    // The same spec through `isolink run`.
    const std::string spec = dir + "/point" + std::to_string(i) + ".yaml";
    write(spec, cap_link(std::stod(lengths[i])));
    const std::string rdir = dir + "/run" + std::to_string(i);
    const int rrc = run(kBinary + " run " + spec + " -o " + rdir + " --no-images -q");
    ASSERT_TRUE(rrc == 0 || rrc == 1) << rrc;
    EXPECT_EQ(r[csv.col("verdict")], rrc == 0 ? "pass" : "fail") << "point " << i;
    all_pass = all_pass && rrc == 0;
    const nlohmann::json rep = nlohmann::json::parse(slurp(rdir + "/report.json"));
    const nlohmann::json& worst = rep["directions"][0]["check"]["summary"]["worst"];
    // The sweep's fast path (path "edges") against `isolink run`'s simulation: within the
    // fast path's guarantee, 1 mV and 25 ps (analysis/README.md).
    EXPECT_EQ(r[csv.col("path")], "edges") << "point " << i;
    EXPECT_NEAR(std::stod(r[csv.col("margin_vstart_V")]), worst["vstart"]["margin"].get<double>(),
                1e-3)
        << "point " << i;
    EXPECT_NEAR(std::stod(r[csv.col("margin_width_ns")]), worst["width"]["margin"].get<double>(),
                0.025)
        << "point " << i;
    EXPECT_EQ(r[csv.col("decoded_ok")],
              rep["directions"][0]["check"]["verdict"] == "pass" ? "true" : "false");
  }
  EXPECT_EQ(rc, all_pass ? 0 : 1);
  const nlohmann::json sum = nlohmann::json::parse(slurp(dir + "/out/summary.json"));
  EXPECT_EQ(sum["points"], 3);
  EXPECT_EQ(sum["done"], 3);
  EXPECT_EQ(sum["pass"].get<int>() + sum["fail"].get<int>(), 3);
  EXPECT_TRUE(fs::exists(dir + "/out/sweep_margin.png"));
  EXPECT_FALSE(fs::exists(dir + "/out/sweep_heatmap.png"));  // one axis
}

// `outputs: [noise]`: each point's noise columns are exactly what run_noise (the work of
// `isolink noise`) gives for that point's spec, in both directions; the row carries them.
TEST(SweepSim, NoiseColumnsEqualRunNoiseOnThePointsSpec) {
  const std::string text = R"(base:
  name: t
  tx: {device: bq7961x}
  rx: {device: bq7961x}
  cable: {length: 1, material: pp}
  stimulus: {frames: ["single-read dev=1 reg=0x0215 n=1"]}
  noise: {level: 10m, points_per_decade: 4, time_domain: false}
outputs: [noise]
sweep:
  choke:
    none: {ends.isolation: {type: cap, cap: 2.2n}}
    ACT45B-510: {ends.isolation: {type: capchoke, cap: 2.2n, chokes: [ACT45B-510-2P-TL003]}}
)";
  StatusOr<SweepSpec> s = read_sweep_text(text, "sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  const RowShape shape = row_shape(*s);
  for (size_t i = 0; i < s->size(); ++i) {
    const PointResult r = run_point(*s, *parts, i, {});
    ASSERT_EQ(r.verdict == "error", false) << r.error;
    ASSERT_TRUE(r.noise.has_value());
    const PointOutcome po = make_point(*s, i);
    ASSERT_TRUE(po.status.ok());
    StatusOr<NoiseRun> direct = run_noise(po.point.spec, *parts);
    ASSERT_TRUE(direct.ok()) << direct.status().message();
    const NoiseResult& n = direct->noise;
    ASSERT_EQ(n.directions.size(), 2u);
    // The sweep takes the fast path (the waveform and pins superposed from edge responses),
    // run_noise simulates: the receiver budget moves by at most 1 mV (or 25 ps of slope), a
    // fraction of a percent of these budgets, so the immunity agrees within 1 % (0.09 dB).
    EXPECT_EQ(r.path, "edges");
    EXPECT_EQ(r.noise->verdict, n.pass ? "pass" : "fail");
    EXPECT_NEAR(r.noise->immunity_min_db, noise_immunity_min_db(n), 0.09);
    for (const NoiseDirection& d : n.directions) {
      const size_t k = d.direction == link::Direction::kDown ? 0 : 1;
      EXPECT_NEAR(r.noise->immunity_min[k], d.immunity_min, 0.01 * d.immunity_min)
          << "point " << i << " dir " << k;
      EXPECT_EQ(r.noise->freq_hz[k], d.immunity_min_freq) << "point " << i << " dir " << k;
      EXPECT_NEAR(r.noise->immunity_min_db_dir[k], 20 * std::log10(d.immunity_min / 10e-3), 0.09);
      EXPECT_GT(d.immunity_min, 0.0);
    }
    // The overall figure is the weaker direction's.
    EXPECT_DOUBLE_EQ(r.noise->immunity_min_db,
                     std::min(r.noise->immunity_min_db_dir[0], r.noise->immunity_min_db_dir[1]));
    // The link's own columns are run_link's, as without the noise family.
    EXPECT_EQ(r.verdict, direct->run.pass ? "pass" : "fail");
    // Through the CSV: 6 significant digits.
    const std::string row = results_row(r);
    StatusOr<PointResult> back = parse_results_row(row.substr(0, row.size() - 1), shape);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_NEAR(back->noise->immunity_min[0], r.noise->immunity_min[0],
                1e-5 * r.noise->immunity_min[0]);
  }
}

// `outputs: [worst]`: each point's worst.* columns are what worst_case (the work of `isolink
// worst`, default options) gives for that point's spec; `verdict` stays run_link's on the spec's
// traffic; the row carries both to 6 digits.
TEST(SweepSim, WorstColumnsEqualWorstCaseOnThePointsSpec) {
  const std::string text = "base: link.yaml\nsweep:\n  cable.length: [1, 4]\noutputs: [worst]\n";
  const std::string dir = temp_dir("worst");
  write(dir + "/link.yaml", cap_link(1));
  write(dir + "/sweep.yaml", text);
  StatusOr<SweepSpec> s = read_sweep_file(dir + "/sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  const RowShape shape = row_shape(*s);
  for (size_t i = 0; i < s->size(); ++i) {
    const PointResult r = run_point(*s, *parts, i, {});
    ASSERT_NE(r.verdict, "error") << r.error;
    ASSERT_TRUE(r.worst.has_value());
    const PointOutcome po = make_point(*s, i);
    ASSERT_TRUE(po.status.ok());
    StatusOr<WorstResult> direct = worst_case(po.point.spec, *parts, {});
    ASSERT_TRUE(direct.ok()) << direct.status().message();
    ASSERT_EQ(direct->directions.size(), 1u);  // the spec runs down only
    const DirectionWorst& d = direct->directions[0];
    ASSERT_EQ(d.direction, link::Direction::kDown);
    EXPECT_EQ(r.worst->verdict, direct->pass ? "pass" : "fail");
    // Through the CSV (6 significant digits) against worst_case's numbers.
    const std::string row = results_row(r);
    StatusOr<PointResult> back = parse_results_row(row.substr(0, row.size() - 1), shape);
    ASSERT_TRUE(back.ok()) << back.status().message();
    ASSERT_TRUE(back->worst.has_value());
    double rel_min = 1e300;
    std::string rel_metric;
    for (size_t m = 0; m < kWorstMetrics.size(); ++m) {
      const WorstMetric* wm = d.metric(kWorstMetrics[m]);
      ASSERT_NE(wm, nullptr) << kWorstMetrics[m];
      EXPECT_NEAR(back->worst->margin[0][m], wm->margin, 1e-5 * std::abs(wm->margin) + 1e-15)
          << "point " << i << " " << kWorstMetrics[m];
      EXPECT_TRUE(std::isnan(back->worst->margin[1][m]));  // up is not run: empty
      const double rel = wm->margin / std::abs(wm->limit);
      if (rel < rel_min) {
        rel_min = rel;
        rel_metric = kWorstMetrics[m];
      }
    }
    EXPECT_EQ(back->worst->worst_metric, rel_metric);
    EXPECT_NEAR(back->worst->margin_rel, rel_min, 1e-5 * std::abs(rel_min));
    // The spec's own traffic through run_link: the `verdict` column is its verdict.
    StatusOr<LinkRun> run = run_link(po.point.spec, *parts, {});
    ASSERT_TRUE(run.ok()) << run.status().message();
    EXPECT_EQ(r.verdict, run->pass ? "pass" : "fail");
    EXPECT_EQ(back->verdict, r.verdict);
    // The spec's frames are legal traffic: its VSTART cannot be lower than the worst case's.
    EXPECT_LE(d.metric("vstart")->margin, r.margin[0] + 1e-3) << "point " << i;
  }
}

// `outputs: [stress]` with the ESD level as the key, on a link whose 1 uF Y caps keep every
// clamp off (tests/analysis/stress_test.cpp: the connector peaks at Q / C): the circuit is linear
// in the level, so the highest pin peak moves in proportion, (m8 - m2) / (m2 - m1) = 6 whatever
// the pins' idle level. Point 8 kV's columns are those of run_stress on its spec, through the CSV.
TEST(SweepSim, StressColumnsFollowTheSweptEsdLevel) {
  const std::string text =
      "base:\n  name: ycap\n  tx: {device: bq79600, y_cap: 1u}\n  rx: {device: bq7961x, y_cap: "
      "1u}\n"
      "  cable: {length: 2}\n  stress: {only: [esd]}\n"
      "sweep:\n  stress.esd: [1kV, 2kV, 8kV]\noutputs: [stress]\n";
  StatusOr<SweepSpec> s = read_sweep_text(text, "sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  const RowShape shape = row_shape(*s);
  std::vector<PointResult> back;
  for (size_t i = 0; i < s->size(); ++i) {
    const PointResult r = run_point(*s, *parts, i, {});
    ASSERT_NE(r.verdict, "error") << r.error;
    const std::string row = results_row(r);
    StatusOr<PointResult> b = parse_results_row(row.substr(0, row.size() - 1), shape);
    ASSERT_TRUE(b.ok()) << b.status().message();
    ASSERT_TRUE(b->stress.has_value());
    EXPECT_EQ(b->stress->scenarios, 8) << i;  // 2 ends x 2 lines x 2 polarities
    EXPECT_EQ(b->stress->verdict, "pass") << i << ": " << b->stress->first_broken;
    EXPECT_EQ(b->stress->breaking, 0) << i;
    back.push_back(*b);
  }
  const double m1 = back[0].stress->max_pin_v, m2 = back[1].stress->max_pin_v,
               m8 = back[2].stress->max_pin_v;
  ASSERT_GT(m2 - m1, 0.01);  // tens of mV per kV: a ratio of real swings
  EXPECT_NEAR((m8 - m2) / (m2 - m1), 6.0, 0.06) << m1 << " " << m2 << " " << m8;
  std::printf("highest pin peak: %.5f V at 1 kV, %.5f V at 2 kV, %.5f V at 8 kV: ratio %.4f\n", m1,
              m2, m8, (m8 - m2) / (m2 - m1));
  const PointOutcome po = make_point(*s, 2);
  ASSERT_TRUE(po.status.ok());
  StatusOr<StressResult> direct = run_stress(po.point.spec, *parts, {});
  ASSERT_TRUE(direct.ok()) << direct.status().message();
  double pin = 0, cm = 0, diode = 0;
  for (const StressScenario& sc : direct->scenarios) {
    EXPECT_DOUBLE_EQ(std::abs(sc.level.front().second), 8.0) << sc.id;  // contact_kV
    for (const auto& [node, p] : sc.peak_pin_v) pin = std::max({pin, p.max, -p.min});
    cm = std::max(cm, sc.peak_cm_v);
    for (const DiodePeak& d : sc.diodes) diode = std::max(diode, d.peak_a);
  }
  EXPECT_NEAR(m8, pin, 1e-5 * pin);
  EXPECT_NEAR(back[2].stress->max_cm_v, cm, 1e-5 * cm);
  EXPECT_NEAR(back[2].stress->max_diode_a, diode, 1e-5 * diode);
}

// Every point's reduced model starts from point 0's expansion points, per direction: exactly
// those of point 0's own edge response (so they do not depend on threads or on resume), and a
// point started from them gives the margins of a point searched from scratch within the model's
// accuracy (0.5 mV, 1 ps: both models pass the same check against the exact AC solution).
TEST(SweepSim, EveryPointStartsFromPointZerosExpansionPoints) {
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  const std::string dir = temp_dir("start_points");
  write(dir + "/link.yaml", cap_link(1));
  StatusOr<SweepSpec> s =
      read_sweep_text("base: link.yaml\nsweep:\n  cable.length: [1, 6]\n", dir + "/sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto start = sweep_start_points(*s, *parts, {});
  ASSERT_EQ(start.size(), 1u);
  ASSERT_TRUE(start.count(link::Direction::kDown));
  WorstOptions fine;
  fine.dt /= kSynthesisOversample;
  StatusOr<EdgeResponse> e0 =
      edge_response(make_point(*s, 0).point.spec, *parts, link::Direction::kDown, fine);
  ASSERT_TRUE(e0.ok()) << e0.status().message();
  EXPECT_EQ(start.at(link::Direction::kDown), e0->expansion_points);
  EXPECT_GE(e0->expansion_points.size(), 2u);
  const PointResult scratch = run_point(*s, *parts, 1, {});
  const PointResult warm = run_point(*s, *parts, 1, {.start_points = start});
  ASSERT_EQ(scratch.path, "edges") << scratch.error;
  ASSERT_EQ(warm.path, "edges") << warm.error;
  EXPECT_EQ(warm.verdict, scratch.verdict);
  EXPECT_NEAR(warm.margin[0], scratch.margin[0], 0.5e-3);
  EXPECT_NEAR(warm.margin[1], scratch.margin[1], 0.5e-3);
  EXPECT_NEAR(warm.margin[2], scratch.margin[2], 1e-12);
  EXPECT_NEAR(warm.margin[3], scratch.margin[3], 1e-12);
}

// The path column: the fast path by default, with waveform files on its grid too (the same
// columns as a simulation's, within the LTI engine's 1 mV output grid of it); simulated, saying
// why, with --simulate, waveform files at a step off the synthesis grid, and traffic off it.
TEST(SweepSim, PathSaysHowEachPointWasObtained) {
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok()) << parts.status().message();
  const std::string dir = temp_dir("path");
  write(dir + "/link.yaml", cap_link(1));
  auto point = [&](const std::string& extra, const PointOptions& opt) {
    StatusOr<SweepSpec> s = read_sweep_text(
        "base: link.yaml\nsweep:\n  cable.length: [1]\n" + extra, dir + "/sweep.yaml");
    EXPECT_TRUE(s.ok()) << s.status().message();
    return s.ok() ? run_point(*s, *parts, 0, opt) : PointResult{};
  };
  fs::create_directories(dir + "/fast");
  fs::create_directories(dir + "/sim");
  const PointResult fast = point("", {.waves_dir = dir + "/fast"});
  EXPECT_EQ(fast.path, "edges") << fast.error;
  const PointResult sim = point("", {.waves_dir = dir + "/sim", .simulate = true});
  EXPECT_EQ(sim.path, "simulated: --simulate") << sim.error;
  EXPECT_EQ(fast.verdict, sim.verdict);
  EXPECT_NEAR(fast.margin[0], sim.margin[0], 1e-3);
  EXPECT_NEAR(fast.margin[2], sim.margin[2], 25e-12);
  const Csv a = read_csv(dir + "/fast/point_00000.csv");
  const Csv b = read_csv(dir + "/sim/point_00000.csv");
  EXPECT_EQ(a.header, b.header);
  ASSERT_EQ(a.header.size(), 5u);  // time and the four probes of the direction
  double worst = 0;
  for (size_t i = 0; i < std::min(a.rows.size(), b.rows.size()); ++i) {
    EXPECT_NEAR(std::stod(a.rows[i][0]), std::stod(b.rows[i][0]), 1e-12);
    for (size_t c = 1; c <= 3; ++c)  // the receiver's probes (v(txp,txn) is only plotted)
      worst = std::max(worst, std::abs(std::stod(a.rows[i][c]) - std::stod(b.rows[i][c])));
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(a.rows.size(), 1000u);
  EXPECT_EQ(a.rows.size(), b.rows.size());

  write(dir + "/link.yaml", cap_link(1) + "sim: {tstep: 0.3n}\n");
  EXPECT_EQ(point("", {.waves_dir = dir + "/sim"}).path,
            "simulated: waveform files at sim.tstep 0.3 ns (not a multiple of the 0.25 ns grid of "
            "the edge response)");
  EXPECT_EQ(point("", {}).path, "edges");  // no files: the step does not matter
  std::string off = cap_link(1);
  off.replace(off.find("], direction"), 1, "], gaps: [1.0001u]");
  write(dir + "/link.yaml", off);
  const PointResult off_grid = point("", {});
  EXPECT_EQ(off_grid.path,
            "simulated: down: the drive changes level at 1.0001 us (off the 0.25 ns grid of the "
            "edge response)")
      << off_grid.error;
  EXPECT_EQ(point("", {.run = {.engine = Engine::Transient}}).path,
            "simulated: --engine transient");
}

TEST(SweepSim, AFailingPointIsRecordedAndTheSweepGoesOn) {
  const std::string dir = temp_dir("error");
  write(dir + "/sweep.yaml", R"(base:
  name: xfmr
  tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
  rx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
  cable: {length: 1}
  stimulus: {frames: ["single-read dev=1 reg=0x0215 n=1"], direction: down}
sweep:
  ends.isolation.part: [NOPE-123, HMU1228NL]
)");
  const int rc =
      run(kBinary + " sweep " + dir + "/sweep.yaml -o " + dir + "/out -q 2> " + dir + "/err");
  EXPECT_EQ(rc, 1);  // done, but a point could not run
  const Csv csv = read_csv(dir + "/out/results.csv");
  ASSERT_EQ(csv.rows.size(), 2u);
  EXPECT_EQ(csv.rows[0][1], "NOPE-123");
  EXPECT_EQ(csv.rows[0][csv.col("verdict")], "error");
  EXPECT_NE(csv.rows[0][csv.col("error")].find("NOPE-123"), std::string::npos)
      << csv.rows[0][csv.col("error")];
  EXPECT_EQ(csv.rows[0][csv.col("margin_vstart_V")], "");
  EXPECT_TRUE(csv.rows[1][csv.col("verdict")] == "pass" ||
              csv.rows[1][csv.col("verdict")] == "fail");
  EXPECT_EQ(csv.rows[1][csv.col("error")], "");
  EXPECT_NE(csv.rows[1][csv.col("margin_vstart_V")], "");
  const nlohmann::json sum = nlohmann::json::parse(slurp(dir + "/out/summary.json"));
  EXPECT_EQ(sum["error"], 1);
  EXPECT_EQ(sum["done"], 2);
}

TEST(SweepSim, ResumeSkipsThePointsAlreadyDone) {
  const std::string dir = temp_dir("resume");
  write(dir + "/link.yaml", cap_link(1));
  write(dir + "/sweep.yaml", "base: link.yaml\nsweep:\n  cable.length: [1, 2]\n");
  fs::create_directories(dir + "/out");
  // Point 0 "done" by an earlier run (made-up numbers: a re-run would replace them).
  const std::string header =
      "point,cable.length,verdict,worst_metric,worst_margin_rel,margin_vstart_V,margin_vend_V,"
      "margin_width_ns,margin_edge_ns,decoded_ok,fail_reason,seconds,error,path\n";
  const std::string done = "0,1,pass,vstart,0.5,0.8,0.6,30,40,true,,99.00,,edges\n";
  write(dir + "/out/results.csv", header + done);
  const int rc = run(kBinary + " sweep " + dir + "/sweep.yaml -o " + dir +
                     "/out --resume --keep-waves > " + dir + "/stdout 2> " + dir + "/stderr");
  EXPECT_TRUE(rc == 0 || rc == 1) << rc;
  const std::string text = slurp(dir + "/out/results.csv");
  EXPECT_EQ(text.substr(0, header.size() + done.size()), header + done);
  const Csv csv = read_csv(dir + "/out/results.csv");
  ASSERT_EQ(csv.rows.size(), 2u);
  EXPECT_EQ(csv.rows[1][1], "2");
  EXPECT_NE(csv.rows[1][csv.col("seconds")], "99.00");
  EXPECT_NE(slurp(dir + "/stdout").find("2 points: "), std::string::npos) << slurp(dir + "/stdout");
  EXPECT_NE(slurp(dir + "/stdout").find("(1 from the earlier run)"), std::string::npos);
  EXPECT_NE(slurp(dir + "/stderr").find("sweep: 2/2 points"), std::string::npos)
      << slurp(dir + "/stderr");
  // --keep-waves: the point that ran has its waveforms.
  EXPECT_FALSE(fs::exists(dir + "/out/waves/point_00000.csv"));
  ASSERT_TRUE(fs::exists(dir + "/out/waves/point_00001.csv"));
  EXPECT_EQ(slurp(dir + "/out/waves/point_00001.csv").substr(0, 26),
            "time,\"down v(rxp,rxn)\",dow");
}

TEST(SweepSim, MonteCarloWritesTheHistogramAndYield) {
  const std::string dir = temp_dir("mc");
  write(dir + "/link.yaml", cap_link(1));
  write(dir + "/sweep.yaml", R"(base: link.yaml
monte_carlo:
  samples: 3
  seed: 5
  tolerances: {tx.isolation.cap: 10%, cable.temperature: {normal: [25, 20]}}
)");
  const int rc = run(kBinary + " sweep " + dir + "/sweep.yaml -o " + dir + "/out -q");
  EXPECT_TRUE(rc == 0 || rc == 1) << rc;
  const Csv csv = read_csv(dir + "/out/results.csv");
  EXPECT_EQ(csv.header[1], "sample");
  EXPECT_EQ(csv.header[2], "mc.tx.isolation.cap");
  ASSERT_EQ(csv.rows.size(), 3u);
  for (const auto& r : csv.rows) {
    const double c = std::stod(r[2]);
    EXPECT_GE(c, 2.2e-9 * 0.9);
    EXPECT_LE(c, 2.2e-9 * 1.1);
  }
  const nlohmann::json sum = nlohmann::json::parse(slurp(dir + "/out/summary.json"));
  EXPECT_EQ(sum["monte_carlo"]["samples"], 3);
  EXPECT_DOUBLE_EQ(sum["pass_yield"].get<double>(), sum["pass"].get<double>() / 3.0);
  EXPECT_TRUE(fs::exists(dir + "/out/mc_histogram.png"));
  EXPECT_FALSE(fs::exists(dir + "/out/sweep_margin.png"));  // no axis
}

TEST(SweepSim, MpiTwoRanksGiveTheThreadedResults) {
  if (kMpiexec.empty()) GTEST_SKIP() << "built without MPI (ISOLINK_MPI=OFF)";
  const std::string dir = temp_dir("mpi");
  write(dir + "/link.yaml", cap_link(1));
  write(dir + "/sweep.yaml",
        "base: link.yaml\nsweep:\n  cable.length: [0.5, 1]\n  rx.isolation.cap: [1n, 4.7n]\n");
  const int rc_threads = run(kBinary + " sweep " + dir + "/sweep.yaml -o " + dir + "/threads -q");
  // As root (CI) OpenMPI wants --allow-run-as-root; --oversubscribe for machines with 1 core; no
  // single-copy (CMA) transport inside containers; plm isolated: start the ranks on this machine
  // without looking for ssh (Debian's openmpi-bin only recommends openssh-client).
  const std::string env =
      "OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_rmaps_base_oversubscribe=1 "
      "OMPI_MCA_plm=isolated OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ";
  const int rc_mpi =
      run(env + kMpiexec + " --allow-run-as-root --oversubscribe -np 2 " + kBinary + " sweep " +
          dir + "/sweep.yaml -o " + dir + "/mpi -q > " + dir + "/mpi.log 2>&1");
  EXPECT_EQ(rc_mpi, rc_threads) << slurp(dir + "/mpi.log");
  Csv a = read_csv(dir + "/threads/results.csv"), b = read_csv(dir + "/mpi/results.csv");
  ASSERT_EQ(a.header, b.header);
  ASSERT_EQ(a.rows.size(), 4u);
  ASSERT_EQ(b.rows.size(), 4u) << slurp(dir + "/mpi.log");
  const size_t sec = a.col("seconds");
  for (size_t i = 0; i < 4; ++i) {
    a.rows[i].erase(a.rows[i].begin() + static_cast<long>(sec));
    b.rows[i].erase(b.rows[i].begin() + static_cast<long>(sec));
    EXPECT_EQ(a.rows[i], b.rows[i]) << "point " << i;
  }
  EXPECT_EQ(slurp(dir + "/threads/summary.json"), slurp(dir + "/mpi/summary.json"));
  EXPECT_TRUE(fs::exists(dir + "/mpi/sweep_heatmap.png"));
  EXPECT_TRUE(fs::exists(dir + "/mpi/sweep_margin.png"));
}

}  // namespace
}  // namespace isolink::analysis::sweep
