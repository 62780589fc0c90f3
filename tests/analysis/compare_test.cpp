// isolink compare (analysis/compare.h), on synthetic captures whose truth is known: the link
// simulated by the transient engine (compare fits with the LTI model's edge response), then a
// scope's bandwidth limit, clock, noise, 8-bit quantisation and trigger offset, written in a real
// scope layout (synthetic_capture.h).
// - the fitter against closed forms: an RC step's time constant, exactly and with noise (its
//   standard error against the textbook sigma / sqrt(sum (dv/dtau)^2));
// - the superposition at arbitrary times against analysis::synthesize on its grid;
// - a nominal capture: match, no findings, the trigger offset recovered;
// - a halved rx isolation cap, a longer cable, another termination: mismatch, and the fit finds
//   the truth (caps and length within 10 %, termination within 20 %), the finding names the key;
// - a transformer capture against a cap spec: mismatch even after fitting the cable length;
// - a record without pulses: inconclusive; bad keys and bounds: errors.
#include "analysis/compare.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <random>

#include "analysis/compare_model.h"
#include "analysis/worst.h"
#include "base/file_io.h"
#include "reports/compare_report.h"
#include "tests/analysis/synthetic_capture.h"

namespace isolink::analysis {
namespace {

const char* kCapLink = R"(name: cap-2m
tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
cable: {length: 2, material: pp, gauge: 24}
stimulus: {frames: ["stack-write reg=0x0100 data=02B778BC"], direction: down}
)";

const char* kXfmrLink = R"(name: xfmr-2m
tx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
rx: {device: bq7961x, isolation: {type: transformer, part: HMU1228NL}}
cable: {length: 2, material: pp, gauge: 24}
stimulus: {frames: ["stack-write reg=0x0100 data=02B778BC"], direction: down}
)";

std::string tmp_dir() {
  const std::string d =
      (std::filesystem::temp_directory_path() / fmt::format("isolink_compare_test_{}", ::getpid()))
          .string();
  std::filesystem::create_directories(d);
  return d;
}

std::string write_spec(const std::string& name, const char* text) {
  const std::string p = tmp_dir() + "/" + name;
  EXPECT_TRUE(write_file_atomic(p, text).ok());
  return p;
}

const link::PartLibrary& parts() {
  static const link::PartLibrary lib = *link::PartLibrary::load({});
  return lib;
}

// A capture of `spec_text` with `truth` applied, through the scope model.
std::string capture(const std::string& name, const char* spec_text,
                    std::vector<sweep::Assignment> truth, testing::ScopeModel scope = {}) {
  const std::string p = tmp_dir() + "/" + name;
  Status s = testing::write_synthetic_capture(spec_text, name + ".yaml", truth, scope, p);
  EXPECT_TRUE(s.ok()) << s.message();
  return p;
}

CompareResult run(const std::string& cap, const std::string& spec, CompareOptions opt = {},
                  eye::CsvColumns cols = {}) {
  CompareInput in{.files = {cap}, .cols = cols, .spec_path = spec};
  StatusOr<CompareResult> r = compare_capture(in, parts(), opt);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? *r : CompareResult{};
}

TEST(CompareFit, RcTimeConstantExactly) {
  // v(t) = 1 - exp(-t / tau) sampled every 10 ns over 5 us, tau = 470 ns; the fit starts at
  // 1 us and is bounded to [100 ns, 5 us].
  const double tau = 470e-9;
  std::vector<double> t, v;
  for (int i = 0; i < 500; ++i) {
    t.push_back(i * 10e-9);
    v.push_back(1 - std::exp(-t.back() / tau));
  }
  const ResidualFn f = [&](std::span<const double> x, std::vector<double>& r) {
    r.resize(t.size());
    for (size_t i = 0; i < t.size(); ++i) r[i] = v[i] - (1 - std::exp(-t[i] / (x[0] * 1e-9)));
    return Status::Ok();
  };
  StatusOr<LsqResult> fit = fit_least_squares(f, t.size(), {{1000, 100, 5000, 0.01}}, 50);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_NEAR(fit->x[0], 470.0, 1e-6);
  EXPECT_LT(fit->sse, 1e-18);
}

