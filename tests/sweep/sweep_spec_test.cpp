// The sweep file: keys, ranges, grid / zip points, Monte Carlo draws, and errors with file:line.
#include "analysis/sweep_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

namespace isolink::analysis::sweep {
namespace {

// An inline base: a capacitor link, 1 m, one frame down.
const std::string kBase = R"(base:
  name: t
  tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
  rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
  cable: {length: 1, material: pp}
  stimulus: {frames: ["single-read dev=1 reg=0x0215 n=1"], direction: down}
)";

SweepSpec read_ok(const std::string& text) {
  StatusOr<SweepSpec> s = read_sweep_text(text, "sweep.yaml");
  if (!s) {
    ADD_FAILURE() << s.status().message();
    return SweepSpec{};
  }
  return *s;
}

std::string read_error(const std::string& text) {
  StatusOr<SweepSpec> s = read_sweep_text(text, "sweep.yaml");
  EXPECT_FALSE(s.ok()) << "expected an error";
  return s ? "" : s.status().message();
}

TEST(SweepSpec, GridIsTheProductInRowMajorOrder) {
  const SweepSpec s = read_ok(kBase + R"(sweep:
  cable.length: [1, 2, 3]
  rx.isolation.cap: [1n, 2.2n]
)");
  ASSERT_EQ(s.axes.size(), 2u);
  EXPECT_EQ(s.grid_size(), 6u);
  EXPECT_EQ(s.size(), 6u);
  EXPECT_EQ(s.point_columns(), (std::vector<std::string>{"cable.length", "rx.isolation.cap"}));
  // The last key varies fastest.
  const std::vector<std::vector<size_t>> want = {{0, 0}, {0, 1}, {1, 0}, {1, 1}, {2, 0}, {2, 1}};
  for (size_t g = 0; g < 6; ++g) EXPECT_EQ(s.grid_indices(g), want[g]) << g;
  const PointOutcome p = make_point(s, 3);
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_EQ(p.point.cells, (std::vector<std::string>{"2", "2.2e-09"}));
  EXPECT_DOUBLE_EQ(p.point.spec.cable.length, 2.0);
  EXPECT_DOUBLE_EQ(p.point.spec.rx.isolation.cap, 2.2e-9);
  EXPECT_DOUBLE_EQ(p.point.spec.tx.isolation.cap, 2.2e-9);  // untouched
  EXPECT_EQ(p.point.spec.cable.material, "pp");
  EXPECT_EQ(p.point.spec.name, "t");
  ASSERT_EQ(s.axes[1].values.size(), 2u);
  EXPECT_DOUBLE_EQ(*s.axes[1].values[0].number, 1e-9);
  EXPECT_EQ(s.axes[1].unit, config::Unit::kFarad);
}

TEST(SweepSpec, ZipPairsTheValues) {
  const SweepSpec s = read_ok(kBase + R"(mode: zip
sweep:
  cable.length: [1, 2, 3]
  cable.temperature: [-40, 25, 85]
)");
  EXPECT_EQ(s.size(), 3u);
  const PointOutcome p = make_point(s, 2);
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_DOUBLE_EQ(p.point.spec.cable.length, 3.0);
  EXPECT_DOUBLE_EQ(p.point.spec.cable.temperature, 85.0);
}

TEST(SweepSpec, ZipLengthMismatchIsAnError) {
  const std::string e = read_error(kBase + R"(mode: zip
sweep:
  cable.length: [1, 2, 3]
  cable.temperature: [-40, 25]
)");
  EXPECT_NE(e.find("sweep.yaml:7:7: error: mode zip needs the same number of values"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("cable.length has 3, cable.temperature has 2"), std::string::npos) << e;
}

TEST(SweepSpec, LogRangeIsTheGeometricSeries) {
  const SweepSpec s = read_ok(kBase + R"(sweep:
  rx.isolation.cap: {from: 1n, to: 5.6n, steps: 5, scale: log}
)");
  ASSERT_EQ(s.axes.size(), 1u);
  const Axis& a = s.axes[0];
  EXPECT_TRUE(a.log);
  ASSERT_EQ(a.values.size(), 5u);
  for (int i = 0; i < 5; ++i)
    EXPECT_DOUBLE_EQ(*a.values[static_cast<size_t>(i)].number, 1e-9 * std::pow(5.6, i / 4.0)) << i;
  EXPECT_EQ(*a.values[4].number, 5.6e-9);  // the end exactly
  EXPECT_EQ(a.values[2].label, "2.36643e-09");
  // The spec gets the value as text, read with the key's own unit rules.
  const PointOutcome p = make_point(s, 2);
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_NEAR(p.point.spec.rx.isolation.cap, 2.36643e-9, 1e-15);
}

TEST(SweepSpec, LinearRangeAndLengthsWithoutSuffixScaling) {
  const SweepSpec s = read_ok(kBase + R"(sweep:
  cable.length: {from: 1m, to: 4, steps: 4}
)");
  ASSERT_EQ(s.axes[0].values.size(), 4u);
  for (int i = 0; i < 4; ++i)
    EXPECT_DOUBLE_EQ(*s.axes[0].values[static_cast<size_t>(i)].number,
                     1.0 + i);  // "1m" is one metre, not milli
  EXPECT_FALSE(s.axes[0].log);
  EXPECT_EQ(range_values(0, 1, 1, false), std::vector<double>{0});
  EXPECT_EQ(range_values(2, 4, 3, false), (std::vector<double>{2, 3, 4}));
}

TEST(SweepSpec, RangeWithZeroStepsIsAnError) {
  const std::string e = read_error(kBase + R"(sweep:
  rx.isolation.cap: {from: 1n, to: 5.6n, steps: 0}
)");
  EXPECT_NE(e.find("sweep.yaml:8:49: error: key 'sweep.rx.isolation.cap.steps': steps must be a "
                   "whole number from 1 to 100000, found '0'"),
            std::string::npos)
      << e;
}

TEST(SweepSpec, LogRangeNeedsPositiveEnds) {
  const std::string e = read_error(kBase + R"(sweep:
  cable.temperature: {from: -40, to: 85, steps: 3, scale: log}
)");
  EXPECT_NE(e.find("sweep.yaml:8:"), std::string::npos) << e;
  EXPECT_NE(e.find("a log range needs from and to > 0"), std::string::npos) << e;
}

TEST(SweepSpec, UnknownKeyNamesTheSweepFileLineAndKey) {
  const std::string e = read_error(kBase + R"(sweep:
  cable.length: [1, 2]
  cable.lenght: [1, 2]
)");
  EXPECT_NE(e.find("sweep.yaml:9:3: error: sweep key 'cable.lenght' is not a link-spec key: "
                   "unknown key 'cable.lenght' in 'cable'"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("known keys: length, material"), std::string::npos) << e;
}

TEST(SweepSpec, UnknownTopLevelAndNestedKeys) {
  EXPECT_NE(read_error(kBase + "sweep:\n  tx.isolaton.cap: [1n]\n")
                .find("sweep.yaml:8:3: error: sweep key 'tx.isolaton.cap' is not a link-spec key"),
            std::string::npos);
  EXPECT_NE(read_error(kBase + "sweep:\n  cable.length.x: [1]\n")
                .find("sweep.yaml:8:3: error: sweep key 'cable.length.x' is not a link-spec key: "
                      "key 'cable.length' is a value"),
            std::string::npos);
  EXPECT_NE(read_error(kBase + "sweep: {cable.length: [1]}\nmodes: zip\n")
                .find("sweep.yaml:8:1: error: unknown key 'modes'"),
            std::string::npos);
}

TEST(SweepSpec, OutputsAddTheNoiseAndWorstFamiliesAndRefuseUnknownOnes) {
  StatusOr<SweepSpec> plain = read_sweep_text(kBase + "sweep: {cable.length: [1, 2]}\n", "s.yaml");
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_FALSE(plain->noise_outputs);
  for (const char* o : {"outputs: [noise]\n", "outputs: noise\n"}) {
    StatusOr<SweepSpec> s =
        read_sweep_text(kBase + "sweep: {cable.length: [1, 2]}\n" + o, "sweep.yaml");
    ASSERT_TRUE(s.ok()) << s.status().message();
    EXPECT_TRUE(s->noise_outputs) << o;
  }
  const std::string e = read_error(kBase + "sweep: {cable.length: [1]}\noutputs: [noise, nosie]\n");
  EXPECT_NE(e.find("sweep.yaml:8:18: error: key 'outputs': 'nosie' is not a result family; the "
                   "ones known are noise (the noise-immunity columns), worst (the worst case "
                   "over all legal traffic) and stress (isolink stress's verdict and peaks)"),
            std::string::npos)
      << e;
  StatusOr<SweepSpec> st =
      read_sweep_text(kBase + "sweep: {cable.length: [1, 2]}\noutputs: [stress]\n", "sweep.yaml");
  ASSERT_TRUE(st.ok()) << st.status().message();
  EXPECT_TRUE(st->stress_outputs);
  EXPECT_FALSE(st->worst_outputs || st->noise_outputs || plain->stress_outputs);
  // worst alone and both.
  StatusOr<SweepSpec> w =
      read_sweep_text(kBase + "sweep: {cable.length: [1, 2]}\noutputs: [worst]\n", "sweep.yaml");
  ASSERT_TRUE(w.ok()) << w.status().message();
  EXPECT_TRUE(w->worst_outputs);
  EXPECT_FALSE(w->noise_outputs);
  EXPECT_FALSE(plain->worst_outputs);
  StatusOr<SweepSpec> both = read_sweep_text(
      kBase + "sweep: {cable.length: [1, 2]}\noutputs: [worst, noise]\n", "sweep.yaml");
  ASSERT_TRUE(both.ok()) << both.status().message();
  EXPECT_TRUE(both->worst_outputs && both->noise_outputs);
}

// The example that sweeps the TVS part against the ESD level reads: 3 parts x 3 levels, the
// stress columns, the part and the level landing in the point's spec.
TEST(SweepSpec, EsdTvsExampleReads) {
  StatusOr<SweepSpec> s =
      read_sweep_file(std::string(ISOLINK_EXAMPLES_DIR) + "/sweep_esd_tvs.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->stress_outputs);
  EXPECT_EQ(s->size(), 9u);
  const PointOutcome p = make_point(*s, 5);  // ESD24VS2U at 15 kV
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_EQ(p.point.cells, (std::vector<std::string>{"ESD24VS2U", "15kV"}));
  EXPECT_DOUBLE_EQ(p.point.spec.stress.esd_v, 15e3);
  EXPECT_EQ(p.point.spec.tx.isolation.esd_part, "ESD24VS2U");
  EXPECT_EQ(p.point.spec.rx.isolation.esd_part, "ESD24VS2U");
}

// The example that sweeps TI's chokes against BCI immunity reads: 4 isolation variants x 3
// lengths, with the noise columns.
TEST(SweepSpec, ChokeImmunityExampleReads) {
  StatusOr<SweepSpec> s =
      read_sweep_file(std::string(ISOLINK_EXAMPLES_DIR) + "/sweep_choke_immunity.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->noise_outputs);
  EXPECT_EQ(s->size(), 12u);
  const PointOutcome p = make_point(*s, 4);  // ACT45B-510 at 5 m
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_EQ(p.point.cells, (std::vector<std::string>{"ACT45B-510", "5"}));
  EXPECT_EQ(p.point.spec.noise.injection, "bci");
  EXPECT_DOUBLE_EQ(p.point.spec.noise.level, 0.1);
}

// The example that puts the worst case beside the capacitor link's length sweep reads: 6
// lengths, down, with the worst.* columns only.
TEST(SweepSpec, CapLengthWorstExampleReads) {
  StatusOr<SweepSpec> s =
      read_sweep_file(std::string(ISOLINK_EXAMPLES_DIR) + "/sweep_cap_length_worst.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_TRUE(s->worst_outputs);
  EXPECT_FALSE(s->noise_outputs);
  EXPECT_EQ(s->size(), 6u);
  const PointOutcome p = make_point(*s, 5);
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_DOUBLE_EQ(p.point.spec.cable.length, 20.0);
  EXPECT_EQ(p.point.spec.stimulus.directions, std::vector<link::Direction>{link::Direction::kDown});
}

TEST(SweepSpec, BadValueIsReportedAtTheValue) {
  const std::string e = read_error(kBase + R"(sweep:
  cable.length: [1, -2]
)");
  EXPECT_NE(e.find("sweep.yaml:8:21: error: sweep key 'cable.length': value '-2' does not make a "
                   "valid spec: key 'cable.length' = -2: must be > 0"),
            std::string::npos)
      << e;
  const std::string m = read_error(kBase + "sweep:\n  cable.material: [pp, pcv]\n");
  EXPECT_NE(m.find("sweep.yaml:8:24: error: sweep key 'cable.material': value 'pcv'"),
            std::string::npos)
      << m;
}

TEST(SweepSpec, BaseFileRelativeToTheSweepFile) {
  const auto dir = std::filesystem::temp_directory_path() / "isolink_sweep_spec_base";
  std::filesystem::create_directories(dir / "sub");
  std::ofstream(dir / "sub" / "link.yaml")
      << "name: from-file\ncable: {length: 3}\nstimulus: {frames: [\"single-read dev=1 "
         "reg=0x0215 n=1\"]}\n";
  std::ofstream(dir / "sweep.yaml") << "base: sub/link.yaml\nsweep:\n  cable.length: [4, 5]\n";
  StatusOr<SweepSpec> s = read_sweep_file((dir / "sweep.yaml").string());
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->name, "sweep");
  EXPECT_EQ(s->base_path, (dir / "sub" / "link.yaml").string());
  const PointOutcome p = make_point(*s, 1);
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_EQ(p.point.spec.name, "from-file");
  EXPECT_DOUBLE_EQ(p.point.spec.cable.length, 5.0);
  // A missing base file.
  std::ofstream(dir / "bad.yaml") << "base: nope.yaml\nsweep: {cable.length: [1]}\n";
  StatusOr<SweepSpec> b = read_sweep_file((dir / "bad.yaml").string());
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("bad.yaml:1:7: error: key 'base': cannot read the link spec"),
            std::string::npos)
      << b.status().message();
  // An error in the base spec names the base file's own line.
  std::ofstream(dir / "sub" / "broken.yaml") << "name: x\ncable: {length: 3, colour: red}\n";
  std::ofstream(dir / "s2.yaml") << "base: sub/broken.yaml\nsweep: {cable.length: [1]}\n";
  StatusOr<SweepSpec> c = read_sweep_file((dir / "s2.yaml").string());
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("broken.yaml:2:20: error: unknown key 'cable.colour'"),
            std::string::npos)
      << c.status().message();
  std::filesystem::remove_all(dir);
}

TEST(SweepSpec, EndsSetsBothEndsAndVariantsSetSeveralKeys) {
  const SweepSpec s = read_ok(kBase + R"(sweep:
  isolation:
    cap: {ends.isolation: {type: cap, cap: 4.7n}}
    transformer: {ends.isolation: {type: transformer, part: HMU1228NL}, tx.series_r: 30}
  ends.termination: [1k, 2k]
)");
  ASSERT_EQ(s.axes.size(), 2u);
  EXPECT_TRUE(s.axes[0].variants);
  EXPECT_EQ(s.axes[0].values[1].label, "transformer");
  EXPECT_EQ(s.point_columns(), (std::vector<std::string>{"isolation", "ends.termination"}));
  const PointOutcome a = make_point(s, 0);
  ASSERT_TRUE(a.status.ok()) << a.status.message();
  EXPECT_EQ(a.point.spec.tx.isolation.type, "cap");
  EXPECT_DOUBLE_EQ(a.point.spec.rx.isolation.cap, 4.7e-9);
  EXPECT_DOUBLE_EQ(*a.point.spec.tx.termination, 1000.0);
  EXPECT_DOUBLE_EQ(*a.point.spec.rx.termination, 1000.0);
  const PointOutcome b = make_point(s, 3);
  ASSERT_TRUE(b.status.ok()) << b.status.message();
  EXPECT_EQ(b.point.cells, (std::vector<std::string>{"transformer", "2000"}));
  EXPECT_EQ(b.point.spec.tx.isolation.type, "transformer");
  EXPECT_EQ(b.point.spec.rx.isolation.part, "HMU1228NL");
  EXPECT_DOUBLE_EQ(*b.point.spec.tx.series_r, 30.0);
  EXPECT_FALSE(b.point.spec.rx.series_r.has_value());
  EXPECT_DOUBLE_EQ(*b.point.spec.rx.termination, 2000.0);
}

const std::string kMc = kBase + R"(sweep:
  cable.length: [1, 2]
monte_carlo:
  samples: 400
  seed: 7
  tolerances:
    tx.isolation.cap: 10%
    rx.isolation.cap: {normal: 30%}
    cable.temperature: {normal: [25, 20]}
    tx.series_r: {uniform: [40, 60]}
)";

TEST(SweepSpec, MonteCarloPointsAndColumns) {
  const SweepSpec s = read_ok(kMc);
  EXPECT_EQ(s.grid_size(), 2u);
  EXPECT_EQ(s.size(), 800u);
  EXPECT_EQ(
      s.point_columns(),
      (std::vector<std::string>{"cable.length", "sample", "mc.tx.isolation.cap",
                                "mc.rx.isolation.cap", "mc.cable.temperature", "mc.tx.series_r"}));
  ASSERT_EQ(s.mc.tolerances.size(), 4u);
  EXPECT_EQ(s.mc.tolerances[0].dist, Dist::kRelUniform);
  EXPECT_DOUBLE_EQ(s.mc.tolerances[0].a, 0.1);
  EXPECT_EQ(s.mc.tolerances[1].dist, Dist::kRelNormal);
  EXPECT_EQ(s.mc.tolerances[2].dist, Dist::kNormal);
  EXPECT_EQ(s.mc.tolerances[3].dist, Dist::kUniform);
  const PointOutcome p = make_point(s, 401);  // grid point 1, sample 1
  ASSERT_TRUE(p.status.ok()) << p.status.message();
  EXPECT_EQ(p.point.grid, 1u);
  EXPECT_EQ(p.point.sample, 1);
  EXPECT_DOUBLE_EQ(p.point.spec.cable.length, 2.0);
  EXPECT_EQ(p.point.cells[1], "1");
  ASSERT_EQ(p.point.mc_values.size(), 4u);
  EXPECT_NEAR(p.point.spec.tx.isolation.cap, p.point.mc_values[0], 1e-6 * 2.2e-9);
  EXPECT_NEAR(p.point.spec.cable.temperature, p.point.mc_values[2], 1e-4);
  EXPECT_NEAR(*p.point.spec.tx.series_r, p.point.mc_values[3], 1e-4);
}

TEST(SweepSpec, MonteCarloIsDeterministicAndSharedAcrossGridPoints) {
  const SweepSpec s = read_ok(kMc);
  const SweepSpec again = read_ok(kMc);
  for (size_t i : {0u, 5u, 399u, 400u, 777u}) {
    const PointOutcome a = make_point(s, i), b = make_point(again, i);
    EXPECT_EQ(a.point.mc_values, b.point.mc_values) << i;
    EXPECT_EQ(a.point.cells, b.point.cells) << i;
  }
  // Sample s draws the same values at every grid point (relative ones around that point's
  // nominal, which is the same here).
  EXPECT_EQ(make_point(s, 3).point.mc_values, make_point(s, 403).point.mc_values);
  EXPECT_NE(make_point(s, 3).point.mc_values, make_point(s, 4).point.mc_values);
  // Another seed, other draws.
  SweepSpec other = s;
  other.mc.seed = 8;
  EXPECT_NE(make_point(other, 3).point.mc_values, make_point(s, 3).point.mc_values);
  EXPECT_EQ(make_point(other, 3).point.mc_values, make_point(s, 4).point.mc_values);  // seed + s
}

TEST(SweepSpec, MonteCarloDrawsStayInsideTheirBounds) {
  const SweepSpec s = read_ok(kMc);
  const std::vector<double> nominal = {2.2e-9, 2.2e-9, 25, 49};
  double lo0 = 1, hi0 = 0, lo3 = 1e9, hi3 = 0;
  for (size_t k = 0; k < 5000; ++k) {
    const std::vector<double> v = draw_sample(s.mc, k, nominal);
    ASSERT_EQ(v.size(), 4u);
    ASSERT_GE(v[0], 2.2e-9 * 0.9);
    ASSERT_LE(v[0], 2.2e-9 * 1.1);
    ASSERT_GE(v[3], 40.0);
    ASSERT_LE(v[3], 60.0);
    lo0 = std::min(lo0, v[0]), hi0 = std::max(hi0, v[0]);
    lo3 = std::min(lo3, v[3]), hi3 = std::max(hi3, v[3]);
  }
  // ... and fill them: 5000 uniform draws come within 0.2 % of each end.
  EXPECT_LT(lo0, 2.2e-9 * 0.902);
  EXPECT_GT(hi0, 2.2e-9 * 1.098);
  EXPECT_LT(lo3, 40.1);
  EXPECT_GT(hi3, 59.9);
}

TEST(SweepSpec, NormalDrawsHaveTheirMeanAndSigma) {
  const SweepSpec s = read_ok(kMc);
  const std::vector<double> nominal = {2.2e-9, 2.2e-9, 25, 49};
  const size_t n = 40000;
  double sum2 = 0, sq2 = 0, sum1 = 0, sq1 = 0;
  for (size_t k = 0; k < n; ++k) {
    const std::vector<double> v = draw_sample(s.mc, k, nominal);
    sum2 += v[2], sq2 += v[2] * v[2];
    const double r = v[1] / 2.2e-9 - 1.0;  // relative deviation, sigma 0.3 / 3 = 0.1
    sum1 += r, sq1 += r * r;
  }
  const double mean2 = sum2 / n, sd2 = std::sqrt(sq2 / n - mean2 * mean2);
  // Mean within 4 standard errors (20 / sqrt(40000) = 0.1), sigma within 2 %.
  EXPECT_NEAR(mean2, 25.0, 0.4);
  EXPECT_NEAR(sd2, 20.0, 0.4);
  const double mean1 = sum1 / n, sd1 = std::sqrt(sq1 / n - mean1 * mean1);
  EXPECT_NEAR(mean1, 0.0, 0.002);
  EXPECT_NEAR(sd1, 0.1, 0.002);
}

TEST(SweepSpec, MonteCarloErrors) {
  // A relative tolerance on a key with no nominal value (the part's inductance).
  const std::string e = read_error(R"(base:
  tx: {isolation: {type: transformer, part: HMU1228NL}}
  rx: {isolation: {type: transformer, part: HMU1228NL}}
monte_carlo:
  samples: 10
  tolerances:
    tx.isolation.inductance: 10%
)");
  EXPECT_NE(e.find("sweep.yaml:7:30: error: tolerance 'tx.isolation.inductance' is relative but "
                   "the key has no nominal value"),
            std::string::npos)
      << e;
  const std::string f = read_error(kBase + R"(monte_carlo:
  samples: 10
  tolerances: {tx.isolation.cap: 10}
)");
  EXPECT_NE(f.find("sweep.yaml:9:34: error: tolerance 'tx.isolation.cap': expected a percentage"),
            std::string::npos)
      << f;
  const std::string g = read_error(kBase + R"(monte_carlo:
  samples: 0
  tolerances: {tx.isolation.cap: 10%}
)");
  EXPECT_NE(g.find("sweep.yaml:8:12: error: key 'monte_carlo.samples' = 0: must be in"),
            std::string::npos)
      << g;
  const std::string h = read_error(kBase + R"(monte_carlo:
  samples: 3
  tolerances: {cable.lenth: 10%}
)");
  EXPECT_NE(h.find("sweep.yaml:9:16: error: sweep key 'cable.lenth' is not a link-spec key"),
            std::string::npos)
      << h;
  EXPECT_NE(read_error(kBase).find("nothing to sweep"), std::string::npos);
}

TEST(SweepSpec, KeyUnitsAndNumbers) {
  EXPECT_EQ(key_unit("rx.isolation.cap"), config::Unit::kFarad);
  EXPECT_EQ(key_unit("ends.isolation.inductance"), config::Unit::kHenry);
  EXPECT_EQ(key_unit("cable.length"), config::Unit::kMetre);
  EXPECT_EQ(key_unit("tx.series_r"), config::Unit::kOhm);
  EXPECT_EQ(key_unit("cable.material"), config::Unit::kNone);
  EXPECT_DOUBLE_EQ(*key_number("tx.isolation.inductance", "150u"), 150e-6);
  EXPECT_DOUBLE_EQ(*key_number("cable.length", "12m"), 12.0);
  EXPECT_FALSE(key_number("cable.material", "pvc").has_value());
}

}  // namespace
}  // namespace isolink::analysis::sweep
