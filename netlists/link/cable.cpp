#include "netlists/link/cable.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <string>

#include "netlists/link/cards.h"
#include "netlists/link/touchstone_cable.h"
#include "solver/nnls.h"

namespace isolink::link {

namespace {

using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kMu0 = 4e-7 * kPi;         // H/m (close enough to the 2019 SI value)
constexpr double kC0 = 299'792'458.0;       // m/s
constexpr double kRhoCu20 = 1.724e-8;       // ohm m, annealed copper at 20 degC (IACS)
constexpr double kAlphaCu = 0.00393;        // 1/K, copper resistance temperature coefficient
constexpr double kFillDiff = 0.70;          // differential fill factor: er_eff = 1 + q (er - 1)
constexpr int kSkinSections = 7;            // R || L sections per conductor
constexpr int kDielectricBranches = 7;      // series R-C branches across the pair
constexpr int kMaxLossStride = 4;           // segments per loss section, at most
constexpr double kNeighbourCoupling = 0.1;  // kappa between adjacent segments' inductors

// Insulation wall (mm) for even gauges 18..30, interpolated for odd ones (assumed, typical
// thin-wall hook-up / data wire; README "Cable").
double wall_mm(int gauge) {
  static constexpr double kWall[] = {0.30, 0.28, 0.26, 0.25, 0.23, 0.20, 0.18};  // 18, 20, ... 30
  const int i = (gauge - 18) / 2;
  if (gauge % 2 == 0) return kWall[i];
  return 0.5 * (kWall[i] + kWall[i + 1]);
}

// AWG diameter (m): 0.127 mm * 92^((36 - n) / 39) (ASTM B258).
double awg_diameter(int gauge) {
  return 0.127e-3 * std::pow(92.0, (36.0 - gauge) / 39.0);
}

struct Insulation {
  double er, tan_delta;
};
// Relative permittivity and loss tangent at 1 MHz and the temperature (degC). PP: constant;
// PVC: assumed linear drift (README "Cable").
Insulation insulation(const std::string& material, double t) {
  if (material == "pvc") return {4.5 + 0.015 * (t - 25.0), 0.05 + 0.0003 * (t - 25.0)};
  return {2.25, 3e-4};
}

// J1(z) / J0(z) by backward recurrence of r_n = J_n / J_{n-1} = 1 / (2n / z - r_{n+1}), which
// converges for any z (J_n is the minimal solution of the Bessel recurrence).
cd bessel_j1_over_j0(cd z) {
  if (std::abs(z) < 1e-8) return z / 2.0;
  // Large |z| below the real axis (the skin effect's z has arg -45 degrees): Hankel asymptotics,
  // J1 / J0 = -j + 1 / (2 z) + O(1 / z^2).
  if (std::abs(z) > 200 && z.imag() < 0) return cd(0, -1) + 1.0 / (2.0 * z);
  const int n_max = 40 + 2 * static_cast<int>(std::abs(z));
  cd r = 0;
  for (int n = n_max; n >= 1; --n) r = 1.0 / (2.0 * n / z - r);
  return r;
}

// Fit points: a little wider than the band so the band's ends are not the fit's ends; the
// fits are then scored on the band itself.
std::vector<double> fit_frequencies() {
  return log_space(CableModel::kFitLow / 2, CableModel::kFitHigh * 2, 81);
}
std::vector<double> score_frequencies() {
  return log_space(CableModel::kFitLow, CableModel::kFitHigh, 61);
}

// Skin ladder: Z_int(f) - R_dc = sum R_i (j f / f_i) / (1 + j f / f_i), R_i >= 0 (NNLS), each
// frequency weighted by 1 / |Z_int|. The corners f_i are log-spaced; their span is chosen from a
// small grid (around the skin corner 2 R_dc / mu0 and up to a few GHz) for the smallest worst
// error over the band: max(|dR| / R, |dX| / (2 X)).
std::vector<SkinSection> fit_skin(const CableModel& m) {
  const std::vector<double> freqs = fit_frequencies(), check = score_frequencies();
  std::vector<cd> target(freqs.size()), check_target(check.size());
  for (size_t k = 0; k < freqs.size(); ++k) target[k] = m.target_internal_impedance(freqs[k]);
  for (size_t k = 0; k < check.size(); ++k) check_target[k] = m.target_internal_impedance(check[k]);
  const double f_skin = 2 * m.r_dc / kMu0;
  std::vector<SkinSection> best;
  double best_score = INFINITY;
  for (double lo_factor : {0.25, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0}) {
    for (double hi : {0.5e9, 0.7e9, 1e9, 1.4e9, 2e9, 3e9, 5e9}) {
      const double lo = std::max(lo_factor * f_skin, 1e3);
      const std::vector<double> poles = log_space(lo, hi, kSkinSections);
      const int rows = 2 * static_cast<int>(freqs.size());
      Eigen::MatrixXd a(rows, kSkinSections);
      Eigen::VectorXd b(rows);
      for (size_t k = 0; k < freqs.size(); ++k) {
        const double w = 1.0 / std::abs(target[k]);
        const int row = 2 * static_cast<int>(k);
        for (int i = 0; i < kSkinSections; ++i) {
          const cd s(0, freqs[k] / poles[i]);
          const cd basis = s / (1.0 + s);
          a(row, i) = w * basis.real();
          a(row + 1, i) = w * basis.imag();
        }
        b[row] = w * (target[k].real() - m.r_dc);
        b[row + 1] = w * target[k].imag();
      }
      const Eigen::VectorXd r = nnls(a, b);
      CableModel trial;
      trial.r_dc = m.r_dc;
      for (int i = 0; i < kSkinSections; ++i)
        if (r[i] > 0) trial.skin.push_back({r[i], r[i] / (2 * kPi * poles[i])});
      double score = 0;
      for (size_t k = 0; k < check.size(); ++k) {
        const cd z = trial.internal_impedance(check[k]), zt = check_target[k];
        score = std::max(
            {score, std::abs(z.real() / zt.real() - 1), 0.5 * std::abs(z.imag() / zt.imag() - 1)});
      }
      if (score < best_score) best_score = score, best = trial.skin;
    }
  }
  return best;
}

// Dielectric ladder on the normalised capacitance c(f): c_inf + sum c_i / (1 + j 2 pi f tau_i),
// c >= 0 (NNLS); real parts weighted relative to |c|, imaginary parts relative to the loss
// |Im c|. Corner span from a small grid, scored by max(|dG| / G, 10 |dC| / C) over the band.
void fit_dielectric(CableModel& m) {
  const std::vector<double> freqs = fit_frequencies(), check = score_frequencies();
  const int n = kDielectricBranches + 1;
  const int rows = 2 * static_cast<int>(freqs.size());
  double best_score = INFINITY;
  CableModel best = m;
  for (double lo : {3e3, 5e3, 10e3, 20e3, 40e3}) {
    for (double hi : {0.3e9, 0.5e9, 1e9, 2e9, 4e9}) {
      const std::vector<double> poles = log_space(lo, hi, kDielectricBranches);
      Eigen::MatrixXd a(rows, n);
      Eigen::VectorXd b(rows);
      for (size_t k = 0; k < freqs.size(); ++k) {
        const cd target = m.target_capacitance_factor(freqs[k]);
        const double wr = 1.0 / std::abs(target), wi = 1.0 / std::abs(target.imag());
        const int row = 2 * static_cast<int>(k);
        a(row, 0) = wr;
        a(row + 1, 0) = 0;
        for (int i = 0; i < kDielectricBranches; ++i) {
          const cd basis = 1.0 / cd(1.0, freqs[k] / poles[i]);
          a(row, i + 1) = wr * basis.real();
          a(row + 1, i + 1) = wi * basis.imag();
        }
        b[row] = wr * target.real();
        b[row + 1] = wi * target.imag();
      }
      const Eigen::VectorXd x = nnls(a, b);
      CableModel trial = m;
      trial.c_inf = x[0];
      trial.dielectric.clear();
      for (int i = 0; i < kDielectricBranches; ++i)
        if (x[i + 1] > 0) trial.dielectric.push_back({x[i + 1], 1.0 / (2 * kPi * poles[i])});
      double score = 0;
      for (double f : check) {
        const cd c = trial.capacitance_factor(f), ct = m.target_capacitance_factor(f);
        score = std::max(
            {score, std::abs(c.imag() / ct.imag() - 1), 10 * std::abs(c.real() / ct.real() - 1)});
      }
      if (score < best_score) best_score = score, best = std::move(trial);
    }
  }
  m.c_inf = best.c_inf;
  m.dielectric = best.dielectric;
}

Status field_error(const char* field, double v, const std::string& rule) {
  return Status::Error(fmt::format("cable.{} = {:g}: {}", field, v, rule));
}

Card card(char letter, std::string name, std::vector<std::string> nodes, double value,
          std::vector<std::string> refs = {}) {
  return make_card(letter, std::move(name), std::move(nodes), {number_arg(value)}, std::move(refs));
}

}  // namespace

Status CableSpec::validate() const {
  if (!(length > 0) || !std::isfinite(length)) return field_error("length", length, "must be > 0");
  // The model's valid range: below 1 cm the per-metre L and C vanish next to the board parts
  // (a 1 nm cable made a singular matrix); above 100 m the segment count (at most 200 when
  // automatic) no longer resolves 10 ns edges, and no daisy-chain hop is that long.
  if (length < kMinCableLength || length > kMaxCableLength)
    return field_error("length", length,
                       fmt::format("the cable model is valid from {:g} m to {:g} m",
                                   kMinCableLength, kMaxCableLength));
  if (material != "pp" && material != "pvc")
    return Status::Error(fmt::format("cable.material = '{}': must be pp or pvc", material));
  if (gauge < 18 || gauge > 30)
    return field_error("gauge", gauge, "must be an AWG size from 18 to 30");
  if (!(temperature >= -40 && temperature <= 125))
    return field_error("temperature", temperature, "must be within -40..125 degC");
  if (material == "pvc" && temperature > 105)
    return field_error("temperature", temperature,
                       "the PVC model covers -40..105 degC (PVC wire insulation is rated to 105)");
  if (r && !(*r >= 0 && std::isfinite(*r)))
    return field_error("r", *r, "must be >= 0 (ohm/m per conductor)");
  if (l && !(*l > 0 && std::isfinite(*l))) return field_error("l", *l, "must be > 0 (H/m)");
  if (c && !(*c > 0 && std::isfinite(*c))) return field_error("c", *c, "must be > 0 (F/m)");
  if (g && !(*g >= 0 && std::isfinite(*g))) return field_error("g", *g, "must be >= 0 (S/m)");
  if (chassis_c && !(*chassis_c > 0 && std::isfinite(*chassis_c)))
    return field_error("chassis_c", *chassis_c, "must be > 0 (F/m per conductor)");
  if (segments < 0 || segments > 1000)
    return field_error("segments", segments, "must be 0 (automatic) or 1..1000");
  if (!(fit_tolerance > 0 && fit_tolerance <= 0.5))
    return field_error("tolerance", fit_tolerance, "must be in (0, 0.5] (RMS of |S_fit - S|)");
  return Status::Ok();
}

double CableModel::g_diff() const {
  return 2 * kPi * kReferenceFrequency * c_diff() * tan_delta_eff;
}
double CableModel::z_diff() const {
  return std::sqrt(l_diff / c_diff());
}
double CableModel::velocity() const {
  return 1.0 / std::sqrt(l_diff * c_diff());
}
double CableModel::z_cm() const {
  return std::sqrt(l_cm / c_cm());
}
double CableModel::velocity_cm() const {
  return 1.0 / std::sqrt(l_cm * c_cm());
}

cd round_wire_skin_factor(double x) {
  const cd z = std::sqrt(cd(0, -x));
  return std::abs(z) < 1e-8 ? cd(1.0) : (z / 2.0) / bessel_j1_over_j0(z);
}

cd CableModel::target_internal_impedance(double f) const {
  if (!skin_effect || r_dc <= 0) return r_dc;
  // Round wire: Z = R_dc (z / 2) J0(z) / J1(z), z^2 = -j w mu0 / (pi R_dc) = -j w mu0 sigma a^2;
  // the frequency-dependent part scaled by the pair's proximity factor.
  const cd isolated = r_dc * round_wire_skin_factor(f * 2 * kMu0 / r_dc);
  return r_dc + proximity * (isolated - r_dc);
}

cd CableModel::internal_impedance(double f) const {
  cd z = r_dc;
  for (const SkinSection& s : skin) {
    const cd jwl(0, 2 * kPi * f * s.l);
    z += s.r * jwl / (s.r + jwl);
  }
  return z;
}

cd CableModel::target_capacitance_factor(double f) const {
  if (!dielectric_loss || dc_delta == 0) return 1.0;
  const double w1 = 2 * kPi * debye_f1, w2 = 2 * kPi * debye_f2, w = 2 * kPi * f;
  return dc_inf + dc_delta * std::log(cd(w2, w) / cd(w1, w)) / std::log(w2 / w1);
}

cd CableModel::capacitance_factor(double f) const {
  cd c = c_inf;
  for (const DielectricBranch& d : dielectric) c += d.c / cd(1.0, 2 * kPi * f * d.tau);
  return c;
}

cd CableModel::series_impedance_diff(double f) const {
  return 2.0 * internal_impedance(f) + cd(0, 2 * kPi * f * l_diff);
}
cd CableModel::shunt_admittance_diff(double f) const {
  return cd(0, 2 * kPi * f * c_diff()) * capacitance_factor(f);
}
cd CableModel::target_series_impedance_diff(double f) const {
  return 2.0 * target_internal_impedance(f) + cd(0, 2 * kPi * f * l_diff);
}
cd CableModel::target_shunt_admittance_diff(double f) const {
  return cd(0, 2 * kPi * f * c_diff()) * target_capacitance_factor(f);
}
cd CableModel::gamma_diff(double f) const {
  return std::sqrt(series_impedance_diff(f) * shunt_admittance_diff(f));
}
cd CableModel::target_gamma_diff(double f) const {
  return std::sqrt(target_series_impedance_diff(f) * target_shunt_admittance_diff(f));
}
cd CableModel::target_z0_diff(double f) const {
  return std::sqrt(target_series_impedance_diff(f) / target_shunt_admittance_diff(f));
}

namespace {

// cable_model without the cache: everything but `length` is per metre.
StatusOr<CableModel> compute_cable_model(const CableSpec& spec) {
  CableModel m;
  m.length = spec.length;
  m.material = spec.material;
  m.gauge = spec.gauge;
  m.temperature = spec.temperature;
  m.skin_effect = spec.skin_effect;
  m.dielectric_loss = spec.dielectric_loss;

  // Geometry.
  m.wire_diameter = awg_diameter(spec.gauge);
  m.wall = wall_mm(spec.gauge) * 1e-3;
  m.spacing = m.wire_diameter + 2 * m.wall;
  const double a = m.wire_diameter / 2, d = m.spacing, h = m.height;

  // Copper.
  const double rho = kRhoCu20 * (1 + kAlphaCu * (spec.temperature - 20.0));
  m.r_dc = spec.r ? *spec.r : rho / (kPi * a * a);
  // Proximity effect of the pair at high frequency (current crowding towards the other wire):
  // R_pair / R_isolated = (D / 2a) / sqrt((D / 2a)^2 - 1).
  const double u = d / (2 * a);
  m.proximity = u / std::sqrt(u * u - 1);

  // Inductance: two round wires (exact differential loop), common mode from images.
  m.l_diff = kMu0 / kPi * std::acosh(d / (2 * a));
  const double l_self_img = kMu0 / (2 * kPi) * std::log(2 * h / a);
  const double m_img = kMu0 / (2 * kPi) * std::log(std::hypot(2 * h, d) / d);
  m.l_cm = (l_self_img + m_img) / 2;
  if (spec.l) {
    if (!(*spec.l < 4 * m.l_cm))
      return field_error("l", *spec.l,
                         fmt::format("must be below 4 l_cm = {:.4g} H/m (the common-mode "
                                     "inductance of the geometry: the coupling would exceed 1)",
                                     4 * m.l_cm));
    m.l_diff = *spec.l;
  }
  m.l_self = m.l_cm + m.l_diff / 4;
  m.k_pn = (m.l_cm - m.l_diff / 4) / m.l_self;

  // Insulation and capacitance.
  const Insulation ins = insulation(spec.material, spec.temperature);
  m.er = ins.er;
  m.tan_delta = ins.tan_delta;
  m.er_eff = 1 + kFillDiff * (m.er - 1);
  // Common mode: air with a coaxial insulation shell of the wall's thickness on each wire.
  const double x = std::log(4 * h * h / (a * d));
  m.er_eff_cm = x / (x - (1 - 1 / m.er) * std::log(1 + m.wall / a));
  m.c_g = m.er_eff_cm / (kC0 * kC0 * m.l_cm) / 2;
  double c_diff = m.er_eff / (kC0 * kC0 * m.l_diff);
  if (spec.chassis_c) {
    const double c_d = spec.c ? *spec.c : c_diff;
    if (!(*spec.chassis_c < 2 * c_d))
      return field_error("chassis_c", *spec.chassis_c,
                         fmt::format("must be below 2 c = {:.4g} F/m (the differential "
                                     "capacitance holds half of it)",
                                     2 * c_d));
    m.c_g = *spec.chassis_c;
  }
  if (spec.c) {
    if (!(*spec.c > m.c_g / 2))
      return field_error("c", *spec.c,
                         fmt::format("must exceed c_g / 2 = {:.4g} F/m (each line's capacitance "
                                     "to the reference)",
                                     m.c_g / 2));
    c_diff = *spec.c;
  }
  m.c_pn = c_diff - m.c_g / 2;

  // Dielectric loss: effective loss tangent of the differential mode (the share of its field
  // energy in the insulation), or from an explicit g.
  m.tan_delta_eff = kFillDiff * m.er * m.tan_delta / m.er_eff;
  if (spec.g) m.tan_delta_eff = *spec.g / (2 * kPi * CableModel::kReferenceFrequency * c_diff);
  if (!spec.dielectric_loss) m.tan_delta_eff = 0;
  if (m.tan_delta_eff > 0.2)
    return field_error(
        "g", spec.g.value_or(0),
        fmt::format("gives a loss tangent of {:.3g}; the model takes up to 0.2", m.tan_delta_eff));

  if (m.tan_delta_eff > 0) {
    // Wideband Debye: Im c = -dc_delta (atan(w/w1) - atan(w/w2)) / ln(w2/w1); Re c = 1 at f_ref.
    const double w1 = 2 * kPi * m.debye_f1, w2 = 2 * kPi * m.debye_f2;
    const double w = 2 * kPi * CableModel::kReferenceFrequency, span = std::log(w2 / w1);
    m.dc_delta = m.tan_delta_eff * span / (std::atan(w / w1) - std::atan(w / w2));
    m.dc_inf = 1 - m.dc_delta * std::log(std::abs(cd(w2, w) / cd(w1, w))) / span;
    fit_dielectric(m);
    if (!(m.c_inf * c_diff - m.c_g / 2 > 0))
      return Status::Error(
          fmt::format("cable: the dielectric loss (tan delta {:.3g}) leaves no room for the lines' "
                      "capacitance to the reference in the fitted ladder",
                      m.tan_delta_eff));
  } else {
    m.c_inf = 1;
    m.dielectric.clear();
  }

  if (m.skin_effect && m.r_dc > 0) m.skin = fit_skin(m);
  return m;
}

// What the per-metre model depends on: every field but the length and the ladder's layout
// (segments, loss_stride), exactly (hex floats).
std::string per_metre_key(const CableSpec& spec) {
  auto opt = [](const std::optional<double>& x) { return x ? fmt::format("{:a}", *x) : "-"; };
  return fmt::format("{}|{}|{:a}|{}|{}|{}|{}|{}|{}|{}", spec.material, spec.gauge, spec.temperature,
                     opt(spec.r), opt(spec.l), opt(spec.c), opt(spec.g), opt(spec.chassis_c),
                     spec.skin_effect, spec.dielectric_loss);
}

}  // namespace

StatusOr<CableModel> cable_model(const CableSpec& spec) {
  if (Status s = spec.validate(); !s.ok()) return s;
  // The ladder fits (a few ms) do not depend on the length, and a length sweep expands the same
  // cable several times per point (the edge response, both directions, the worst case): the
  // per-metre models are kept, at most kKept of them, shared by the threads.
  constexpr size_t kKept = 64;
  static std::mutex mutex;
  static std::map<std::string, CableModel> kept;
  const std::string key = per_metre_key(spec);
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = kept.find(key); it != kept.end()) {
      CableModel m = it->second;
      m.length = spec.length;
      return m;
    }
  }
  StatusOr<CableModel> m = compute_cable_model(spec);
  if (!m) return m;
  std::lock_guard<std::mutex> lock(mutex);
  if (kept.size() >= kKept) kept.clear();
  kept.emplace(key, *m);
  return m;
}