TEST(CompareFit, RcTimeConstantWithNoiseAndItsStandardError) {
  // The same RC with Gaussian noise sigma = 10 mV: the standard error must be the closed form
  // sigma / sqrt(sum_i (dv_i / dtau)^2), dv/dtau = -t / tau^2 exp(-t / tau), and the estimate
  // within 4 of them of the truth.
  const double tau = 470e-9, sigma = 0.01;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0, sigma);
  std::vector<double> t, v;
  double s2 = 0;
  for (int i = 0; i < 500; ++i) {
    t.push_back(i * 10e-9);
    v.push_back(1 - std::exp(-t.back() / tau) + n(rng));
    const double d = -t.back() / (tau * tau) * std::exp(-t.back() / tau) * 1e-9;  // per ns
    s2 += d * d;
  }
  const ResidualFn f = [&](std::span<const double> x, std::vector<double>& r) {
    r.resize(t.size());
    for (size_t i = 0; i < t.size(); ++i) r[i] = v[i] - (1 - std::exp(-t[i] / (x[0] * 1e-9)));
    return Status::Ok();
  };
  StatusOr<LsqResult> fit = fit_least_squares(f, t.size(), {{1000, 100, 5000, 0.01}}, 50);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  const double se = sigma / std::sqrt(s2);  // ns
  EXPECT_NEAR(fit->stderr_x[0], se, 0.15 * se);
  EXPECT_NEAR(fit->x[0], 470.0, 4 * se);
}

TEST(CompareFit, TwoProportionalParametersAreNotIdentifiable) {
  // v = a b t: only the product is determined; the fit must say so for both.
  std::vector<double> t, v;
  for (int i = 1; i <= 50; ++i) {
    t.push_back(i);
    v.push_back(6.0 * i);
  }
  const ResidualFn f = [&](std::span<const double> x, std::vector<double>& r) {
    r.resize(t.size());
    for (size_t i = 0; i < t.size(); ++i) r[i] = v[i] - x[0] * x[1] * t[i];
    return Status::Ok();
  };
  StatusOr<LsqResult> fit =
      fit_least_squares(f, t.size(), {{1, 0.1, 10, 0.01}, {1, 0.1, 10, 0.01}}, 50);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_NEAR(fit->x[0] * fit->x[1], 6.0, 1e-6);
  EXPECT_FALSE(fit->identifiable[0]);
  EXPECT_FALSE(fit->identifiable[1]);
}

TEST(CompareFit, CorrelationOfAStraightLineIsTheClosedForm) {
  // v = a + b t at t = 1..20 with noise: least squares' covariance is sigma^2 (X^T X)^-1, so
  // corr(a, b) = -mean(t) / sqrt(mean(t^2)) whatever the noise: -10.5 / sqrt(143.5) = -0.8765.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0, 0.1);
  std::vector<double> t, v;
  for (int i = 1; i <= 20; ++i) {
    t.push_back(i);
    v.push_back(3.0 + 0.5 * i + n(rng));
  }
  const ResidualFn f = [&](std::span<const double> x, std::vector<double>& r) {
    r.resize(t.size());
    for (size_t i = 0; i < t.size(); ++i) r[i] = v[i] - (x[0] + x[1] * t[i]);
    return Status::Ok();
  };
  StatusOr<LsqResult> fit =
      fit_least_squares(f, t.size(), {{1, -10, 10, 0.01}, {1, -10, 10, 0.01}}, 50);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ASSERT_EQ(fit->correlation.size(), 4u);
  EXPECT_NEAR(fit->correlation[1], -10.5 / std::sqrt(143.5), 1e-6);
  EXPECT_NEAR(fit->correlation[2], fit->correlation[1], 1e-12);
  EXPECT_DOUBLE_EQ(fit->correlation[0], 1.0);
}

TEST(CompareFit, DefaultBoundsCoverAWrongMultiplierDigit) {
  CompareOptions opt;
  using compare_detail::fit_bounds;
  auto b = fit_bounds(opt, "rx.isolation.cap", 2.2e-9);  // C: 1/10..10x
  ASSERT_TRUE(b.ok());
  EXPECT_NEAR(b->first, 0.22e-9, 1e-18);
  EXPECT_NEAR(b->second, 22e-9, 1e-18);
  b = fit_bounds(opt, "ends.termination", 1000);  // R: 1/10..10x
  EXPECT_NEAR(b->first, 100, 1e-9);
  EXPECT_NEAR(b->second, 10000, 1e-9);
  b = fit_bounds(opt, "rx.isolation.leakage", 0.5e-6);  // L: 1/10..2x
  EXPECT_NEAR(b->first, 0.05e-6, 1e-15);
  EXPECT_NEAR(b->second, 1e-6, 1e-15);
  b = fit_bounds(opt, "cable.length", 8);  // 0.1..100 m
  EXPECT_DOUBLE_EQ(b->first, 0.1);
  EXPECT_DOUBLE_EQ(b->second, 100);
  b = fit_bounds(opt, "cable.length", 150);  // widened to hold the design
  EXPECT_DOUBLE_EQ(b->second, 150);
  opt.bounds["cable.length"] = {1, 30};  // --bounds overrides
  b = fit_bounds(opt, "cable.length", 8);
  EXPECT_DOUBLE_EQ(b->first, 1);
  EXPECT_DOUBLE_EQ(b->second, 30);
  opt.bounds["cable.length"] = {10, 30};  // must hold the design
  b = fit_bounds(opt, "cable.length", 8);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("cable.length=10:30"), std::string::npos);
}

