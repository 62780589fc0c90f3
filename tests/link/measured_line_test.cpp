// A long measured cable fitted as a uniform line (netlists/link/measured_line.h), against a line
// in closed form: the telegrapher's solution with the skin effect's Bessel impedance and the
// wideband Debye dielectric (the cable model's targets, not its ladders), so the fit's ladders
// meet a shape they were not built from.
#include "netlists/link/measured_line.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <random>

#include "netlists/link/touchstone_cable.h"
#include "solver/vector_fit.h"

namespace isolink::link {
namespace {

using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;

// A mode's per-metre series impedance and shunt admittance, in the mode's own terms.
struct ModeLaw {
  cd z, y;
};

// The closed-form line of length `len` (m) for the model's per-metre targets, single-ended
// 4-port (tx P, tx N, rx P, rx N) or, differential, the pair's 2-port.
Eigen::MatrixXcd closed_form_y(const CableModel& m, double len, double f, bool differential) {
  const cd jw(0, 2 * kPi * f);
  const cd zi = m.target_internal_impedance(f);
  const ModeLaw d{zi + jw * (m.l_diff / 2), 2.0 * jw * m.c_diff() * m.target_capacitance_factor(f)};
  const ModeLaw c{zi + jw * (2 * m.l_cm), jw * m.c_g};
  auto two_port = [&](const ModeLaw& law) {
    const cd gamma = std::sqrt(law.z * law.y) * len, zc = std::sqrt(law.z / law.y);
    Eigen::Matrix2cd y;
    y << 1.0 / (zc * std::tanh(gamma)), -1.0 / (zc * std::sinh(gamma)),
        -1.0 / (zc * std::sinh(gamma)), 1.0 / (zc * std::tanh(gamma));
    return y;
  };
  const Eigen::Matrix2cd yd = two_port(d);
  if (differential) return yd / 2.0;  // v = v_P - v_N = sqrt 2 v_d, i = i_d / sqrt 2
  const Eigen::Matrix2cd yc = two_port(c);
  // Modal (d_tx, c_tx, d_rx, c_rx) to ports with the orthonormal (P - N, P + N) / sqrt 2.
  Eigen::MatrixXcd ym = Eigen::MatrixXcd::Zero(4, 4);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) ym(2 * a, 2 * b) = yd(a, b), ym(2 * a + 1, 2 * b + 1) = yc(a, b);
  const double r = 1 / std::sqrt(2.0);
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(4, 4);
  t << r, -r, 0, 0, r, r, 0, 0, 0, 0, r, -r, 0, 0, r, r;
  return t.transpose().cast<cd>() * ym * t.cast<cd>();
}

struct Sweep {
  std::vector<double> f;
  std::vector<Eigen::MatrixXcd> y;
};

Sweep sweep(const CableModel& m, double len, bool differential, double f_top, int points,
            double f_start = 10e3) {
  Sweep s;
  for (int k = 0; k < points; ++k) {
    const double f = f_start + (f_top - f_start) * k / (points - 1);  // linear, as a VNA sweeps
    s.f.push_back(f);
    s.y.push_back(closed_form_y(m, len, f, differential));
  }
  return s;
}

// The RMS of |S_line - S| (50 ohm) over the sweep.
double rms_s_error(const MeasuredLine& line, const Sweep& s) {
  double sum = 0;
  for (size_t k = 0; k < s.f.size(); ++k)
    sum += (s_from_y(uniform_line_y(line, s.f[k]), 50) - s_from_y(s.y[k], 50)).squaredNorm();
  return std::sqrt(sum / (double(s.f.size()) * s.y[0].size()));
}

// A pair drawn over the model's range: 20-28 AWG, PP or PVC, -40..85 degC.
CableSpec random_pair(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  CableSpec spec;
  spec.gauge = 20 + 2 * static_cast<int>(u(rng) * 5);
  spec.material = u(rng) < 0.5 ? "pp" : "pvc";
  spec.temperature = -40 + 125 * u(rng);
  return spec;
}

// 15 m of 24 AWG PP to 200 MHz, 500 points: 27 periods of its delay, where a rational fit takes
// about 70 poles and a minute. As a uniform line: the DC resistance to 0.5 %, the differential
// phase at the top (the delay the far end sees) to 1e-4 of its 37 rad, and S within 1e-3 RMS.
TEST(MeasuredLine, FifteenMetresFitTheClosedForm) {
  CableSpec spec;
  spec.length = 1;  // per metre figures; the line below is 15 of them
  StatusOr<CableModel> m = cable_model(spec);
  ASSERT_TRUE(m.ok()) << m.status().message();
  const double len = 15;
  const Sweep s = sweep(*m, len, false, 200e6, 500);
  std::optional<MeasuredLine> line = fit_uniform_line(s.f, s.y, false);
  ASSERT_TRUE(line.has_value());
  EXPECT_NEAR(line->model.r_dc, m->r_dc * len, 0.005 * m->r_dc * len);
  // Phase of the differential propagation at the top frequency, closed form against the fit.
  const double f = s.f.back();
  const cd jw(0, 2 * kPi * f);
  const cd gamma_true = std::sqrt((m->target_internal_impedance(f) + jw * (m->l_diff / 2)) *
                                  (2.0 * jw * m->c_diff() * m->target_capacitance_factor(f))) *
                        len;
  const CableModel& g = line->model;
  const cd gamma_fit = std::sqrt((g.internal_impedance(f) + jw * (g.l_diff / 2)) *
                                 (2.0 * g.shunt_admittance_diff(f)));
  EXPECT_NEAR(gamma_fit.imag(), gamma_true.imag(), 1e-4 * gamma_true.imag());
  EXPECT_NEAR(gamma_fit.real(), gamma_true.real(), 0.01 * gamma_true.real());  // the loss, 1 %
  // Loss-free figures against the model's own (external inductance, capacitance at 1 MHz): the
  // delay within 1 % (the dielectric's dispersion lies between), the impedance within 2 %.
  EXPECT_NEAR(line->delay_diff, len / m->velocity(), 0.01 * len / m->velocity());
  EXPECT_NEAR(line->z_diff, m->z_diff(), 0.02 * m->z_diff());
  EXPECT_NEAR(line->delay_cm, len / m->velocity_cm(), 0.01 * len / m->velocity_cm());
  EXPECT_NEAR(line->z_cm, m->z_cm(), 0.02 * m->z_cm());
  EXPECT_LT(rms_s_error(*line, s), 1e-3);
}

// Not one cable: a seeded corpus of 24 closed-form lines over the model's range (5-100 m, 20-28
// AWG, PP and PVC, -40..85 degC), each swept linearly to a top of 8-40 periods of its delay
// (200-500 points), read back as a uniform line. Every one must be found with its DC resistance
// within 0.5 %; its S within 1e-3 RMS in at least 22 of the 24 (measured 2026-12-05: 23, the
// other a 73 m 26 AWG PVC line to 81 MHz at 1.6e-3, which fit_touchstone_cable then leaves to
// the rational fit). Before the reader stopped at 40 dB of attenuation instead of giving up,
// a 71.5 m line was not found at all.
TEST(MeasuredLine, SeededCorpusOfLinesFitsTheClosedForm) {
  std::mt19937 rng(20261205);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  int within = 0;
  for (int k = 0; k < 24; ++k) {
    const CableSpec spec = random_pair(rng);
    StatusOr<CableModel> m = cable_model(spec);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const double len = 5 * std::pow(20.0, u(rng));  // 5..100 m
    const double delay = len / m->velocity();
    const double f_top = (8 + 32 * u(rng)) / delay;
    const int points = 200 + static_cast<int>(300 * u(rng));
    const Sweep s = sweep(*m, len, false, f_top, points);
    std::optional<MeasuredLine> line = fit_uniform_line(s.f, s.y, false);
    ASSERT_TRUE(line.has_value()) << "case " << k << ": " << len << " m";
    EXPECT_NEAR(line->model.r_dc, m->r_dc * len, 0.005 * m->r_dc * len) << "case " << k;
    const double e = rms_s_error(*line, s);
    worst = std::max(worst, e);
    if (e < 1e-3)
      ++within;
    else
      std::printf("case %d: %.1f m, AWG %d %s, to %.0f MHz, %d points: %.3g RMS\n", k, len,
                  spec.gauge, spec.material.c_str(), f_top / 1e6, points, e);
  }
  std::printf("corpus: %d of 24 within 1e-3 RMS, the worst %.3g\n", within, worst);
  EXPECT_GE(within, 22);
}

// The same pair as a differential 2-port: one mode, no capacitance to the chassis.
TEST(MeasuredLine, DifferentialTwoPort) {
  CableSpec spec;
  StatusOr<CableModel> m = cable_model(spec);
  ASSERT_TRUE(m.ok());
  const Sweep s = sweep(*m, 15, true, 200e6, 500);
  std::optional<MeasuredLine> line = fit_uniform_line(s.f, s.y, true);
  ASSERT_TRUE(line.has_value());
  EXPECT_EQ(line->model.c_g, 0);
  EXPECT_NEAR(line->delay_diff, 15 / m->velocity(), 0.01 * 15 / m->velocity());
  EXPECT_LT(rms_s_error(*line, s), 1e-3);
}

Touchstone as_file(const Sweep& s) {
  Touchstone t;
  t.source = "closed form";
  t.ports = static_cast<int>(s.y[0].rows());
  t.z0 = 50;
  t.freqs = s.f;
  for (const Eigen::MatrixXcd& y : s.y) t.s.push_back(s_from_y(y, 50));
  return t;
}

// fit_touchstone_cable takes the line for a long cable: no poles, its error that of the line, Y(0)
// the two lines' DC resistance end to end and nothing else.
TEST(MeasuredLine, TouchstoneCableTakesTheLineForALongCable) {
  CableSpec spec;
  StatusOr<CableModel> m = cable_model(spec);
  ASSERT_TRUE(m.ok());
  auto c = fit_touchstone_cable(as_file(sweep(*m, 15, false, 200e6, 200)), {}, 1e-3);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE((*c)->line.has_value());
  EXPECT_TRUE((*c)->fit.model.poles.empty());
  EXPECT_LT((*c)->fit.rms_error, 1e-3);
  EXPECT_EQ((*c)->fit.rms_error, (*c)->line_rms_error);
  const Eigen::MatrixXd g0 = (*c)->dc_conductance;
  EXPECT_NEAR(-g0(0, 2), 1 / (15 * m->r_dc), 0.005 / (15 * m->r_dc));
  EXPECT_NEAR(g0(0, 1), 0, 1e-6);
}

// 15 m whose far end carries a lumped 10 pF from P to the chassis (a connector's stub) is not a
// uniform line: read as one, it is off by more than the default tolerance, so fit_touchstone_cable
// leaves it to the rational fit (measured: 0.8 % RMS in S).
TEST(MeasuredLine, ANonUniformHarnessIsNotTakenForALine) {
  CableSpec spec;
  StatusOr<CableModel> m = cable_model(spec);
  ASSERT_TRUE(m.ok());
  Sweep s = sweep(*m, 15, false, 200e6, 200);
  for (size_t k = 0; k < s.f.size(); ++k) s.y[k](2, 2) += cd(0, 2 * kPi * s.f[k] * 10e-12);
  std::optional<MeasuredLine> line = fit_uniform_line(s.f, s.y, false);
  if (line) {
    const double e = rms_s_error(*line, s);
    std::printf("the stubbed line read as uniform: RMS |S - S_file| %.3g\n", e);
    EXPECT_GT(e, 1e-3);
  }
}

// Short lines whose band ends at their first resonance (0.5 and 1 m to 100 MHz: a quarter and a
// half period of their delay): the rational fit puts high-Q poles just past the band whose Re Y
// dips far below zero there (-0.59 S at 284 MHz for 1 m, -7 S at 293 MHz for 0.5 m). Before the
// residue perturbation held every sweep point by an inequality, it bounced from one violation to
// the next and both files were refused; now each is made passive without a shunt and the model
// as simulated stays within the tolerance of the file, its DC resistance that of the line.
TEST(MeasuredLine, ShortLinesToTheirFirstResonanceAreMadePassive) {
  CableSpec spec;
  StatusOr<CableModel> m = cable_model(spec);
  ASSERT_TRUE(m.ok());
  for (double len : {0.5, 1.0}) {
    const Sweep s = sweep(*m, len, false, 100e6, 200);
    auto c = fit_touchstone_cable(as_file(s), {}, 1e-3);
    ASSERT_TRUE(c.ok()) << len << " m: " << c.status().message();
    const TouchstoneCable& cable = **c;
    EXPECT_FALSE(cable.line.has_value());
    EXPECT_EQ(cable.passivity.added_conductance, 0);
    EXPECT_TRUE(check_passivity(cable.fit.model, 100e6).passive) << len << " m";
    double sum = 0;
    for (size_t k = 0; k < s.f.size(); ++k)
      sum += (s_from_y(cable.y(s.f[k]), 50) - s_from_y(s.y[k], 50)).squaredNorm();
    const double rms = std::sqrt(sum / (double(s.f.size()) * 16));
    std::printf("%.1f m to 100 MHz: %zu poles, as simulated %.3g RMS off the file\n", len,
                cable.fit.model.poles.size(), rms);
    EXPECT_LT(rms, 1e-3) << len << " m";
    EXPECT_NEAR(-cable.dc_conductance(0, 2), 1 / (len * m->r_dc), 0.01 / (len * m->r_dc));
  }
}

// Not the two lines above alone: a seeded corpus of 12 short closed-form lines fitted rationally
// (0.3-5 m, 20-28 AWG, PP and PVC, -40..85 degC, to 50-500 MHz, 150-400 points, one in four a
// differential 2-port). Every one must fit, be made passive without a shunt, stay within the
// tolerance as simulated (fit_touchstone_cable refuses it otherwise) and keep its DC resistance.
// Measured 2026-12-06: all 12 (the cases and their errors are printed).
TEST(MeasuredLine, SeededCorpusOfShortLinesFitsAndIsPassive) {
  std::mt19937 rng(20261206);
  std::uniform_real_distribution<double> u(0, 1);
  const double tops[] = {50e6, 100e6, 200e6, 300e6, 500e6};
  for (int k = 0; k < 12; ++k) {
    const CableSpec spec = random_pair(rng);
    StatusOr<CableModel> m = cable_model(spec);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const double len = 0.3 * std::pow(5 / 0.3, u(rng));
    const double f_top = tops[static_cast<int>(u(rng) * 5)];
    const int points = 150 + static_cast<int>(250 * u(rng));
    const bool differential = u(rng) < 0.25;
    const Sweep s = sweep(*m, len, differential, f_top, points);
    auto c = fit_touchstone_cable(as_file(s), {}, 1e-3, /*long_line=*/false);
    ASSERT_TRUE(c.ok()) << "case " << k << ": " << c.status().message();
    const TouchstoneCable& cable = **c;
    std::printf(
        "case %d: %.2f m, AWG %d %s, to %.0f MHz, %d points%s: %zu poles, fit %.2g RMS, "
        "violation %.2g S, %d perturbations\n",
        k, len, spec.gauge, spec.material.c_str(), f_top / 1e6, points,
        differential ? ", 2-port" : "", cable.fit.model.poles.size(), cable.fit.rms_error,
        std::min(cable.passivity.min_eigenvalue, 0.0), cable.passivity.perturbation_iterations);
    EXPECT_EQ(cable.passivity.added_conductance, 0) << "case " << k;
    EXPECT_TRUE(check_passivity(cable.fit.model, f_top).passive) << "case " << k;
    // Through P end to end (the 2-port: the loop's, both wires).
    const double r = (differential ? 2 : 1) * m->r_dc * len;
    EXPECT_NEAR(-cable.dc_conductance(0, differential ? 1 : 2), 1 / r, 0.01 / r) << "case " << k;
  }
}

// Below the band (extend_below_band): a VNA's linear sweep from 10, 100 or 300 kHz (to 100-500
// MHz in 201-801 points, a step of 0.1-2.5 MHz), a seeded corpus of 24 closed-form lines (0.3-10
// m, 20-28 AWG, PP and PVC, -40..85 degC, one in four a differential 2-port), against the closed
// form. Where the first point is at most 10 times the wire's skin corner f_s = R_dc / (2 mu0)
// (per metre; about 33 kHz for 24 AWG, 11 kHz for 20 AWG): each conductor's DC resistance within
// 3 %, and at every point added between 1e-3 of the first frequency and the first, the series
// impedance -(Y_tx,rx)^-1 within 3 % in its resistance and 0.5 % in its reactance (measured
// 2026-12-07, 20 such cases: at most 1.8 %, 1.8 % and 0.28 %, growing with the first point's
// depth: under 0.7 % below 4 times the corner). Deeper in the skin effect the file does not tell
// the DC resistance apart from the proximity effect (both add a constant to R(f) ~ sqrt(f)):
// within 30 % and 3 % (docs/touchstone.md, "Limits"). Before the skin-effect fit the resistance
// came from the first point alone (a + b f^2 over the points within 4 times the first: one point
// in such a sweep): 35 % high for 2 m of 24 AWG from 300 kHz, where the link ran 2.2 mV off the
// native cable (0.56 mV now).
TEST(MeasuredLine, BelowTheBandFollowsTheClosedForm) {
  std::mt19937 rng(20261207);
  std::uniform_real_distribution<double> u(0, 1);
  const double starts[] = {10e3, 100e3, 300e3};
  constexpr double kMu0 = 4e-7 * kPi;
  for (int k = 0; k < 24; ++k) {
    const CableSpec spec = random_pair(rng);
    StatusOr<CableModel> m = cable_model(spec);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const double len = 0.3 * std::pow(10 / 0.3, u(rng));
    const double f_start = starts[static_cast<int>(u(rng) * 3)];
    const double f_top = 100e6 + 400e6 * u(rng);
    const int points = 201 + static_cast<int>(600 * u(rng));
    const bool differential = u(rng) < 0.25;
    Sweep s = sweep(*m, len, differential, f_top, points, f_start);
    Eigen::MatrixXd r_dc;
    ASSERT_TRUE(extend_below_band(s.f, s.y, &r_dc).ok()) << "case " << k;
    const double r_true = (differential ? 2 : 1) * m->r_dc * len;
    const double dc = std::fabs(r_dc(0, 0) / r_true - 1);
    const int h = differential ? 1 : 2;
    double r_off = 0, x_off = 0;
    for (size_t q = 1; q < s.f.size() && s.f[q] < f_start; ++q) {
      const Eigen::MatrixXcd want = closed_form_y(*m, len, s.f[q], differential);
      const cd z = (-s.y[q].block(0, h, h, h)).inverse()(0, 0);
      const cd z_true = (-want.block(0, h, h, h)).inverse()(0, 0);
      r_off = std::max(r_off, std::fabs(z.real() / z_true.real() - 1));
      x_off = std::max(x_off, std::fabs(z.imag() / z_true.imag() - 1));
    }
    const double depth = f_start / (m->r_dc / (2 * kMu0));
    std::printf(
        "case %d: %.2f m, AWG %d %s%s, from %.0f kHz (%.1f f_s), step %.2f MHz: R_dc %.2g, "
        "R %.2g, X %.2g off\n",
        k, len, spec.gauge, spec.material.c_str(), differential ? ", 2-port" : "", f_start / 1e3,
        depth, (f_top - f_start) / (points - 1) / 1e6, dc, r_off, x_off);
    const bool told = depth <= 10;
    EXPECT_LT(dc, told ? 0.03 : 0.3) << "case " << k;
    EXPECT_LT(r_off, told ? 0.03 : 0.3) << "case " << k;
    EXPECT_LT(x_off, told ? 0.005 : 0.03) << "case " << k;
  }
}

}  // namespace
}  // namespace isolink::link
