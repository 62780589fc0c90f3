#include "netlists/link/measured_line.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "solver/nnls.h"

namespace isolink::link {

namespace {

using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kCornersPerDecade = 3;

// The modes of one end, as rows (orthonormal): (P - N) / sqrt 2 and (P + N) / sqrt 2.
Eigen::MatrixXd end_modes() {
  const double r = 1 / std::sqrt(2.0);
  Eigen::MatrixXd q(2, 2);
  q << r, -r, r, r;
  return q;
}

// Per point (f > 0): a mode's propagation gamma (per metre of a 1 m line) and characteristic
// impedance, both in the mode's own terms (v_m / i_m).
struct ModeData {
  std::vector<double> f;
  std::vector<cd> gamma, zc;
};

// One mode's 2-port admittances (y11, y22, y12) per point read as a uniform line; nothing when
// the mode is attenuated by 40 dB or more, or is not finite, at some point.
std::optional<ModeData> read_mode(const std::vector<double>& freqs,
                                  const std::vector<Eigen::Vector3cd>& mode) {
  ModeData out;
  double prev_phase = 0, prev_f = 0;
  for (size_t k = 0; k < freqs.size(); ++k) {
    const double f = freqs[k];
    if (!(f > 0)) continue;
    const cd y11 = mode[k][0], y22 = mode[k][1], y12 = mode[k][2];
    const cd x = -(y11 + y22) / (2.0 * y12);
    cd e = x - std::sqrt(x * x - 1.0);  // e^{-gamma}, the root of magnitude at most 1
    if (std::abs(e) > 1) e = 1.0 / e;
    if (!std::isfinite(e.real()) || !std::isfinite(e.imag())) return std::nullopt;
    // Past 40 dB of attenuation the far end's share of the file is under 1 %: the band below is
    // read, and the score over the whole band (touchstone_cable.cpp) decides.
    if (!(std::abs(e) >= 0.01)) break;
    // The branch of the phase nearest the previous point's phase delay carried to f.
    const double raw = -std::arg(e);
    const double predicted = prev_f > 0 ? prev_phase * f / prev_f : 0.0;
    const double phase = raw + 2 * kPi * std::round((predicted - raw) / (2 * kPi));
    cd zc = 1.0 / std::sqrt(y11 * y22 - y12 * y12);
    if (zc.real() < 0) zc = -zc;
    if (!std::isfinite(zc.real()) || !std::isfinite(zc.imag())) return std::nullopt;
    out.f.push_back(f);
    out.gamma.push_back(cd(-std::log(std::abs(e)), phase));
    out.zc.push_back(zc);
    prev_phase = phase, prev_f = f;
  }
  if (out.f.size() < 10) return std::nullopt;
  return out;
}

// Corners for the ladders: kCornersPerDecade over the band (from its first point above 0, at
// least 1 kHz) widened by a factor 2 each side, 3 to 14 of them.
std::vector<double> corners(const std::vector<double>& f) {
  const double lo = std::max(f.front(), 1e3) / 2, hi = 2 * f.back();
  const int n =
      std::clamp(static_cast<int>(std::ceil(kCornersPerDecade * std::log10(hi / lo))) + 1, 3, 24);
  return log_space(lo, hi, n);
}

// Least squares of complex rows, x >= 0: each row's real and imaginary parts weighted by their
// own size (relative errors of each: the loss and the reactance are fitted alike, where one
// weight per point would fit a line's resistance only to its reactance's rounding; a part under a
// thousandth of the row's magnitude is weighed at that).
Eigen::VectorXd nonnegative_fit(const std::vector<std::vector<cd>>& basis,
                                const std::vector<cd>& target) {
  const int rows = static_cast<int>(target.size()), cols = static_cast<int>(basis[0].size());
  Eigen::MatrixXd a(2 * rows, cols);
  Eigen::VectorXd b(2 * rows);
  for (int k = 0; k < rows; ++k) {
    const double floor = 1e-3 * std::abs(target[k]);
    const double wr = 1 / (std::abs(target[k].real()) + floor);
    const double wi = 1 / (std::abs(target[k].imag()) + floor);
    for (int j = 0; j < cols; ++j) {
      a(2 * k, j) = wr * basis[k][j].real();
      a(2 * k + 1, j) = wi * basis[k][j].imag();
    }
    b[2 * k] = wr * target[k].real();
    b[2 * k + 1] = wi * target[k].imag();
  }
  return nnls(a, b);
}

// The differential mode's series impedance per metre, Z' = R_dc + sum R_i || L_i + j w l: the
// internal impedance (into model.r_dc and model.skin) and l.
double fit_series(const ModeData& d, CableModel* model) {
  const std::vector<double> fc = corners(d.f);
  std::vector<std::vector<cd>> basis;
  std::vector<cd> target;
  for (size_t k = 0; k < d.f.size(); ++k) {
    std::vector<cd> row = {1.0, cd(0, 2 * kPi * d.f[k])};
    for (double c : fc) {
      const cd s(0, d.f[k] / c);
      row.push_back(s / (1.0 + s));
    }
    basis.push_back(row);
    target.push_back(d.gamma[k] * d.zc[k]);
  }
  const Eigen::VectorXd x = nonnegative_fit(basis, target);
  model->r_dc = x[0];
  model->skin.clear();
  for (size_t i = 0; i < fc.size(); ++i)
    if (x[2 + i] > 0) model->skin.push_back({x[2 + i], x[2 + i] / (2 * kPi * fc[i])});
  return x[1];
}

// A single positive coefficient a of target ~ a basis, weighted least squares.
double fit_scalar(const std::vector<cd>& basis, const std::vector<cd>& target,
                  const std::vector<double>& weight) {
  double num = 0, den = 0;
  for (size_t k = 0; k < target.size(); ++k) {
    const double w2 = weight[k] * weight[k];
    num += w2 * (std::conj(basis[k]) * target[k]).real();
    den += w2 * std::norm(basis[k]);
  }
  return den > 0 ? num / den : 0.0;
}

// The differential mode's capacitance per metre beyond c_g: Y' / (j w) = c_g + 2 (c_pn +
// sum c_b / (1 + j w tau_b)) (into model.c_pn and model.dielectric, c_g already set).
void fit_shunt(const ModeData& d, CableModel* model) {
  const std::vector<double> fc = corners(d.f);
  std::vector<std::vector<cd>> basis;
  std::vector<cd> target;
  for (size_t k = 0; k < d.f.size(); ++k) {
    std::vector<cd> row = {1.0};
    for (double c : fc) row.push_back(1.0 / cd(1.0, d.f[k] / c));
    basis.push_back(row);
    const cd y = d.gamma[k] / d.zc[k];
    target.push_back((y / cd(0, 2 * kPi * d.f[k]) - model->c_g) / 2.0);
  }
  const Eigen::VectorXd x = nonnegative_fit(basis, target);
  model->c_pn = x[0];
  model->c_inf = 1;
  model->dielectric.clear();
  const double c_diff = model->c_pn + model->c_g / 2;
  for (size_t i = 0; i < fc.size(); ++i)
    if (x[1 + i] > 0) model->dielectric.push_back({x[1 + i] / c_diff, 1 / (2 * kPi * fc[i])});
}

// A mode's 2-port admittance as a line of propagation gamma and impedance zc (1 m), stable for
// any attenuation: coth g = (1 + e^-2g) / (1 - e^-2g), 1 / sinh g = 2 e^-g / (1 - e^-2g).
Eigen::Matrix2cd mode_admittance(cd gamma, cd zc) {
  const cd e1 = std::exp(-gamma), e2 = e1 * e1;
  const cd self = (1.0 + e2) / ((1.0 - e2) * zc), through = -2.0 * e1 / ((1.0 - e2) * zc);
  Eigen::Matrix2cd y;
  y << self, through, through, self;
  return y;
}

}  // namespace

std::optional<MeasuredLine> fit_uniform_line(const std::vector<double>& freqs,
                                             const std::vector<Eigen::MatrixXcd>& y,
                                             bool differential) {
  // Each mode's 2-port (tx, rx) admittances, in the mode's own terms.
  const int modes = differential ? 1 : 2;
  std::vector<std::vector<Eigen::Vector3cd>> per_mode(modes);
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(4, 4);
  t.topLeftCorner(2, 2) = t.bottomRightCorner(2, 2) = end_modes();
  for (const Eigen::MatrixXcd& yk : y) {
    if (differential) {
      // The pair's port: v = v_P - v_N = sqrt 2 v_d, i = sqrt 2 i_d: the mode's Y is 2 Y_port.
      per_mode[0].push_back(
          Eigen::Vector3cd(2.0 * yk(0, 0), 2.0 * yk(1, 1), (yk(0, 1) + yk(1, 0))));
      continue;
    }
    const Eigen::MatrixXcd ym = t * yk * t.transpose();
    for (int m = 0; m < 2; ++m)
      per_mode[m].push_back(
          Eigen::Vector3cd(ym(m, m), ym(2 + m, 2 + m), (ym(m, 2 + m) + ym(2 + m, m)) / 2.0));
  }
  const std::optional<ModeData> d = read_mode(freqs, per_mode[0]);
  if (!d) return std::nullopt;
  MeasuredLine line;
  line.differential = differential;
  CableModel& m = line.model;
  m.length = 1;
  m.material = "measured";
  const double l_d = fit_series(*d, &m);
  double l_c = l_d;
  if (!differential) {
    const std::optional<ModeData> c = read_mode(freqs, per_mode[1]);
    if (!c) return std::nullopt;
    // Common mode: the same internal impedance, its own inductance and capacitance.
    std::vector<cd> jw, rest, shunt;
    std::vector<double> w_series, w_shunt;
    for (size_t k = 0; k < c->f.size(); ++k) {
      const cd z = c->gamma[k] * c->zc[k], yc = c->gamma[k] / c->zc[k];
      jw.push_back(cd(0, 2 * kPi * c->f[k]));
      rest.push_back(z - m.internal_impedance(c->f[k]));
      shunt.push_back(yc);
      w_series.push_back(1 / std::abs(z));
      w_shunt.push_back(1 / std::abs(yc));
    }
    l_c = fit_scalar(jw, rest, w_series);
    m.c_g = fit_scalar(jw, shunt, w_shunt);
    if (!(m.c_g > 0)) return std::nullopt;
  }
  if (!(l_d > 0) || !(l_c > 0)) return std::nullopt;
  m.l_self = (l_d + l_c) / 2;
  m.k_pn = (l_c - l_d) / (l_c + l_d);
  m.l_diff = 2 * l_d;
  m.l_cm = l_c / 2;
  fit_shunt(*d, &m);
  if (!(m.c_pn > 0)) return std::nullopt;
  m.skin_effect = !m.skin.empty();
  m.dielectric_loss = !m.dielectric.empty();
  // Loss-free high-frequency figures.
  const double c_d = m.c_g + 2 * m.c_pn;
  line.delay_diff = std::sqrt(l_d * c_d);
  line.z_diff = 2 * std::sqrt(l_d / c_d);
  if (!differential) {
    line.delay_cm = std::sqrt(l_c * m.c_g);
    line.z_cm = std::sqrt(l_c / m.c_g) / 2;
  }
  return line;
}

Eigen::MatrixXcd uniform_line_y(const MeasuredLine& line, double f) {
  f = std::max(f, 1e-3);
  const CableModel& m = line.model;
  const cd jw(0, 2 * kPi * f);
  const cd zi = m.internal_impedance(f);
  // Differential mode (per metre, its own terms): Z' = Z_int + j w l_d, Y' = 2 j w c_diff c(f).
  auto admittance = [](cd z, cd y) {
    const cd gamma = std::sqrt(z * y);
    return mode_admittance(gamma.real() < 0 ? -gamma : gamma, std::sqrt(z / y));
  };
  const Eigen::Matrix2cd yd =
      admittance(zi + jw * (m.l_diff / 2), 2.0 * m.shunt_admittance_diff(f));
  if (line.differential) return yd / 2.0;  // the pair's port (fit_uniform_line)
  const Eigen::Matrix2cd yc = admittance(zi + jw * (2 * m.l_cm), jw * m.c_g);
  Eigen::MatrixXcd ym = Eigen::MatrixXcd::Zero(4, 4);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      ym(2 * a, 2 * b) = yd(a, b);
      ym(2 * a + 1, 2 * b + 1) = yc(a, b);
    }
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(4, 4);
  t.topLeftCorner(2, 2) = t.bottomRightCorner(2, 2) = end_modes();
  return t.transpose().cast<cd>() * ym * t.cast<cd>();
}

}  // namespace isolink::link