// Issue 43's honest end: another point of the bounds that explains the capture within its noise
// and differs from the kept solution beyond a key's band makes that key not separable (its
// alternatives listed, no finding), while a key on which the two agree keeps its finding.
TEST(CompareFit, NearSolutionElsewhereMakesTheKeysItMovesNotSeparable) {
  CompareOptions opt;
  opt.fit = {"cable.length", "rx.termination"};
  const std::vector<DesignValue> design = {{3.0, 0.10, 0.10, "10 %"}, {1000, 0.10, 0.10, "1 %"}};
  const std::vector<std::pair<double, double>> bounds = {{0.3, 30}, {100, 10000}};
  compare_detail::FitSolution best;
  best.x = {std::log(2.0 / 3.0), std::log(2.0)};  // 2 m, 2 kohm
  best.lsq.stderr_x = {0.001, 0.001, 0.01};
  best.lsq.identifiable = {true, true, true};
  best.lsq.correlation = {1, 0.1, 0, 0.1, 1, 0, 0, 0, 1};
  CompareResult r;
  r.noise_rms_v = 0.010;
  r.search.chosen_rms_v = 0.012;
  // 2.6 m (a different answer) with 2.1 kohm (the same one: within its 10 % band).
  const std::vector<compare_detail::NearSolution> near = {
      {{std::log(2.6 / 3.0), std::log(2.1)}, 0.0125}};
  compare_detail::report_fit(opt, design, bounds, best, near, r);
  ASSERT_EQ(r.fit.size(), 2u);
  EXPECT_FALSE(r.fit[0].identifiable);
  ASSERT_EQ(r.fit[0].alternatives.size(), 1u);
  EXPECT_NEAR(r.fit[0].alternatives[0], 2.6, 1e-9);
  EXPECT_TRUE(r.fit[1].identifiable);
  EXPECT_TRUE(r.fit[1].alternatives.empty());
  ASSERT_EQ(r.findings.size(), 1u);  // the termination's, not the cable's
  EXPECT_EQ(r.findings[0].key, "rx.termination");
  bool said = false;
  for (const std::string& s : r.reasons)
    said = said || (s.find("cable length is not separable") != std::string::npos &&
                    s.find("2.6 m") != std::string::npos &&
                    s.find("none of the answers is the design") != std::string::npos);
  EXPECT_TRUE(said) << fmt::format("{}", fmt::join(r.reasons, "\n"));
  // The JSON carries the other answer and the multiple correlation (0 with two keys).
  r.search.near = 1;
  const nlohmann::ordered_json j = reports::compare_json(r);
  ASSERT_EQ(j["fit"]["cable.length"]["alternatives"].size(), 1u);
  EXPECT_NEAR(j["fit"]["cable.length"]["alternatives"][0].get<double>(), 2.6, 1e-9);
  EXPECT_TRUE(j["fit"]["rx.termination"]["alternatives"].empty());
  EXPECT_EQ(j["fit"]["rx.termination"]["multiple_correlation"], 0.0);
  EXPECT_EQ(j["search"]["near"], 1);
  // With the design among the near answers it is a note, not a reason.
  CompareResult r2;
  r2.noise_rms_v = 0.010;
  const std::vector<compare_detail::NearSolution> near_design = {{{0.0, 0.0}, 0.0125}};
  compare_detail::report_fit(opt, design, bounds, best, near_design, r2);
  EXPECT_FALSE(r2.fit[0].identifiable);
  EXPECT_FALSE(r2.fit[1].identifiable);
  EXPECT_TRUE(r2.findings.empty());
  for (const std::string& s : r2.reasons) EXPECT_EQ(s.find("not separable"), std::string::npos);
  bool noted = false;
  for (const std::string& s : r2.notes)
    noted = noted || s.find("are not separable") != std::string::npos;
  EXPECT_TRUE(noted);
}