int loss_stride(int segments) {
  return std::clamp(segments / 8, 1, kMaxLossStride);
}
int loss_stride(const CableSpec& spec, int segments) {
  return spec.loss_stride > 0 ? spec.loss_stride : loss_stride(segments);
}

std::vector<double> log_space(double lo, double hi, int n) {
  std::vector<double> out(n);
  for (int i = 0; i < n; ++i)
    out[i] = n == 1 ? lo : lo * std::pow(hi / lo, static_cast<double>(i) / (n - 1));
  return out;
}

int cable_segments(const CableSpec& spec, const CableModel& m, double edge_time) {
  if (spec.segments > 0) return spec.segments;
  if (!(edge_time > 0)) return 200;
  const double delay = m.length / m.velocity();
  const double n = std::ceil(delay / (edge_time / 10) - 1e-9);
  return static_cast<int>(std::clamp(n, 2.0, 200.0));
}

Status add_cable(std::vector<Card>& cards, const std::string& prefix, const std::string& a_p,
                 const std::string& a_n, const std::string& b_p, const std::string& b_n,
                 const CableSpec& spec, double edge_time, int* segments) {
  if (!(edge_time > 0) || !std::isfinite(edge_time))
    return Status::Error(fmt::format("cable {}: edge time {:g} s must be > 0", prefix, edge_time));
  if (!spec.touchstone.empty()) {
    return add_touchstone_cable(cards, prefix, a_p, a_n, b_p, b_n, spec, edge_time, segments);
  }
  StatusOr<CableModel> model = cable_model(spec);
  if (!model) return model.status();
  const int n = cable_segments(spec, *model, edge_time);
  if (segments != nullptr) *segments = n;
  add_cable_ladder(cards, prefix, a_p, a_n, b_p, b_n, *model, n, loss_stride(spec, n));
  return Status::Ok();
}

