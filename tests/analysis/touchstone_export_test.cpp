// A native cable's S-parameters from the AC analysis (analysis/touchstone_export.h), written as
// .s4p, read back and fitted as the cable: the link's waveform against the native cable's.
#include "analysis/touchstone_export.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <random>

#include "analysis/link_run.h"
#include "analysis/noise.h"
#include "base/file_io.h"
#include "netlists/link/touchstone_cable.h"
#include "solver/vector_fit.h"

namespace isolink::analysis {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          fmt::format("isolink_ts_{}_{}", ::getpid(), name))
      .string();
}

// Largest |v_a - v_b| of column k over a's time grid.
double max_difference(const Waveform& a, const Waveform& b, size_t k) {
  double worst = 0;
  for (size_t i = 0; i < a.samples(); ++i)
    worst = std::max(worst, std::abs(a.columns[k][i] - b.value_at(k, a.time[i])));
  return worst;
}

// An example spec, sent down only.
StatusOr<link::LinkSpec> example_down(const std::string& name) {
  StatusOr<link::LinkSpec> spec =
      link::read_link_spec_file(std::string(ISOLINK_EXAMPLES_DIR) + "/" + name);
  if (spec.ok()) spec->stimulus.directions = {link::Direction::kDown};
  return spec;
}

StatusOr<LinkRun> run_lti(const link::LinkSpec& spec, const link::PartLibrary& parts) {
  RunOptions ro;
  ro.engine = Engine::Lti;
  return run_link(spec, parts, ro);
}

// The spec with its cable replaced by the Touchstone file at path.
// The cable exported to 200 MHz (500 points) as a temporary .s4p: its path.
StatusOr<std::string> exported_to_200mhz(const link::CableSpec& cable, const char* name) {
  TouchstoneExportOptions o;
  o.f_stop = 200e6;
  StatusOr<Touchstone> t = cable_touchstone(cable, o);
  if (!t.ok()) return t.status();
  const std::string path = temp_path(name);
  if (Status w = write_file_atomic(path, write_touchstone(*t, "test")); !w.ok()) return w;
  return path;
}

link::LinkSpec with_measured_cable(const link::LinkSpec& spec, const std::string& path) {
  link::LinkSpec measured = spec;
  measured.cable = link::CableSpec{};
  measured.cable.touchstone = path;
  return measured;
}

struct Case {
  const char* spec;
  double f_start;
  double noise;  // RMS of complex Gaussian noise added to every S entry
};