// Three keys whose pairs all stay under 0.95 except one, and a third key tied to the two together
// (the corpus's seed 59: multiple correlation 0.953): inseparable from them, no finding.
TEST(CompareFit, KeyTiedToTheOthersTogetherIsNotSeparable) {
  CompareOptions opt;
  opt.fit = {"tx.isolation.inductance", "rx.termination", "rx.isolation.cap"};
  const std::vector<DesignValue> design = {
      {260e-6, 0.10, 0.10, "10 %"}, {1000, 0.10, 0.10, "1 %"}, {2.2e-9, 0.10, 0.10, "10 %"}};
  const std::vector<std::pair<double, double>> bounds = {
      {26e-6, 520e-6}, {100, 10000}, {0.22e-9, 22e-9}};
  compare_detail::FitSolution best;
  best.x = {std::log(352.7 / 260), std::log(0.5904), std::log(3.724 / 2.2)};
  best.lsq.stderr_x = {0.003, 0.001, 0.002, 0.01};
  best.lsq.identifiable = {true, true, true, true};
  const double a = 0.879, b = -0.946, c = -0.962;
  best.lsq.correlation = {1, a, b, 0, a, 1, c, 0, b, c, 1, 0, 0, 0, 0, 1};
  CompareResult r;
  compare_detail::report_fit(opt, design, bounds, best, {}, r);
  ASSERT_EQ(r.fit.size(), 3u);
  EXPECT_NEAR(r.fit[0].multiple_correlation, 0.953, 0.001);
  EXPECT_FALSE(r.fit[0].identifiable);
  EXPECT_TRUE(r.findings.empty());  // the pair (termination, cap) by its own correlation
  bool said = false;
  for (const std::string& s : r.reasons)
    said = said || s.find(
                       "tx isolation inductance (352.7 uH) is correlated with rx termination "
                       "and rx isolation cap together (0.953") != std::string::npos;
  EXPECT_TRUE(said) << fmt::format("{}", fmt::join(r.reasons, "\n"));
}

TEST(CompareModel, SuperpositionAtAnyTimeEqualsTheGridSynthesis) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(kCapLink, "cap.yaml");
  ASSERT_TRUE(spec.ok());
  StatusOr<EdgeResponse> e = edge_response(*spec, parts(), link::Direction::kDown, {});
  ASSERT_TRUE(e.ok()) << e.status().message();
  Traffic tr{.frames = {{0x5A, 0}, {0xC3, 1}}, .gaps = {1e-6, 3.8e-6}};
  traffic::EncodingOptions enc;
  const Waveform w = synthesize(*e, tr, enc, 0, 30e-6);
  compare_detail::EdgeList edges;
  // The same two frames as level changes (what compare replays from decoded frames).
  for (size_t f = 0; f < 2; ++f) {
    traffic::EncodingOptions ef = enc;
    ef.error_bit = tr.frames[f].error_bit;
    const std::vector<int> hb = traffic::byte_half_bits(tr.frames[f].byte, ef);
    const double t0 = tr.frame_start(f, traffic::byte_duration(enc));
    int level = 0;
    for (size_t j = 0; j <= hb.size(); ++j) {
      const int next = j < hb.size() ? hb[j] : 0;
      if (next != level) edges.t.push_back(t0 + j * enc.half_bit), edges.dl.push_back(next - level);
      level = next;
    }
  }
  std::vector<double> out(w.time.size());
  compare_detail::synth_at(*e, edges, 0.0, w.time, out);
  double worst = 0;
  for (size_t i = 0; i < out.size(); ++i)
    worst = std::max(worst, std::abs(out[i] - w.columns[0][i]));
  EXPECT_LT(worst, 1e-9);
  // Half a sample later, each value is the mean of its neighbours' (linear interpolation).
  std::vector<double> mid(w.time.size() - 1), tm(w.time.size() - 1);
  for (size_t i = 0; i + 1 < w.time.size(); ++i) tm[i] = (w.time[i] + w.time[i + 1]) / 2;
  compare_detail::synth_at(*e, edges, 0.0, tm, mid);
  for (size_t i = 0; i + 1 < w.time.size(); i += 997)
    EXPECT_NEAR(mid[i], (w.columns[0][i] + w.columns[0][i + 1]) / 2, 1e-9);
}