void add_cable_ladder(std::vector<Card>& cards, const std::string& prefix, const std::string& a_p,
                      const std::string& a_n, const std::string& b_p, const std::string& b_n,
                      const CableModel& m, int n, int stride) {
  const double dz = m.length / n;

  auto node = [&](char side, int j) -> std::string {
    if (j == 0) return side == 'p' ? a_p : a_n;
    if (j == n) return side == 'p' ? b_p : b_n;
    return fmt::format("{}_{}{}", prefix, side, j);
  };

  // External inductance of segment i: neighbouring segments' inductors are coupled with
  // kappa = 1/10 (M = kappa L_seg), which cancels the lumped ladder's leading dispersion term;
  // L_seg = L dz / (1 + 2 kappa) keeps every row sum of the inductance matrix at L dz, and the two
  // end segments, with one neighbour each, get L_seg (1 + kappa). One segment: no neighbours.
  const double kappa = n >= 2 ? kNeighbourCoupling : 0.0;
  const double l_seg = m.l_self * dz / (1 + 2 * kappa);
  auto l_of = [&](int i) { return (i == 1 || i == n) ? l_seg * (1 + kappa) : l_seg; };

  // Loss sections: the skin ladders and the dielectric branches are small corrections to each
  // segment's R, L and C, so they are lumped every `stride` segments (their values scaled by the
  // length they stand for) instead of in every segment: most of a segment's unknowns are in its
  // ladders, and the wave's timing needs the fine LC segments, not fine loss sections.
  // Segment i (1..n) carries the skin ladder of segments i - stride + 1 .. i (and the last one
  // the rest).
  auto series_loss_length = [&](int i) -> double {
    if (i == n) return dz * (n - (n - 1) / stride * stride);
    return i % stride == 0 ? dz * stride : 0.0;
  };
  // Node j (0..n) carries the dielectric branches of the shunt length around it: nodes are
  // grouped in runs of `stride` from node 0; the run's middle node carries the run's length.
  auto shunt_loss_length = [&](int j) -> double {
    auto len_of = [&](int k) { return (k == 0 || k == n) ? dz / 2 : dz; };
    const int first = j / stride * stride;
    const int last = std::min(n, first + stride - 1);
    if (j != (first + last) / 2) return 0.0;
    double total = 0;
    for (int k = first; k <= last; ++k) total += len_of(k);
    return total;
  };

  // Series branches of segment i (1..n), per conductor: R_dc, L_ext (coupled), skin sections.
  for (int i = 1; i <= n; ++i) {
    for (char side : {'p', 'n'}) {
      std::string from = node(side, i - 1);
      int k = 0;
      auto next = [&]() { return fmt::format("{}_{}{}_{}", prefix, side, i, k++); };
      const bool last_is_l = m.skin.empty() || series_loss_length(i) == 0;
      if (m.r_dc > 0) {
        std::string to = next();
        cards.push_back(
            card('r', fmt::format("r{}_{}{}", prefix, side, i), {from, to}, m.r_dc * dz));
        from = to;
      }
      std::string to = last_is_l ? node(side, i) : next();
      cards.push_back(card('l', fmt::format("l{}_{}{}", prefix, side, i), {from, to}, l_of(i)));
      from = to;
      const double skin_len = series_loss_length(i);
      for (size_t s = 0; s < m.skin.size() && skin_len > 0; ++s) {
        to = s + 1 == m.skin.size() ? node(side, i) : next();
        cards.push_back(card('r', fmt::format("r{}_{}{}_s{}", prefix, side, i, s), {from, to},
                             m.skin[s].r * skin_len));
        cards.push_back(card('l', fmt::format("l{}_{}{}_s{}", prefix, side, i, s), {from, to},
                             m.skin[s].l * skin_len));
        from = to;
      }
    }
    if (m.k_pn != 0)  // 0 on a measured 2-port's delay line
      cards.push_back(card('k', fmt::format("k{}_{}", prefix, i), {}, m.k_pn,
                           {fmt::format("l{}_p{}", prefix, i), fmt::format("l{}_n{}", prefix, i)}));
    if (i < n && kappa > 0) {
      const double k_adj = kappa * l_seg / std::sqrt(l_of(i) * l_of(i + 1));
      for (auto [a, b, k] :
           {std::tuple{'p', 'p', k_adj}, std::tuple{'n', 'n', k_adj},
            std::tuple{'p', 'n', k_adj * m.k_pn}, std::tuple{'n', 'p', k_adj * m.k_pn}})
        if (k != 0)
          cards.push_back(card(
              'k', fmt::format("k{}_{}{}{}", prefix, a, b, i), {}, k,
              {fmt::format("l{}_{}{}", prefix, a, i), fmt::format("l{}_{}{}", prefix, b, i + 1)}));
    }
  }

  // Shunt elements at node j (0..n): half a segment's worth at the ends (pi segments).
  const double c_diff = m.c_diff();
  for (int j = 0; j <= n; ++j) {
    const double len = (j == 0 || j == n) ? dz / 2 : dz;
    const std::string p = node('p', j), q = node('n', j);
    cards.push_back(card('c', fmt::format("c{}_pn{}", prefix, j), {p, q},
                         (m.c_inf * c_diff - m.c_g / 2) * len));
    const double loss_len = shunt_loss_length(j);
    for (size_t b = 0; b < m.dielectric.size() && loss_len > 0; ++b) {
      const double cb = m.dielectric[b].c * c_diff * loss_len;
      const std::string mid = fmt::format("{}_pn{}_d{}", prefix, j, b);
      cards.push_back(
          card('r', fmt::format("r{}_pn{}_d{}", prefix, j, b), {p, mid}, m.dielectric[b].tau / cb));
      cards.push_back(card('c', fmt::format("c{}_pn{}_d{}", prefix, j, b), {mid, q}, cb));
    }
    if (m.c_g > 0) {  // none on a measured 2-port's delay line (its common mode is open)
      cards.push_back(card('c', fmt::format("c{}_gp{}", prefix, j), {p, "0"}, m.c_g * len));
      cards.push_back(card('c', fmt::format("c{}_gn{}", prefix, j), {q, "0"}, m.c_g * len));
    }
  }
}

}  // namespace isolink::link