void check_case(const Case& c, double limit_mv) {
  StatusOr<link::LinkSpec> spec = example_down(c.spec);
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<LinkRun> native = run_lti(*spec, *parts);
  ASSERT_TRUE(native.ok()) << native.status().message();

  TouchstoneExportOptions o;
  o.f_start = c.f_start;
  StatusOr<Touchstone> t = cable_touchstone(spec->cable, o);
  ASSERT_TRUE(t.ok()) << t.status().message();
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0, c.noise / std::sqrt(2.0));
  if (c.noise > 0)
    for (auto& s : t->s)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) s(i, j) += std::complex<double>(g(rng), g(rng));
  const std::string path = temp_path(fmt::format("{}.s4p", c.f_start));
  ASSERT_TRUE(write_file_atomic(path, write_touchstone(*t, "test")).ok());

  const link::LinkSpec measured = with_measured_cable(*spec, path);
  auto fit = link::touchstone_cable(measured.cable);
  ASSERT_TRUE(fit.ok()) << c.spec << " " << c.f_start << " " << fit.status().message();
  std::printf(
      "fit: %zu poles, order %d, rms %.3g max %.3g at %.3g Hz, passive %d (min eig %.3g at %g Hz, "
      "%d perturbations, added %.3g S)\n",
      (*fit)->fit.model.poles.size(), (*fit)->fit.model.order(), (*fit)->fit.rms_error,
      (*fit)->fit.error, (*fit)->fit.error_frequency, (*fit)->passivity.passive,
      (*fit)->passivity.min_eigenvalue, (*fit)->passivity.at_frequency,
      (*fit)->passivity.perturbation_iterations, (*fit)->passivity.added_conductance);
  StatusOr<LinkRun> run = run_lti(measured, *parts);
  ASSERT_TRUE(run.ok()) << run.status().message();
  std::printf("native %s %.2f s, fitted %s %.2f s (method %s, note %s, model %.2f s order %d)\n",
              engine_name(native->directions[0].sim.engine), native->directions[0].sim.seconds,
              engine_name(run->directions[0].sim.engine), run->directions[0].sim.seconds,
              run->directions[0].sim.lti.method.c_str(), run->directions[0].sim.lti.note.c_str(),
              run->directions[0].sim.lti.model_seconds, run->directions[0].sim.lti.model.order);
  std::cout << "Y0 fit\n" << (*fit)->dc_conductance.row(0) << "\n";
  ASSERT_TRUE(run.ok()) << run.status().message();
  const Waveform& a = native->directions[0].sim.wave;
  const Waveform& b = run->directions[0].sim.wave;
  const double diff = max_difference(a, b, 0);
  std::printf("%s from %g Hz, noise %g: |dv(rxp,rxn)| <= %.3f mV (engine %s)\n", c.spec, c.f_start,
              c.noise, diff * 1e3, engine_name(run->directions[0].sim.engine));
  EXPECT_LT(diff, limit_mv * 1e-3);
  std::remove(path.c_str());
}

// The figure: within 2 mV of the native cable. Measured 2026-12-07: 0.014 mV (0.85 mV
// before the extrapolation below the band added points from 1e-3 of the first frequency, 4 a
// decade, and weighed the lowest points most; 0.96 mV before the passivity enforcement's
// inequalities; 1.30 mV before the fit in the ends' sum and difference, vector_fit.h Weighting).
TEST(TouchstoneExport, CapLink2mReadBackWithin2mV) {
  check_case({"cap_2m.yaml", 10e3, 0}, 2);
}

// A file starting at 300 kHz (below it the pi-section extrapolation, extend_below_band), the
// issue's 2 mV: 0.56 mV measured 2026-12-07. Before the series impedance below the band was
// fitted as a skin effect, the DC resistance came from the first point alone, 35 % high, and
// the link was 2.19 mV off (3.74 mV before the passivity enforcement's inequalities, 13.2-15.7
// mV before the sum-and-difference fit).
TEST(TouchstoneExport, CapLink2mFrom300kHz) {
  check_case({"cap_2m.yaml", 300e3, 0}, 2);
}

// A 5 m link with chokes, whose common mode is sensitive below a few hundred kHz: 0.55 mV (24.8 mV
// before the sum-and-difference fit).
TEST(TouchstoneExport, Capchoke5m) {
  check_case({"capchoke_5m.yaml", 10e3, 0}, 2);
}

// Noise of 1e-5 RMS (-100 dB) on every S entry: 0.38 mV (0.41 mV before the skin-effect fit below
// the band; 0.06-0.52 mV on two machines before the
// passivity enforcement's inequalities; 3.93 mV before the sum-and-difference fit, when the fit
// followed the noise into a model that was not passive at 306 kHz).
TEST(TouchstoneExport, NoisyFileWithin2mV) {
  check_case({"cap_2m.yaml", 10e3, 1e-5}, 2);
}