// The alignment of a record longer than its 2 ms span (align: the span's grid and refinement):
// 40 frames over 4 ms, sampled every 2 ns within each frame's window, laid at a sub-nanosecond
// offset and guessed 0.6 us off: the offset comes back to 1 ps.
TEST(CompareModel, AlignmentOfALongRecordUsesItsFirstSpan) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(kCapLink, "cap.yaml");
  ASSERT_TRUE(spec.ok());
  StatusOr<EdgeResponse> e = edge_response(*spec, parts(), link::Direction::kDown, {});
  ASSERT_TRUE(e.ok()) << e.status().message();
  traffic::EncodingOptions enc;
  compare_detail::EdgeList edges;
  std::vector<double> ts;
  for (int f = 0; f < 40; ++f) {
    const uint8_t byte = static_cast<uint8_t>(0x35 + 17 * f);
    const std::vector<int> hb = traffic::byte_half_bits(byte, enc);
    const double t0 = 10e-6 + 100e-6 * f;
    int level = 0;
    for (size_t j = 0; j <= hb.size(); ++j) {
      const int next = j < hb.size() ? hb[j] : 0;
      if (next != level) edges.t.push_back(t0 + j * enc.half_bit), edges.dl.push_back(next - level);
      level = next;
    }
    const double t1 = t0 + static_cast<double>(hb.size()) * enc.half_bit;
    edges.frames.push_back({t0, t1});
    for (double t = t0 - 1e-6; t < t1 + 2e-6; t += 2e-9) ts.push_back(t + 3.3e-6);
  }
  const double truth = 3.3e-6 + 0.37e-9;
  std::vector<double> vs(ts.size());
  compare_detail::synth_at(*e, edges, truth, ts, vs);
  ASSERT_GT(ts.back() - ts.front(), 3.9e-3);
  const double found = compare_detail::align(*e, edges, ts, vs, truth + 0.6e-6, 1e-6, 200e-9, {});
  EXPECT_NEAR(found, truth, 1e-12);
}

TEST(Compare, NominalCaptureMatchesAndTheTriggerOffsetIsRecovered) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  testing::ScopeModel scope;  // 2.5 GS/s, 300 MHz, 10 mV, 8 bits over +/-5 V, 3.3 us
  const CompareResult r = run(capture("nominal.csv", kCapLink, {}, scope), spec);
  EXPECT_EQ(r.verdict, "match") << reports::compare_text(r);
  EXPECT_TRUE(r.findings.empty());
  EXPECT_EQ(r.traffic_from, "capture: 9 frames decoded");
  // Drive time t is capture time t + trigger, plus the bandwidth limit's delay (tau = 0.53 ns).
  EXPECT_NEAR(r.offset_s, scope.trigger, 1.5e-9);
  // The noise estimate: 10 mV per channel, the differential sqrt(2) x; quantised at 10 V / 256.
  EXPECT_NEAR(r.quant_step_v, 10.0 / 256, 1e-6);
  EXPECT_NEAR(r.noise_rms_v, 10e-3 * std::sqrt(2.0), 4e-3);
  // Its peaks (about 4.5 V) stay inside the +/-5 V range: no rail.
  EXPECT_FALSE(r.clipping.high_v || r.clipping.low_v) << reports::compare_text(r);
  EXPECT_EQ(r.residual.clipped, 0u);
}

// A scope range too small for the link: the ADC puts every sample beyond it on its end codes,
// +3 V - q and -3 V (q = 6 V / 256). Those are found as rails, the design's excess over them is
// not counted, and the nominal capture matches; the same scope on a link with five times the
// series resistance (lower, slower pulses) stays a mismatch, and so does a narrower range that
// cuts both captures to a third of their swing.
TEST(Compare, ClippedCaptureMatchesWhereTheScopesRangeCutTheDesign) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  testing::ScopeModel scope;
  scope.range_v = 3.0;
  const double q = 6.0 / 256;
  const CompareResult r = run(capture("clipped.csv", kCapLink, {}, scope), spec);
  EXPECT_EQ(r.verdict, "match") << reports::compare_text(r);
  ASSERT_TRUE(r.clipping.high_v && r.clipping.low_v) << reports::compare_text(r);
  EXPECT_NEAR(*r.clipping.high_v, 3.0 - q, 1e-6);
  EXPECT_NEAR(*r.clipping.low_v, -3.0, 1e-6);
  EXPECT_GT(r.residual.clipped, 100u);
  EXPECT_NE(reports::compare_text(r).find("the capture clips at -3 V and +2.977 V"),
            std::string::npos)
      << reports::compare_text(r);
  for (double range : {3.0, 1.5}) {
    scope.range_v = range;
    const CompareResult w =
        run(capture("clipped_wrong.csv", kCapLink, {{"tx.series_r", "245", true}}, scope), spec);
    EXPECT_EQ(w.verdict, "mismatch") << range << " V\n" << reports::compare_text(w);
  }
}

