// Sweeps over a pack spec: hop keys (hops.K.key, hops.*.key, ends.), refused keys with the sweep
// file's line and column, the extra results.csv columns, and (SweepPackSim, simulating) each
// point's figures against run_pack on the pack edited by hand, and --resume through the binary.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/pack.h"
#include "analysis/sweep_run.h"
#include "analysis/sweep_spec.h"
#include "base/csv.h"

namespace isolink::analysis::sweep {
namespace {

namespace fs = std::filesystem;

std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "isolink_sweep_pack_" + name;
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

// A module spec and a 3-hop pack (hops 2 and 3 one repeated entry), short cables, one frame down.
// hop_2 / hop_3: extra keys of those hops' entries when the pack is written "by hand".
std::string pack_text(const std::string& hop_1 = "", const std::string& hop_2 = "",
                      const std::string& hop_3 = "") {
  std::string t =
      "name: p\n"
      "stimulus: {frames: [\"stack-write reg=0x0100 data=02\"], direction: down}\n"
      "hops:\n";
  t += "  - {spec: module.yaml, cable: {length: 0.5}" + hop_1 + "}\n";
  if (hop_2.empty() && hop_3.empty()) {
    t += "  - {spec: module.yaml, repeat: 2}\n";
  } else {
    t += "  - {spec: module.yaml" + hop_2 + "}\n";
    t += "  - {spec: module.yaml" + hop_3 + "}\n";
  }
  return t;
}

// The simulating tests' pack: two hops (fewer simulations), hop 2 with extra keys.
std::string two_hop_pack(const std::string& hop_2 = "") {
  return "name: p\n"
         "stimulus: {frames: [\"stack-write reg=0x0100 data=02\"], direction: down}\n"
         "hops:\n"
         "  - {spec: module.yaml, cable: {length: 0.5}}\n"
         "  - {spec: module.yaml" +
         hop_2 + "}\n";
}

const char* kModule =
    "name: module\n"
    "tx: {isolation: {type: cap, cap: 2.2n}}\n"
    "rx: {isolation: {type: cap, cap: 2.2n}}\n"
    "cable: {length: 1, material: pp}\n";

std::string setup(const std::string& name, const std::string& sweep) {
  const std::string d = temp_dir(name);
  write(d + "/module.yaml", kModule);
  write(d + "/pack.yaml", pack_text());
  write(d + "/sweep.yaml", "base: pack.yaml\nsweep:\n" + sweep);
  return d;
}

std::string read_error(const std::string& dir) {
  StatusOr<SweepSpec> s = read_sweep_file(dir + "/sweep.yaml");
  EXPECT_FALSE(s.ok()) << "expected an error";
  return s ? "" : s.status().message();
}

TEST(SweepPack, HopKeysSetTheirHopsOnly) {
  const std::string d = setup("keys",
                              "  hops.2.cable.length: [3]\n"
                              "  hops.*.ends.isolation.cap: [4.7n]\n"
                              "  hops.3.rx.series_r: [100]\n");
  StatusOr<SweepSpec> s = read_sweep_file(d + "/sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->pack);
  EXPECT_EQ(s->pack_hops, 3);
  PointOutcome p = make_point(*s, 0);
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  ASSERT_TRUE(p.point.pack);
  const std::vector<HopSpec>& h = p.point.pack->hops;
  ASSERT_EQ(h.size(), 3u);
  // hops.2 changes hop 2 only, though hops 2 and 3 are one repeated entry.
  EXPECT_EQ(h[0].spec.cable.length, 0.5);
  EXPECT_EQ(h[1].spec.cable.length, 3.0);
  EXPECT_EQ(h[2].spec.cable.length, 1.0);
  // hops.* with ends: both ends of every hop.
  for (const HopSpec& x : h) {
    EXPECT_DOUBLE_EQ(x.spec.tx.isolation.cap, 4.7e-9) << x.index;
    EXPECT_DOUBLE_EQ(x.spec.rx.isolation.cap, 4.7e-9) << x.index;
  }
  EXPECT_EQ(h[2].spec.rx.series_r, 100.0);
  EXPECT_NE(h[1].spec.rx.series_r, 100.0);
  // Hop 1 keeps the bridge at its tx end, the others stack devices.
  EXPECT_EQ(h[0].spec.tx.device, "bq79600");
  EXPECT_EQ(h[1].spec.tx.device, "bq7961x");
  EXPECT_EQ(h[2].spec.tx.device, "bq7961x");
  // The extra columns.
  EXPECT_EQ(pack_columns(*s),
            (std::vector<std::string>{"weakest_hop", "failing_hops", "hop_1_margin_rel",
                                      "hop_2_margin_rel", "hop_3_margin_rel"}));
  const std::vector<std::string> header = results_header(*s);
  EXPECT_EQ(header.back(), "hop_3_margin_rel");
}

TEST(SweepPack, BadHopIndexOrKeyIsRefusedAtItsLine) {
  std::string e = read_error(setup("index", "  hops.4.cable.length: [1, 2]\n"));
  EXPECT_NE(e.find("sweep.yaml:3:3: error: sweep key 'hops.4.cable.length': hop 4 is not in the "
                   "pack (3 hops)"),
            std::string::npos)
      << e;
  e = read_error(setup("zero", "  hops.0.cable.length: [1]\n"));
  EXPECT_NE(e.find("sweep.yaml:3:3: error: sweep key 'hops.0.cable.length': a pack sweep's keys "
                   "address hops: hops.<K>.<link-spec key> with K = 1..3"),
            std::string::npos)
      << e;
  e = read_error(setup("nohop", "  cable.length: [1]\n"));
  EXPECT_NE(e.find("sweep.yaml:3:3: error: sweep key 'cable.length': a pack sweep's keys address "
                   "hops"),
            std::string::npos)
      << e;
  e = read_error(setup("typo", "  hops.2.cable.lenght: [1]\n"));
  EXPECT_NE(e.find("sweep.yaml:3:3: error: sweep key 'hops.2.cable.lenght' is not a link-spec "
                   "key: unknown key 'cable.lenght'"),
            std::string::npos)
      << e;
  e = read_error(setup("value", "  hops.*.cable.length: [1, -2]\n"));
  EXPECT_NE(e.find("sweep.yaml:3:28: error: sweep key 'hops.*.cable.length': value '-2' does not "
                   "make a valid spec"),
            std::string::npos)
      << e;
  // Variants: each sub-key is checked.
  e = read_error(setup("variant", "  harness:\n    long: {hops.9.cable.length: 5}\n"));
  EXPECT_NE(e.find("sweep.yaml:4:12: error: sweep key 'hops.9.cable.length': hop 9 is not in the "
                   "pack"),
            std::string::npos)
      << e;
  const std::string d = setup("mc", "  hops.2.cable.length: [1]\n");
  write(d + "/sweep.yaml",
        "base: pack.yaml\nsweep:\n  hops.2.cable.length: [1]\nmonte_carlo:\n  samples: 2\n"
        "  tolerances: {hops.2.cable.length: 10%}\n");
  e = read_error(d);
  EXPECT_NE(e.find("sweep.yaml:5:3: error: key 'monte_carlo': not available when the base is a "
                   "pack spec"),
            std::string::npos)
      << e;
  write(d + "/sweep.yaml",
        "base: pack.yaml\nsweep:\n  hops.2.cable.length: [1]\noutputs: [noise]\n");
  e = read_error(d);
  EXPECT_NE(e.find("sweep.yaml:4:10: error: key 'outputs': noise is not available when the base "
                   "is a pack spec"),
            std::string::npos)
      << e;
  // The worst case over all traffic is `isolink pack`'s, not a pack sweep's.
  write(d + "/sweep.yaml",
        "base: pack.yaml\nsweep:\n  hops.2.cable.length: [1]\noutputs: [worst]\n");
  e = read_error(d);
  EXPECT_NE(e.find("sweep.yaml:4:10: error: key 'outputs': worst is not available when the base "
                   "is a pack spec (sweep a hop's own link spec with outputs: [worst] instead)"),
            std::string::npos)
      << e;
}

TEST(SweepPack, ExtraColumnsRoundTrip) {
  PointResult r;
  r.index = 4;
  r.cells = {"3"};
  r.verdict = "fail";
  r.worst_metric = "vend";
  r.worst_rel = -0.25;
  r.reason = "hop 2: vend";
  r.extra = {"2", "2", "0.1", "-0.25", "0.3"};
  std::string row = results_row(r);
  EXPECT_EQ(row.substr(row.size() - 19), ",2,2,0.1,-0.25,0.3\n") << row;
  row.pop_back();
  StatusOr<PointResult> back = parse_results_row(row, {.cells = 1, .extra = 5});
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->extra, r.extra);
  EXPECT_EQ(back->reason, r.reason);
  // Six hops make 8 pack columns, as many as the noise family has: they are still read as the
  // pack's (the row's shape comes from the sweep, not from its field count).
  r.extra = {"2", "2", "0.1", "-0.25", "0.3", "0.4", "0.5", "0.6"};
  row = results_row(r);
  row.pop_back();
  back = parse_results_row(row, {.cells = 1, .extra = 8});
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->extra, r.extra);
  EXPECT_FALSE(back->noise.has_value());
}

// Each point's row is score_pack of run_pack on the pack written out by hand with that value.
TEST(SweepPackSim, PointsEqualRunPackOnThePackEditedByHand) {
  const std::string d = setup("sim", "  hops.2.cable.length: [2, 4]\n");
  write(d + "/pack.yaml", two_hop_pack());
  StatusOr<SweepSpec> s = read_sweep_file(d + "/sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  const std::vector<std::string> lengths = {"2", "4"};
  const RowShape shape = row_shape(*s);
  EXPECT_EQ(shape.columns(), results_header(*s).size());
  for (size_t i = 0; i < 2; ++i) {
    const PointResult got = round_trip(run_point(*s, *parts, i, {}), shape);
    ASSERT_EQ(got.verdict == "error", false) << got.error;
    write(d + "/hand.yaml", two_hop_pack(", cable: {length: " + lengths[i] + "}"));
    StatusOr<PackSpec> hand = read_pack_spec_file(d + "/hand.yaml");
    ASSERT_TRUE(hand.ok()) << hand.status().message();
    StatusOr<PackResult> pr = run_pack(*hand, *parts, {});
    ASSERT_TRUE(pr.ok()) << pr.status().message();
    PointResult want = score_pack(*pr);
    want.index = i;
    want.cells = {lengths[i]};
    want.seconds = got.seconds;
    want = round_trip(want, shape);
    EXPECT_EQ(results_row(got), results_row(want));
    // The columns say what they claim: the pack's verdict, the weakest hop's margin, per hop
    // margins.
    EXPECT_EQ(got.verdict, pr->pass ? "pass" : "fail");
    EXPECT_EQ(got.extra[0], fmt::format("{}", pr->weakest));
    EXPECT_EQ(got.extra[2 + 1], fmt::format("{:.6g}", pr->hops[1].worst_rel));
    EXPECT_EQ(got.worst_rel, std::stod(got.extra[2 + pr->weakest - 1]));
  }
}

// --resume on a pack sweep: a row already there is kept, the other point runs; the header has
// the pack columns.
TEST(SweepPackSim, ResumeSkipsThePointsAlreadyDone) {
  const std::string d = setup("resume", "  hops.2.cable.length: [2, 3]\n");
  write(d + "/pack.yaml", two_hop_pack());
  StatusOr<SweepSpec> s = read_sweep_file(d + "/sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  fs::create_directories(d + "/out");
  std::string header;
  for (const std::string& h : results_header(*s)) header += (header.empty() ? "" : ",") + h;
  const std::string done =
      "0,2,pass,width,0.5,0.8,0.6,30,40,true,,99.00,,simulated: a pack (every hop simulated),2,,"
      "0.6,0.5\n";
  write(d + "/out/results.csv", header + "\n" + done);
  const std::string cmd = std::string(ISOLINK_BINARY) + " sweep " + d + "/sweep.yaml -o " + d +
                          "/out --resume -q --no-plots > " + d + "/log 2>&1";
  const int rc = WEXITSTATUS(std::system(cmd.c_str()));
  EXPECT_TRUE(rc == 0 || rc == 1) << rc << slurp(d + "/log");
  const std::string text = slurp(d + "/out/results.csv");
  EXPECT_EQ(text.substr(0, header.size() + 1 + done.size()), header + "\n" + done);
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 3u) << text;
  const std::vector<std::string> f = split_csv_line(lines[2]);
  ASSERT_EQ(f.size(), results_header(*s).size());
  EXPECT_EQ(f[0], "1");
  EXPECT_EQ(f[1], "3");
  EXPECT_NE(f[11], "99.00");
}

// A point that cannot run (a part that is not in the library: found when the hop is expanded)
// is an error row with the pack columns present and empty; the sweep goes on and exits 1.
TEST(SweepPackSim, AFailingPointIsRecordedAndTheSweepGoesOn) {
  const std::string d = setup("error",
                              "  hops.2.ends.isolation:\n"
                              "    - {type: transformer, part: NOPE-123}\n"
                              "    - {type: cap, cap: 2.2n}\n");
  write(d + "/pack.yaml", two_hop_pack());
  StatusOr<SweepSpec> s = read_sweep_file(d + "/sweep.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const std::string cmd = std::string(ISOLINK_BINARY) + " sweep " + d + "/sweep.yaml -o " + d +
                          "/out -q --no-plots > " + d + "/log 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 1) << slurp(d + "/log");
  std::istringstream in(slurp(d + "/out/results.csv"));
  std::vector<std::vector<std::string>> rows;
  for (std::string l; std::getline(in, l);) rows.push_back(split_csv_line(l));
  ASSERT_EQ(rows.size(), 3u);
  const size_t ncol = results_header(*s).size();
  for (const auto& r : rows) EXPECT_EQ(r.size(), ncol);
  for (size_t k = 1; k < 3; ++k) {
    const std::vector<std::string>& r = rows[k];
    if (r[0] == "0") {
      EXPECT_EQ(r[2], "error");
      EXPECT_NE(r[12].find("NOPE-123"), std::string::npos) << r[12];
      for (size_t c = 13; c < ncol; ++c) EXPECT_EQ(r[c], "") << c;
    } else {
      EXPECT_TRUE(r[2] == "pass" || r[2] == "fail") << r[2];
      EXPECT_EQ(r[13], "simulated: a pack (every hop simulated)");  // path
      EXPECT_TRUE(r[14] == "1" || r[14] == "2") << r[14];           // weakest_hop
      EXPECT_NE(r[16], "");                                         // hop 1's margin
      EXPECT_NE(r[17], "");                                         // hop 2's margin
    }
  }
}

}  // namespace
}  // namespace isolink::analysis::sweep
