// Twisted-pair cable model: closed-form checks of the lossless limit, the fitted skin and
// dielectric ladders, attenuation against the RLGC formula, segment convergence and presets.
#include "netlists/link/cable.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include "netlists/link/cards.h"
#include "solver/ac.h"
#include "solver/transient.h"

namespace isolink::link {
namespace {

using cd = std::complex<double>;
constexpr double kC0 = 299'792'458.0;

Card source(const std::string& name, const std::string& p, const std::string& n,
            std::vector<double> pwl) {
  CardArg a;
  if (pwl.size() == 1) {
    a = number_arg(pwl[0]);
  } else {
    a.kind = CardArg::Kind::Call;
    a.word = "pwl";
    a.call = std::move(pwl);
  }
  return make_card('v', name, {p, n}, {a});
}
Card resistor(const std::string& name, const std::string& a, const std::string& b, double r) {
  return make_card('r', name, {a, b}, {number_arg(r)});
}

// Time at which column k first crosses `level` (rising) at or after t_from; linear interpolation.
double crossing(const Waveform& w, size_t k, double level, double t_from) {
  const std::vector<double>& v = w.columns[k];
  for (size_t i = 1; i < w.samples(); ++i) {
    if (w.time[i] < t_from) continue;
    if (v[i - 1] < level && v[i] >= level)
      return w.time[i - 1] + (level - v[i - 1]) / (v[i] - v[i - 1]) * (w.time[i] - w.time[i - 1]);
  }
  return NAN;
}
// Mean of column k over [t0, t1] (trapezoidal in time).
double mean(const Waveform& w, size_t k, double t0, double t1) {
  double area = 0, span = 0;
  for (size_t i = 1; i < w.samples(); ++i) {
    const double a = std::max(w.time[i - 1], t0), b = std::min(w.time[i], t1);
    if (b <= a) continue;
    const double va = w.value_at(k, a), vb = w.value_at(k, b);
    area += (va + vb) / 2 * (b - a);
    span += b - a;
  }
  return area / span;
}

TEST(Cable, PresetsFollowTheFormulas) {
  CableSpec spec;
  spec.temperature = 20;
  auto m = cable_model(spec);
  ASSERT_TRUE(m.ok()) << m.status().message();
  // 24 AWG: 0.511 mm, 84.2 mohm/m at 20 degC (AWG tables).
  EXPECT_NEAR(m->wire_diameter, 0.511e-3, 0.001e-3);
  EXPECT_NEAR(m->r_dc, 84.2e-3, 0.01 * 84.2e-3);
  // Copper's 0.393 %/K.
  spec.temperature = 85;
  EXPECT_NEAR(cable_model(spec)->r_dc / m->r_dc, 1 + 0.00393 * 65, 1e-9);
  // PP 24 AWG: the usual twisted-pair figures.
  EXPECT_GT(m->z_diff(), 100);
  EXPECT_LT(m->z_diff(), 120);
  EXPECT_GT(m->velocity(), 0.65 * kC0);
  EXPECT_LT(m->velocity(), 0.75 * kC0);
  // Twin lead: l = mu0 / pi acosh(D / d), Z = (eta0 / pi) acosh(D / d) / sqrt(er_eff).
  const double u = m->spacing / m->wire_diameter;
  EXPECT_NEAR(m->l_diff, 4e-7 * std::acosh(u), 1e-12);
  EXPECT_NEAR(m->z_diff(), 119.9169832 * std::acosh(u) / std::sqrt(m->er_eff), 1e-3 * m->z_diff());
  EXPECT_NEAR(m->l_diff, 2 * m->l_self * (1 - m->k_pn), 1e-18);
  EXPECT_NEAR(m->l_cm, m->l_self * (1 + m->k_pn) / 2, 1e-18);
  std::printf(
      "pp 24 AWG: r_dc %.4g ohm/m, l_diff %.4g H/m, l_cm %.4g, k %.4f, c_pn %.4g F/m, "
      "c_g %.4g, z_diff %.2f ohm, v %.4f c, z_cm %.1f, v_cm %.3f c, tan_eff %.3g\n",
      m->r_dc, m->l_diff, m->l_cm, m->k_pn, m->c_pn, m->c_g, m->z_diff(), m->velocity() / kC0,
      m->z_cm(), m->velocity_cm() / kC0, m->tan_delta_eff);

  // PVC: more capacitance and more loss when hot.
  CableSpec pvc;
  pvc.material = "pvc";
  pvc.temperature = 25;
  auto cold = cable_model(pvc);
  pvc.temperature = 85;
  auto hot = cable_model(pvc);
  ASSERT_TRUE(cold.ok() && hot.ok());
  EXPECT_GT(hot->c_diff(), 1.1 * cold->c_diff());
  EXPECT_GT(hot->g_diff(), 1.3 * cold->g_diff());
  EXPECT_GT(cold->c_diff(), 1.4 * m->c_diff());  // PVC's permittivity is about twice PP's
  std::printf(
      "pvc 25 degC: c %.4g F/m, g %.4g S/m, z %.1f, v %.3f c; 85 degC: c %.4g, g %.4g, "
      "z %.1f\n",
      cold->c_diff(), cold->g_diff(), cold->z_diff(), cold->velocity() / kC0, hot->c_diff(),
      hot->g_diff(), hot->z_diff());

  // Explicit values replace the preset's.
  CableSpec x;
  x.r = 0.1;
  x.l = 0.6e-6;
  x.c = 50e-12;
  x.g = 1e-6;
  auto e = cable_model(x);
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_DOUBLE_EQ(e->r_dc, 0.1);
  EXPECT_NEAR(e->l_diff, 0.6e-6, 1e-15);
  EXPECT_NEAR(e->c_diff(), 50e-12, 1e-20);
  EXPECT_NEAR(e->g_diff(), 1e-6, 1e-12);
  EXPECT_NEAR(std::real(e->shunt_admittance_diff(1e6)), 1e-6, 0.03e-6);
}

// cable_model keeps the per-metre models it has fitted (a length sweep expands one cable many
// times): a second length takes the kept one with its own length, and a spec that differs in any
// other field is fitted anew.
TEST(Cable, KeptModelsServeOtherLengthsOnly) {
  CableSpec base;
  base.length = 3;
  auto a = cable_model(base);
  ASSERT_TRUE(a.ok());
  base.length = 17;
  auto b = cable_model(base);
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(a->length, 3);
  EXPECT_EQ(b->length, 17);
  EXPECT_EQ(a->r_dc, b->r_dc);
  ASSERT_EQ(a->skin.size(), b->skin.size());
  for (size_t i = 0; i < a->skin.size(); ++i) EXPECT_EQ(a->skin[i].r, b->skin[i].r);
  // Each field the model depends on, changed alone after the base was kept: a different model.
  auto differs = [&](const char* what, auto change) {
    SCOPED_TRACE(what);
    CableSpec s = base;
    change(s);
    auto m = cable_model(s);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const bool same = m->r_dc == b->r_dc && m->l_diff == b->l_diff && m->c_pn == b->c_pn &&
                      m->c_g == b->c_g && m->tan_delta_eff == b->tan_delta_eff &&
                      m->skin.size() == b->skin.size() && m->er == b->er;
    EXPECT_FALSE(same);
  };
  differs("material", [](CableSpec& s) { s.material = "pvc"; });
  differs("gauge", [](CableSpec& s) { s.gauge = 26; });
  differs("temperature", [](CableSpec& s) { s.temperature = 60; });
  differs("r", [](CableSpec& s) { s.r = 0.05; });
  differs("l", [](CableSpec& s) { s.l = 0.6e-6; });
  differs("c", [](CableSpec& s) { s.c = 50e-12; });
  differs("g", [](CableSpec& s) { s.g = 1e-6; });
  differs("chassis_c", [](CableSpec& s) { s.chassis_c = 20e-12; });
  differs("skin_effect", [](CableSpec& s) { s.skin_effect = false; });
  differs("dielectric_loss", [](CableSpec& s) { s.dielectric_loss = false; });
}

TEST(Cable, ValidationNamesTheField) {
  CableSpec s;
  s.length = -1;
  EXPECT_EQ(s.validate().message(), "cable.length = -1: must be > 0");
  s = {};
  s.gauge = 40;
  EXPECT_EQ(s.validate().message(), "cable.gauge = 40: must be an AWG size from 18 to 30");
  s = {};
  s.material = "pe";
  EXPECT_EQ(s.validate().message(), "cable.material = 'pe': must be pp or pvc");
  s = {};
  s.material = "pvc";
  s.temperature = 120;
  EXPECT_EQ(s.validate().message().rfind("cable.temperature = 120: ", 0), 0u);
  s = {};
  s.c = 1e-12;
  EXPECT_EQ(cable_model(s).status().message().rfind("cable.c = 1e-12: must exceed", 0), 0u);
  s = {};
  s.l = -1e-6;
  EXPECT_EQ(s.validate().message(), "cable.l = -1e-06: must be > 0 (H/m)");
  std::vector<Card> cards;
  EXPECT_FALSE(add_cable(cards, "cab", "a", "b", "c", "d", CableSpec{}, 0).ok());
}

TEST(Cable, FittedLaddersTrackTheTargets) {
  for (const char* material : {"pp", "pvc"}) {
    for (int gauge : {18, 24, 30}) {
      CableSpec spec;
      spec.material = material;
      spec.gauge = gauge;
      spec.temperature = 85;
      auto m = cable_model(spec);
      ASSERT_TRUE(m.ok()) << m.status().message();
      double worst_r = 0, worst_x = 0, worst_g = 0, worst_c = 0;
      for (int i = 0; i < 20; ++i) {
        const double f = 0.1e6 * std::pow(1000.0, i / 19.0);
        const cd z = m->internal_impedance(f), zt = m->target_internal_impedance(f);
        const cd c = m->capacitance_factor(f), ct = m->target_capacitance_factor(f);
        worst_r = std::max(worst_r, std::abs(z.real() / zt.real() - 1));
        worst_x = std::max(worst_x, std::abs(z.imag() / zt.imag() - 1));
        worst_g = std::max(worst_g, std::abs(c.imag() / ct.imag() - 1));
        worst_c = std::max(worst_c, std::abs(c.real() / ct.real() - 1));
      }
      std::printf(
          "%s %d AWG: %zu skin sections, %zu dielectric branches; worst over 0.1-100 MHz: "
          "R %.2f %%, X_int %.2f %%, G %.2f %%, C %.3f %%\n",
          material, gauge, m->skin.size(), m->dielectric.size(), 100 * worst_r, 100 * worst_x,
          100 * worst_g, 100 * worst_c);
      EXPECT_LT(worst_r, 0.02) << material << " " << gauge;
      EXPECT_LT(worst_x, 0.03) << material << " " << gauge;
      EXPECT_LT(worst_g, 0.02) << material << " " << gauge;
      EXPECT_LT(worst_c, 0.002) << material << " " << gauge;
    }
  }
  // The targets. Well above the skin corner R = R_dc (1 - p) + p R_dc (a / (2 delta) + 1/4)
  // with delta = sqrt(rho / (pi f mu0)) and the proximity factor p; loss tangent flat.
  CableSpec spec;
  auto m = cable_model(spec);
  const double a = m->wire_diameter / 2, rho = m->r_dc * std::numbers::pi * a * a;
  const double u = m->spacing / m->wire_diameter;
  EXPECT_NEAR(m->proximity, u / std::sqrt(u * u - 1), 1e-12);
  for (double f : {10e6, 100e6}) {
    const double delta = std::sqrt(rho / (std::numbers::pi * f * 4e-7 * std::numbers::pi));
    const double r = m->r_dc * (1 - m->proximity + m->proximity * (a / (2 * delta) + 0.25));
    EXPECT_NEAR(m->target_internal_impedance(f).real(), r, 0.005 * r) << f;
    // Internal reactance equals the resistance's frequency-dependent part.
    EXPECT_NEAR(m->target_internal_impedance(f).imag(), r - m->r_dc * (1 - 0.75 * m->proximity),
                0.01 * r)
        << f;
  }
  for (double f : {0.1e6, 1e6, 10e6, 100e6}) {
    const cd ct = m->target_capacitance_factor(f);
    EXPECT_NEAR(-ct.imag() / ct.real(), m->tan_delta_eff, 0.01 * m->tan_delta_eff) << f;
  }
  EXPECT_NEAR(m->target_capacitance_factor(1e6).real(), 1.0, 1e-12);
}

// The cable in one mode from AC solves with the far end open, each line driven by its own
// source and the two solutions superposed: differential (V = v_p - v_n, I = i_p) or common
// (V = (v_p + v_n) / 2, I = i_p + i_n). The cable is a symmetric reciprocal two-port (A = D,
// AD - BC = 1), so A = V1 / V2 and C = I1 / V2 give e^(gamma l) = A + sqrt(A^2 - 1) and
// Z0 = sqrt(A^2 - 1) / C, whatever the terminations.
struct LineFigures {
  cd gamma_l, z0;
};
enum class Mode { Differential, Common };
LineFigures measured_line(const CableSpec& spec, double f, Mode mode) {
  std::vector<Card> cards;
  EXPECT_TRUE(add_cable(cards, "cab", "ap", "an", "bp", "bn", spec).ok());
  cards.push_back(source("vp", "ap", "0", {0.0}));
  cards.push_back(source("vn", "an", "0", {0.0}));
  Circuit c;
  EXPECT_TRUE(add_cards(c, cards).ok());
  EXPECT_TRUE(c.finalize().ok());
  auto ac = AcAnalysis::create(c);
  EXPECT_TRUE(ac.ok());
  auto xp = ac->solve("vp", f), xn = ac->solve("vn", f);
  EXPECT_TRUE(xp.ok() && xn.ok());
  const double s = mode == Mode::Differential ? -1.0 : 1.0;
  auto at = [&](const char* probe) {
    const int k = parse_probe(c, probe)->a;
    return xp->x[k] + s * xn->x[k];
  };
  auto voltage = [&](cd p, cd n) { return s < 0 ? p - n : (p + n) / 2.0; };
  auto current = [&](cd p, cd n) { return s < 0 ? p : p + n; };
  const cd v1 = voltage(at("v(ap)"), at("v(an)")), v2 = voltage(at("v(bp)"), at("v(bn)"));
  const cd i1 = current(-at("i(vp)"), -at("i(vn)"));
  const cd a = v1 / v2, cc = i1 / v2;
  const cd root = std::sqrt(a * a - 1.0);
  // The forward wave: |e^(gamma l)| > 1 with loss; loss-free, the phase lag (Im > 0).
  cd e = a + root;
  const double ratio = std::abs(a + root) / std::abs(a - root);
  if (ratio < 1 - 1e-9 || (ratio <= 1 + 1e-9 && std::log(a + root).imag() < 0)) e = a - root;
  return {std::log(e), (e == a + root ? root : -root) / cc};
}

TEST(Cable, AttenuationFollowsTheRlgcFormula) {
  for (const char* material : {"pp", "pvc"}) {
    CableSpec spec;
    spec.material = material;
    spec.length = 30;
    spec.temperature = 85;
    spec.segments = 150;  // 0.2 m: under a fiftieth of a wavelength at 10 MHz
    auto m = cable_model(spec);
    ASSERT_TRUE(m.ok());
    for (double f : {1e6, 10e6}) {
      const double alpha_sim =
          measured_line(spec, f, Mode::Differential).gamma_l.real() / spec.length;
      const double alpha_target = m->target_gamma_diff(f).real();
      const double alpha_fit = m->gamma_diff(f).real();
      // Loss split: conductor R/(2 Z0), dielectric G Z0 / 2.
      std::printf(
          "%s 85 degC %g MHz: alpha simulated %.4f dB/m, RLGC formula %.4f dB/m (%.2f %%), "
          "fitted ladder %.4f dB/m\n",
          material, f / 1e6, 8.686 * alpha_sim, 8.686 * alpha_target,
          100 * (alpha_sim / alpha_target - 1), 8.686 * alpha_fit);
      EXPECT_NEAR(alpha_sim, alpha_target, 0.05 * alpha_target) << material << " " << f;
    }
  }
}

// Common mode (both lines against the reference) in the loss-free limit: its own velocity and
// impedance, sqrt(l_cm c_cm) and sqrt(l_cm / c_cm); the differential mode the same way.
TEST(Cable, ModesTravelAtTheirOwnVelocities) {
  CableSpec spec;
  spec.length = 5;
  spec.segments = 50;
  spec.skin_effect = false;
  spec.dielectric_loss = false;
  spec.r = 0.0;
  auto m = cable_model(spec);
  ASSERT_TRUE(m.ok());
  const double f = 10e6, w = 2 * std::numbers::pi * f;
  const LineFigures cm = measured_line(spec, f, Mode::Common);
  const LineFigures dm = measured_line(spec, f, Mode::Differential);
  std::printf(
      "5 m at 10 MHz: common mode v %.4f c (model %.4f c), Z %.2f ohm (%.2f); "
      "differential v %.4f c (%.4f c), Z %.2f ohm (%.2f)\n",
      w * spec.length / cm.gamma_l.imag() / kC0, m->velocity_cm() / kC0, cm.z0.real(), m->z_cm(),
      w * spec.length / dm.gamma_l.imag() / kC0, m->velocity() / kC0, dm.z0.real(), m->z_diff());
  EXPECT_NEAR(cm.gamma_l.imag(), w * spec.length / m->velocity_cm(),
              0.005 * w * spec.length / m->velocity_cm());
  EXPECT_NEAR(cm.z0.real(), m->z_cm(), 0.005 * m->z_cm());
  EXPECT_NEAR(dm.gamma_l.imag(), w * spec.length / m->velocity(),
              0.005 * w * spec.length / m->velocity());
  EXPECT_NEAR(dm.z0.real(), m->z_diff(), 0.005 * m->z_diff());
  EXPECT_GT(m->velocity_cm(), m->velocity());  // the common mode's field is mostly in air
}

// Lossless limit: a step through a source resistance into the cable, a mismatched load at the
// far end. Delay, launch divider and load reflection against sqrt(l c), sqrt(l / c).
TEST(Cable, LosslessLimitDelayAndImpedance) {
  CableSpec spec;
  spec.length = 5;
  spec.r = 0.0;
  spec.skin_effect = false;
  spec.dielectric_loss = false;
  auto m = cable_model(spec);
  ASSERT_TRUE(m.ok());
  const double z0 = std::sqrt(m->l_diff / m->c_diff());
  const double delay = spec.length * std::sqrt(m->l_diff * m->c_diff());
  const double edge = 1e-9, t0 = 2e-9, rs = 100.0, rl = 50.0, vs = 1.0;

  std::vector<Card> cards;
  ASSERT_TRUE(add_cable(cards, "cab", "ap", "an", "bp", "bn", spec, edge).ok());
  cards.push_back(source("vp", "sp", "0", {0, 0, t0, 0, t0 + edge, vs / 2}));
  cards.push_back(source("vn", "sn", "0", {0, 0, t0, 0, t0 + edge, -vs / 2}));
  cards.push_back(resistor("rsp", "sp", "ap", rs / 2));
  cards.push_back(resistor("rsn", "sn", "an", rs / 2));
  cards.push_back(resistor("rl", "bp", "bn", rl));
  Circuit c;
  ASSERT_TRUE(add_cards(c, cards).ok());
  ASSERT_TRUE(c.finalize().ok());
  TransientOptions opt{.tstep = 0.02e-9, .tstop = t0 + 4 * delay};
  auto w = run_transient(c, opt, {*parse_probe(c, "v(ap,an)"), *parse_probe(c, "v(bp,bn)")});
  ASSERT_TRUE(w.ok()) << w.status().message();

  // Source end: the launch plateau v1 = vs Z0 / (Z0 + rs) until 2T, then v1 plus the load's
  // reflection v1 Gamma (1 + Gamma_s) with 1 + Gamma_s = 2 rs / (rs + Z0) = 2 (1 - v1 / vs);
  // load end: the first arrival v1 (1 + Gamma).
  const double v1 = mean(*w, 0, t0 + edge + 0.4 * delay, t0 + 1.8 * delay);
  const double v1r = mean(*w, 0, t0 + edge + 2.4 * delay, t0 + 3.8 * delay);
  const double v2 = mean(*w, 1, t0 + edge + 1.4 * delay, t0 + 2.8 * delay);
  const double t_near = crossing(*w, 0, v1 / 2, 0), t_far = crossing(*w, 1, v2 / 2, 0);
  const double delay_meas = t_far - t_near;
  const double z0_launch = rs * v1 / (vs - v1);
  auto z0_from = [&](double gamma) { return rl * (1 - gamma) / (1 + gamma); };
  const double z0_source_end = z0_from((v1r - v1) / (v1 * 2 * (1 - v1 / vs)));
  const double z0_load_end = z0_from(v2 / v1 - 1);
  const int n = cable_segments(spec, *m, edge);
  std::printf(
      "lossless 5 m, %d segments: delay %.3f ns vs %.3f ns (%.3f %%); Z0 theory %.3f ohm, from "
      "the reflected step at the source end %.3f (%.3f %%), at the load %.3f (%.3f %%), from the "
      "launch %.3f (%.3f %%)\n",
      n, delay_meas * 1e9, delay * 1e9, 100 * (delay_meas / delay - 1), z0, z0_source_end,
      100 * (z0_source_end / z0 - 1), z0_load_end, 100 * (z0_load_end / z0 - 1), z0_launch,
      100 * (z0_launch / z0 - 1));
  EXPECT_NEAR(delay_meas, delay, 0.02 * delay);
  EXPECT_NEAR(z0_source_end, z0, 0.02 * z0);
  EXPECT_NEAR(z0_load_end, z0, 0.02 * z0);
  EXPECT_NEAR(z0_launch, z0, 0.02 * z0);
  EXPECT_NEAR(delay, spec.length / m->velocity(), 1e-15);
}

// Received differential voltage of a 10 m PP cable: 5 V differential pulse of 250 ns (50 % to
// 50 %) with 10 ns edges (10-90 %), 49 ohm in each line, 100 ohm load. The edges are smooth
// (erf-shaped, as a driver's are; sampled every 0.25 ns): ideal linear ramps have corners whose
// spectrum reaches past any lumped ladder's cutoff (README "Cable", segment count).
StatusOr<Waveform> received_pulse(int segments, int* used, int loss_stride = 0) {
  CableSpec spec;
  spec.length = 10;
  spec.segments = segments;
  spec.loss_stride = loss_stride;
  const double edge = 10e-9, t0 = 15e-9, width = 250e-9, dt = 0.25e-9;
  std::vector<Card> cards;
  if (Status s = add_cable(cards, "cab", "ap", "an", "bp", "bn", spec, edge); !s.ok()) return s;
  *used = cable_segments(spec, *cable_model(spec), edge);
  const double sigma = edge / (2 * 1.2815515655);  // 10-90 % of a Gaussian edge
  for (int sign : {+1, -1}) {
    std::vector<double> pwl = {0, 0};
    for (double centre : {t0, t0 + width}) {
      const bool rising = centre == t0;
      for (double t = centre - 3.5 * sigma; t <= centre + 3.5 * sigma + 1e-15; t += dt) {
        const double phi = 0.5 * std::erfc(-(t - centre) / (std::sqrt(2.0) * sigma));
        pwl.push_back(t);
        pwl.push_back(2.5 * sign * (rising ? phi : 1 - phi));
      }
    }
    cards.push_back(source(sign > 0 ? "vp" : "vn", sign > 0 ? "sp" : "sn", "0", pwl));
  }
  cards.push_back(resistor("rsp", "sp", "ap", 49));
  cards.push_back(resistor("rsn", "sn", "an", 49));
  cards.push_back(resistor("rl", "bp", "bn", 100));
  Circuit c;
  if (Status s = add_cards(c, cards); !s.ok()) return s;
  if (Status s = c.finalize(); !s.ok()) return s;
  TransientOptions opt{.tstep = 1e-9, .tstop = 450e-9};
  return run_transient(c, opt, {*parse_probe(c, "v(bp,bn)")});
}

TEST(Cable, DoublingTheSegmentsMovesTheWaveformLessThan5mV) {
  int n = 0, n2 = 0;
  auto coarse = received_pulse(0, &n);
  ASSERT_TRUE(coarse.ok()) << coarse.status().message();
  auto fine = received_pulse(2 * n, &n2);
  ASSERT_TRUE(fine.ok()) << fine.status().message();
  double worst = 0, peak = 0;
  for (const Waveform* w : {&*coarse, &*fine}) {
    const Waveform& other = w == &*coarse ? *fine : *coarse;
    for (size_t i = 0; i < w->samples(); ++i) {
      worst = std::max(worst, std::abs(w->columns[0][i] - other.value_at(0, w->time[i])));
      peak = std::max(peak, w->columns[0][i]);
    }
  }
  std::printf("10 m PP, %d vs %d segments: max difference %.2f mV (received peak %.3f V)\n", n, n2,
              1e3 * worst, peak);
  EXPECT_EQ(n, 46);  // 10 m / 0.73 c = 45.6 ns in segments of at most 1 ns
  EXPECT_EQ(n2, 2 * n);
  EXPECT_GT(peak, 2.3);  // 5 V * 100 / (98 + 100), less a little cable loss
  EXPECT_LT(worst, 5e-3);
}

TEST(Cable, LumpingTheLossEveryFewSegmentsMovesTheWaveformLessThan2mV) {
  // The skin and dielectric ladders in every segment against lumped every loss_stride(46) = 4.
  int n = 0, n1 = 0;
  auto lumped = received_pulse(0, &n);
  ASSERT_TRUE(lumped.ok()) << lumped.status().message();
  auto every = received_pulse(0, &n1, 1);
  ASSERT_TRUE(every.ok()) << every.status().message();
  EXPECT_EQ(loss_stride(n), 4);
  double worst = 0;
  for (size_t i = 0; i < every->samples(); ++i)
    worst = std::max(worst, std::abs(every->columns[0][i] - lumped->value_at(0, every->time[i])));
  std::printf("10 m PP, loss in every segment vs every 4th: max difference %.2f mV\n", 1e3 * worst);
  EXPECT_LT(worst, 2e-3);
}

TEST(Cable, LossSectionsAddUpToTheWholeLength) {
  // However the skin ladders are lumped, their elements stand for the whole length: the first
  // section's resistors of both conductors add up to 2 r_0 length.
  for (int stride : {1, 3, 4}) {
    CableSpec spec;
    spec.length = 7;
    spec.segments = 10;
    spec.loss_stride = stride;
    std::vector<Card> cards;
    ASSERT_TRUE(add_cable(cards, "cab", "ap", "an", "bp", "bn", spec).ok());
    double skin_r = 0;
    for (const Card& c : cards)
      if (c.letter == 'r' && c.name.find("_s0") != std::string::npos) skin_r += c.args[0].number;
    auto m = cable_model(spec);
    ASSERT_TRUE(m.ok());
    EXPECT_NEAR(skin_r, 2 * m->skin[0].r * spec.length, 1e-9 * skin_r) << stride;
  }
}

TEST(Cable, CardsAreNamedAfterThePrefix) {
  CableSpec spec;
  spec.segments = 3;
  std::vector<Card> cards;
  ASSERT_TRUE(add_cable(cards, "cab", "ap", "an", "bp", "bn", spec).ok());
  int inductors = 0, couplings = 0;
  for (const Card& c : cards) {
    EXPECT_EQ(c.name[0], c.letter);
    EXPECT_EQ(c.name.substr(1, 4), "cab_") << c.name;
    EXPECT_EQ(c.node_locs.size(), c.nodes.size());
    EXPECT_EQ(c.ref_locs.size(), c.refs.size());
    inductors += c.letter == 'l';
    couplings += c.letter == 'k';
  }
  auto m = cable_model(spec);
  EXPECT_EQ(couplings, 3 + 4 * 2);  // p-n in each segment, 4 between neighbouring segments
  EXPECT_EQ(inductors, 3 * 2 * (1 + static_cast<int>(m->skin.size())));
  EXPECT_EQ(cards.back().name, "ccab_gn3");
  // DC: 1 V into the loop of both conductors through a 1 ohm short at the far end; the skin
  // sections' inductors short their resistors, the dielectric branches are open.
  cards.push_back(source("vp", "ap", "0", {1.0}));
  cards.push_back(source("vn", "an", "0", {0.0}));
  cards.push_back(resistor("rshort", "bp", "bn", 1.0));
  Circuit c;
  ASSERT_TRUE(add_cards(c, cards).ok());
  ASSERT_TRUE(c.finalize().ok());
  EXPECT_GE(c.find_node("cab_p1"), 1);
  auto x = dc_operating_point(c);
  ASSERT_TRUE(x.ok()) << x.status().message();
  const double i = 1.0 / (2 * m->r_dc * spec.length + 1.0);
  EXPECT_NEAR((*x)[c.find_node("bp")] - (*x)[c.find_node("bn")], i, 1e-9);
}

}  // namespace
}  // namespace isolink::link