TEST(Compare, HalvedRxCapIsAMismatchAndTheFitFindsIt) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  testing::ScopeModel scope;
  scope.sample_rate = 1.25e9;
  scope.bandwidth = 200e6;
  scope.noise_v = 15e-3;
  scope.trigger = -2.7e-6;
  scope.layout = "rigol";
  const std::string cap =
      capture("half_cap.csv", kCapLink, {{"rx.isolation.cap", "1.1n", true}}, scope);
  eye::CsvColumns cols{.p = "CH1", .n = "CH2"};
  const CompareResult before = run(cap, spec, {}, cols);
  EXPECT_EQ(before.verdict, "mismatch");
  CompareOptions opt;
  opt.fit = {"rx.isolation.cap"};
  const CompareResult r = run(cap, spec, opt, cols);
  EXPECT_EQ(r.verdict, "mismatch");
  ASSERT_EQ(r.fit.size(), 1u);
  EXPECT_NEAR(r.fit[0].value, 1.1e-9, 0.1 * 1.1e-9) << reports::compare_text(r);
  EXPECT_DOUBLE_EQ(r.fit[0].initial, 2.2e-9);
  EXPECT_NEAR(r.fit[0].low, 0.22e-9, 1e-15);  // the default bounds: 1/10..10x
  EXPECT_NEAR(r.fit[0].high, 22e-9, 1e-15);
  EXPECT_TRUE(r.fit[0].at_bound.empty());
  ASSERT_EQ(r.findings.size(), 1u);
  EXPECT_EQ(r.findings[0].key, "rx.isolation.cap");
  EXPECT_NEAR(r.findings[0].change_rel, -0.5, 0.05);
  EXPECT_NE(r.findings[0].text.find("rx isolation cap behaves like"), std::string::npos);
  ASSERT_TRUE(r.residual_after_fit);
  EXPECT_LT(r.residual_after_fit->rms_v, r.threshold_rms_v);
  EXPECT_LT(r.residual_after_fit->rms_v, 0.5 * r.residual.rms_v);
}

TEST(Compare, CableLengthAndTerminationAreRecovered) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = capture(
      "long.csv", kCapLink, {{"cable.length", "3.2", true}, {"rx.termination", "1300", true}});
  CompareOptions opt;
  opt.fit = {"cable.length", "rx.termination"};
  const CompareResult r = run(cap, spec, opt);
  ASSERT_EQ(r.fit.size(), 2u);
  EXPECT_NEAR(r.fit[0].value, 3.2, 0.32) << reports::compare_text(r);
  EXPECT_NEAR(r.fit[1].value, 1300, 260) << reports::compare_text(r);
  EXPECT_EQ(r.verdict, "mismatch");  // both are outside their 10 % bands
  EXPECT_EQ(r.findings.size(), 2u);
}

// A scope drawn within the issue's ranges (1.25-2.5 GS/s, 200-350 MHz, 5-15 mV per channel,
// trigger -5..+5 us; 8 bits), from a fixed seed so that a failure reproduces; odd seeds write a
// Rigol CSV with P and N, even ones a Keysight CSV of the differential.
testing::ScopeModel random_scope(uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto u = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  testing::ScopeModel s;
  s.sample_rate = u(1.25e9, 2.5e9);
  s.bandwidth = u(200e6, 350e6);
  s.noise_v = u(5e-3, 15e-3);
  s.trigger = u(-5e-6, 5e-6);
  s.seed = seed;
  s.layout = seed % 2 ? "rigol" : "keysight";
  return s;
}
eye::CsvColumns columns_of(const testing::ScopeModel& s) {
  return s.layout == "rigol" ? eye::CsvColumns{.p = "CH1", .n = "CH2"} : eye::CsvColumns{};
}

// One key of the 2 m transformer link made `truth` and fitted from the design: within 20 % (the
// issue's figure for leakage, magnetising inductance and termination), identifiable, named in a
// finding, and the trigger offset found again.
void expect_recovered(const std::string& key, const std::string& truth, double truth_si,
                      uint64_t seed, std::optional<std::pair<double, double>> bounds = {}) {
  const std::string spec = write_spec("xfmr.yaml", kXfmrLink);
  const testing::ScopeModel scope = random_scope(seed);
  const std::string cap = capture(key + ".csv", kXfmrLink, {{key, truth, true}}, scope);
  CompareOptions opt;
  opt.fit = {key};
  if (bounds) opt.bounds[key] = *bounds;
  const CompareResult r = run(cap, spec, opt, columns_of(scope));
  ASSERT_EQ(r.fit.size(), 1u);
  EXPECT_NEAR(r.fit[0].value, truth_si, 0.2 * truth_si) << reports::compare_text(r);
  EXPECT_TRUE(r.fit[0].identifiable) << reports::compare_text(r);
  ASSERT_EQ(r.findings.size(), 1u) << reports::compare_text(r);
  EXPECT_EQ(r.findings[0].key, key);
  EXPECT_EQ(r.verdict, "mismatch");
  ASSERT_TRUE(r.residual_after_fit);
  EXPECT_LT(r.residual_after_fit->rms_v, r.threshold_rms_v) << reports::compare_text(r);
  ASSERT_TRUE(r.offset_after_fit_s);
  EXPECT_NEAR(*r.offset_after_fit_s, scope.trigger, 2e-9);
}