// A long cable (docs/touchstone.md, "Long lines"): the 15 m transformer link's cable exported in
// 1000 segments (a line up to 200 MHz, 27 periods of its 69 ns: its impedance within 0.05 % of
// a continuous line's, where the run's 69 segments rise 2.4 % there) reads back as a uniform line
// with no poles, and the link runs within 5 mV of the native cable, both built in the run's
// segments. Measured 2026-12-06: 1.86 mV, the line's S within 3.3e-4 RMS of the file (the
// rational fit of the same file: the next test).
TEST(TouchstoneExport, Long15mLinkReadsBackAsAUniformLine) {
  StatusOr<link::LinkSpec> spec = example_down("transformer_15m.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<LinkRun> native = run_lti(*spec, *parts);
  ASSERT_TRUE(native.ok()) << native.status().message();

  link::CableSpec fine = spec->cable;
  fine.segments = 1000;
  StatusOr<std::string> path = exported_to_200mhz(fine, "long.s4p");
  ASSERT_TRUE(path.ok()) << path.status().message();
  const link::LinkSpec measured = with_measured_cable(*spec, *path);
  auto fit = link::touchstone_cable(measured.cable);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ASSERT_TRUE((*fit)->line.has_value());
  EXPECT_TRUE((*fit)->fit.model.poles.empty());
  std::printf("as a uniform line: RMS |S - S_file| %.3g, delay %.4g ns, %.4g ohm\n",
              (*fit)->fit.rms_error, (*fit)->line->delay_diff * 1e9, (*fit)->line->z_diff);
  EXPECT_LT((*fit)->fit.rms_error, 1e-3);
  StatusOr<LinkRun> run = run_lti(measured, *parts);
  ASSERT_TRUE(run.ok()) << run.status().message();
  const double diff =
      max_difference(native->directions[0].sim.wave, run->directions[0].sim.wave, 0);
  std::printf("15 m as a uniform line: |dv(rxp,rxn)| <= %.3f mV (%d segments)\n", diff * 1e3,
              run->directions[0].link.cable_segments);
  EXPECT_LT(diff, 5e-3);
  std::remove(path->c_str());
}

// The same file fitted rationally (`uniform_line: false`): 72 poles, a violation of -20 mS just
// past the band made passive, 1.6e-5 RMS off the file as simulated. Against the native cable in
// the file's own 1000 segments (the file's exact circuit): 0.50 mV, measured 2026-12-06. Before
// that day's passivity enforcement the enforced model was 1.5e-3 RMS off and the link 36 mV off
// (then compared with the run's 69 segments, themselves 11.5 mV from the 1000).
TEST(TouchstoneExport, Long15mLinkFittedRationallyMatchesItsOwnLadder) {
  StatusOr<link::LinkSpec> spec = example_down("transformer_15m.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  spec->cable.segments = 1000;
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<LinkRun> native = run_lti(*spec, *parts);
  ASSERT_TRUE(native.ok()) << native.status().message();

  StatusOr<std::string> path = exported_to_200mhz(spec->cable, "long_rational.s4p");
  ASSERT_TRUE(path.ok()) << path.status().message();
  link::LinkSpec measured = with_measured_cable(*spec, *path);
  measured.cable.uniform_line = false;
  auto fit = link::touchstone_cable(measured.cable);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ASSERT_FALSE((*fit)->line.has_value());
  EXPECT_EQ((*fit)->passivity.added_conductance, 0);
  std::printf("rationally: %zu poles, fit %.3g RMS\n", (*fit)->fit.model.poles.size(),
              (*fit)->fit.rms_error);
  StatusOr<LinkRun> run = run_lti(measured, *parts);
  ASSERT_TRUE(run.ok()) << run.status().message();
  const double diff =
      max_difference(native->directions[0].sim.wave, run->directions[0].sim.wave, 0);
  std::printf("15 m fitted rationally: |dv(rxp,rxn)| <= %.3f mV against 1000 segments\n",
              diff * 1e3);
  EXPECT_LT(diff, 2e-3);
  std::remove(path->c_str());
}

// `isolink noise` with a measured cable (analysis/noise.h): the 2 m cap link's own cable as a
// .s4p against the native cable, worst-corner immunity in both directions.
// - ground_shift drives the whole cable's common mode: within 0.5 % (measured 0.33 %: 1.505 V
//   against 1.500 V in both directions).
// - bci at position 0: the clamp between the tx module's connector and the file's ports. The
//   native cable's clamp sits at its first inner node, so its reference is the native cable in
//   100 segments (the clamp 2 cm from the end; at 20 segments, 10 cm, it is 2.6 % off): within
//   2 % (measured 1.1 % down, 0.05 % up).
// - bci at position 0.5 has no node inside a measured cable: refused before any run, naming the
//   position and what to set.
TEST(TouchstoneExport, NoiseWithAMeasuredCable) {
  StatusOr<link::LinkSpec> spec =
      link::read_link_spec_file(std::string(ISOLINK_EXAMPLES_DIR) + "/cap_2m.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StatusOr<Touchstone> t = cable_touchstone(spec->cable, {});
  ASSERT_TRUE(t.ok()) << t.status().message();
  const std::string path = temp_path("noise.s4p");
  ASSERT_TRUE(write_file_atomic(path, write_touchstone(*t, "test")).ok());
  const link::LinkSpec measured = with_measured_cable(*spec, path);
  link::LinkSpec native = *spec;
  native.cable.segments = 100;

  auto immunity = [&](const link::LinkSpec& s, const std::string& injection, double position) {
    link::LinkSpec with = s;
    with.noise.injection = injection;
    with.noise.position = position;
    StatusOr<NoiseRun> r = run_noise(with, *parts);
    EXPECT_TRUE(r.ok()) << r.status().message();
    std::vector<double> out;
    if (r.ok())
      for (const NoiseDirection& d : r->noise.directions) out.push_back(d.immunity_min);
    return out;
  };
  auto compare = [&](const std::string& injection, double rel) {
    const std::vector<double> a = immunity(measured, injection, 0.0);
    const std::vector<double> b = immunity(native, injection, 0.0);
    ASSERT_EQ(a.size(), 2u);
    ASSERT_EQ(b.size(), 2u);
    for (size_t k = 0; k < 2; ++k) {
      std::printf("%s, direction %zu: measured cable %.4g, native %.4g\n", injection.c_str(), k,
                  a[k], b[k]);
      EXPECT_NEAR(a[k], b[k], rel * b[k]) << injection << " direction " << k;
    }
  };
  compare("ground_shift", 0.005);
  compare("bci", 0.02);

  link::LinkSpec middle = measured;
  middle.noise.injection = "bci";
  middle.noise.position = 0.5;
  StatusOr<NoiseRun> refused = run_noise(middle, *parts);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("position 0.5 needs a node inside the cable"),
            std::string::npos)
      << refused.status().message();
  EXPECT_NE(refused.status().message().find("set noise.position to 0"), std::string::npos);
  std::remove(path.c_str());
}

// The export against the cable's closed form at 100 Hz (far below the series R-L corner): the
// through admittance -Re Y13 is 1 / (R_dc l) of the conductor to 0.1 %, and P and N have no
// conductance between them.
TEST(TouchstoneExport, ThroughConductanceIsTheConductorsResistance) {
  link::CableSpec cable;
  cable.length = 2;
  TouchstoneExportOptions o;
  o.f_start = 100;
  o.f_stop = 1e3;
  o.points = 2;
  StatusOr<Touchstone> t = cable_touchstone(cable, o);
  ASSERT_TRUE(t.ok()) << t.status().message();
  StatusOr<link::CableModel> m = link::cable_model(cable);
  ASSERT_TRUE(m.ok());
  const Eigen::MatrixXcd y = y_from_s(t->s[0], 50);
  EXPECT_NEAR(-y(0, 2).real(), 1 / (m->r_dc * 2), 0.001 / (m->r_dc * 2));
  EXPECT_NEAR(y(0, 1).real(), 0, 1e-3);  // no conductance between P and N
}

}  // namespace
}  // namespace isolink::analysis