TEST(Compare, TransformerLeakageIsRecovered) {
  // design 0.5 uH; 1.2 uH is past the default 2x bound (an inductance): --bounds widens it
  expect_recovered("rx.isolation.leakage", "1.2u", 1.2e-6, 11, std::pair{0.05e-6, 5e-6});
}

TEST(Compare, MagnetisingInductanceIsRecovered) {
  expect_recovered("rx.isolation.inductance", "120u", 120e-6, 12);  // design 260 uH (150-370)
}

TEST(Compare, TerminationOfATransformerLinkIsRecovered) {
  expect_recovered("rx.termination", "1.6k", 1600, 13);  // design 1 kohm (bq7961x board)
}

// Issue 43's first case: a termination 30x its design, beyond the default 10x bound. The fit
// stops at the bound and says so: no finding, the value marked as the bound, a reason naming it.
// With --bounds wide enough it is found (within 20 %).
TEST(Compare, TerminationBeyondItsBoundIsReportedAtTheBound) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = capture("term30k.csv", kCapLink, {{"rx.termination", "30k", true}});
  CompareOptions opt;
  opt.fit = {"rx.termination"};
  const CompareResult r = run(cap, spec, opt);
  ASSERT_EQ(r.fit.size(), 1u);
  EXPECT_EQ(r.fit[0].at_bound, "high") << reports::compare_text(r);
  EXPECT_NEAR(r.fit[0].value, 10e3, 0.01 * 10e3);
  EXPECT_TRUE(r.findings.empty()) << reports::compare_text(r);
  EXPECT_EQ(r.verdict, "mismatch");
  bool said = false;
  for (const std::string& x : r.reasons) said = said || x.find("at its upper bound") != x.npos;
  EXPECT_TRUE(said) << reports::compare_text(r);
  opt.bounds["rx.termination"] = {100, 100e3};
  const CompareResult w = run(cap, spec, opt);
  ASSERT_EQ(w.fit.size(), 1u);
  EXPECT_NEAR(w.fit[0].value, 30e3, 0.2 * 30e3) << reports::compare_text(w);
  EXPECT_TRUE(w.fit[0].at_bound.empty());
  ASSERT_EQ(w.findings.size(), 1u);
}

// Issue 43's second case: a cable far from the design (12 m against 2 m). The refinement from
// the design alone stays in its valley; the scan finds the truth within 10 %.
TEST(Compare, CableFarFromTheDesignIsFoundByTheScan) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = capture("cable12.csv", kCapLink, {{"cable.length", "12", true}});
  CompareOptions opt;
  opt.fit = {"cable.length"};
  const CompareResult r = run(cap, spec, opt);
  ASSERT_EQ(r.fit.size(), 1u);
  EXPECT_NEAR(r.fit[0].value, 12, 1.2) << reports::compare_text(r);
  EXPECT_TRUE(r.search.scanned) << reports::compare_text(r);
  ASSERT_TRUE(r.residual_after_fit);
  EXPECT_LT(r.residual_after_fit->rms_v, r.threshold_rms_v) << reports::compare_text(r);
  opt.global_search = false;
  const CompareResult l = run(cap, spec, opt);
  ASSERT_EQ(l.fit.size(), 1u);
  EXPECT_GT(std::abs(l.fit[0].value / 12 - 1), 0.1) << reports::compare_text(l);
}

// A residual the fitted key cannot explain (the driver's series resistor 5x its design, the
// rx cap fitted): the output locates it (a frame, a pulse near it, the time of the largest
// deviation, which is that deviation) and suggests keys by their sensitivity there, the series
// resistors among them.
TEST(Compare, UnexplainedResidualIsLocatedWithTheKeysThatMoveIt) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = capture("series5x.csv", kCapLink, {{"tx.series_r", "245", true}});
  CompareOptions opt;
  opt.fit = {"rx.isolation.cap"};
  const CompareResult r = run(cap, spec, opt);
  ASSERT_TRUE(r.unexplained) << reports::compare_text(r);
  const ResidualPlace& pl = *r.unexplained;
  ASSERT_LT(pl.window, r.windows.size());
  EXPECT_GE(pl.time, r.windows[pl.window].first);
  EXPECT_LE(pl.time, r.windows[pl.window].second);
  ASSERT_TRUE(r.residual_after_fit);
  EXPECT_NEAR(std::abs(pl.residual_v), r.residual_after_fit->max_v, 1e-9);
  ASSERT_TRUE(pl.pulse);
  const eye::PulseMetrics& p = r.check.pulses[*pl.pulse];
  EXPECT_LT(std::max({0.0, p.a - pl.time, pl.time - p.b}), 1e-6);
  ASSERT_FALSE(pl.suggested.empty());
  bool series = false;
  for (const auto& sg : pl.suggested) {
    EXPECT_NE(sg.key, "rx.isolation.cap");  // fitted already
    series = series || sg.key.find("series_r") != std::string::npos;
  }
  EXPECT_TRUE(series) << reports::compare_text(r);
  for (size_t i = 1; i < pl.suggested.size(); ++i)
    EXPECT_GE(pl.suggested[i - 1].sensitivity_v, pl.suggested[i].sensitivity_v);
  EXPECT_EQ(r.verdict, "mismatch");
}

TEST(Compare, TransformerCaptureAgainstACapSpecStaysAMismatch) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = capture("xfmr.csv", kXfmrLink, {});
  CompareOptions opt;
  opt.fit = {"cable.length"};
  const CompareResult r = run(cap, spec, opt);
  EXPECT_EQ(r.verdict, "mismatch") << reports::compare_text(r);
  ASSERT_TRUE(r.residual_after_fit);
  EXPECT_GT(r.residual_after_fit->rms_v, r.threshold_rms_v);
}

TEST(Compare, BrokenLinkThatDecodesNothingIsFittedFromTheSpecStimulus) {
  // A 47 pF rx cap: no pulse stays past the threshold, nothing decodes; the spec's stimulus is
  // the traffic, aligned on the pulses' edges, and the fit finds the cap within 10 %.
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = capture("broken.csv", kCapLink, {{"rx.isolation.cap", "47p", true}});
  CompareOptions opt;
  opt.fit = {"rx.isolation.cap"};
  opt.bounds["rx.isolation.cap"] = {20e-12, 10e-9};
  const CompareResult r = run(cap, spec, opt);
  EXPECT_TRUE(r.check.frames.empty());
  EXPECT_EQ(r.traffic_from, "spec stimulus (nothing decoded)");
  EXPECT_EQ(r.verdict, "mismatch");
  ASSERT_EQ(r.fit.size(), 1u);
  EXPECT_NEAR(r.fit[0].value, 47e-12, 4.7e-12) << reports::compare_text(r);
  ASSERT_TRUE(r.offset_after_fit_s);
  EXPECT_NEAR(*r.offset_after_fit_s, 3.3e-6, 1.5e-9);  // the trigger, as made
  EXPECT_LT(r.noise_rms_v, 0.03);  // the traffic's windows are not taken for idle
}

TEST(Compare, RecordWithoutPulsesIsInconclusive) {
  std::string text = "x-axis,1\nsecond,Volt\n";
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 0.01);
  for (int i = 0; i < 20000; ++i) text += fmt::format("{:.6e},{:.5f}\n", i * 4e-10, n(rng));
  const std::string cap = tmp_dir() + "/quiet.csv";
  ASSERT_TRUE(write_file_atomic(cap, text).ok());
  const CompareResult r = run(cap, write_spec("cap.yaml", kCapLink));
  EXPECT_EQ(r.verdict, "inconclusive");
}

TEST(Compare, BadKeysAndBoundsAreRefused) {
  const std::string spec = write_spec("cap.yaml", kCapLink);
  const std::string cap = tmp_dir() + "/tiny.csv";  // checked before the capture is looked at
  ASSERT_TRUE(write_file_atomic(cap, "t,v\n0,0\n1e-9,0.1\n2e-9,0\n").ok());
  CompareInput in{.files = {cap}, .spec_path = spec};
  CompareOptions opt;
  opt.fit = {"rx.isolation.colour"};
  StatusOr<CompareResult> r = compare_capture(in, parts(), opt);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("rx.isolation.colour"), std::string::npos);
  opt.fit = {"cable.gauge"};
  EXPECT_FALSE(compare_capture(in, parts(), opt).ok());
  opt.fit = {"cable.length"};
  opt.bounds["cable.length"] = {5, 10};  // does not hold the design's 2 m
  r = compare_capture(in, parts(), opt);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("--bounds"), std::string::npos);
}

TEST(Compare, DesignValuesComeFromTheSpecTheBoardAndThePart) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_text(kXfmrLink, "x.yaml");
  ASSERT_TRUE(spec.ok());
  StatusOr<DesignValue> l = design_value(*spec, parts(), "rx.isolation.inductance");
  ASSERT_TRUE(l.ok()) << l.status().message();
  EXPECT_GT(l->value, 150e-6);  // HMU1228NL: OCL 150-370 uH
  EXPECT_LT(l->value, 370e-6);
  StatusOr<DesignValue> t = design_value(*spec, parts(), "rx.termination");
  ASSERT_TRUE(t.ok());
  EXPECT_DOUBLE_EQ(t->value, 1000);  // the bq7961x board preset
  EXPECT_DOUBLE_EQ(t->tol_low, 0.10);
}

}  // namespace
}  // namespace isolink::analysis
