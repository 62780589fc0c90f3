#include "netlists/link/touchstone_cable.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <mutex>
#include <numbers>
#include <optional>

#include "base/file_io.h"
#include "netlists/link/cable.h"
#include "netlists/link/cards.h"

namespace isolink::link {

namespace {

using cd = std::complex<double>;

Card card(char letter, std::string name, std::vector<std::string> nodes, double value) {
  return make_card(letter, std::move(name), std::move(nodes), {number_arg(value)});
}

// a + b f^2 fitted (least squares) to v at freqs (the lowest points): a quantity even in f, at
// DC.
double even_extrapolation(const std::vector<double>& freqs, const std::vector<double>& v) {
  const int k = static_cast<int>(v.size());
  if (k < 2) return v[0];
  Eigen::MatrixXd m(k, 2);
  Eigen::VectorXd b(k);
  for (int q = 0; q < k; ++q) {
    const double f = freqs[q] / freqs[0];
    m(q, 0) = 1, m(q, 1) = f * f, b[q] = v[q];
  }
  return m.colPivHouseholderQr().solve(b)[0];
}

// One entry of the series impedance below the band: Z(f) = a + b F(f / f_s) + j w l, F the
// round wire's skin factor (cable.h; 1 at DC), so R_dc = a + b. An off-diagonal entry (the
// lines' mutual impedance) is a + j w l.
struct SeriesEntry {
  double a = 0, b = 0, l = 0, f_s = 1;
  cd at(double f) const {
    const cd skin = b == 0 ? cd(1.0) : round_wire_skin_factor(f / f_s);
    return a + b * skin + cd(0, 2 * std::numbers::pi * f * l);
  }
  double r_dc() const { return a + b; }
};

// Least squares of z (at freqs) in the form above for a given f_s (0: no skin term), each
// point's real and imaginary parts weighted by their own size (the resistance is a hundredth of
// the reactance at a few MHz). Returns the weighted residual.
double fit_series_entry(const std::vector<double>& freqs, const std::vector<cd>& z, double f_s,
                        SeriesEntry* out) {
  const int k = static_cast<int>(z.size()), unknowns = f_s > 0 ? 3 : 2;
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(2 * k, unknowns);
  Eigen::VectorXd rhs(2 * k);
  for (int q = 0; q < k; ++q) {
    const double near = freqs[0] / freqs[q];
    const double wr = near / std::max(std::abs(z[q].real()), 1e-12 * std::abs(z[q]));
    const double wi = near / std::max(std::abs(z[q].imag()), 1e-12 * std::abs(z[q]));
    const double w = 2 * std::numbers::pi * freqs[q];
    m(2 * q, 0) = wr, m(2 * q + 1, 1) = wi * w;
    rhs[2 * q] = wr * z[q].real(), rhs[2 * q + 1] = wi * z[q].imag();
    if (f_s > 0) {
      const cd skin = round_wire_skin_factor(freqs[q] / f_s);
      m(2 * q, 2) = wr * skin.real(), m(2 * q + 1, 2) = wi * skin.imag();
    }
  }
  const Eigen::VectorXd x = m.colPivHouseholderQr().solve(rhs);
  *out = {x[0], f_s > 0 ? x[2] : 0.0, x[1], f_s > 0 ? f_s : 1.0};
  const double residual = (m * x - rhs).norm();
  return std::isfinite(residual) ? residual : INFINITY;
}

// The diagonal entry's form: the skin term's f_s searched on a log grid (100 Hz to 1 GHz, 16 a
// decade) for the least residual, beside the form without it; the skin term needs two points.
SeriesEntry fit_series_diagonal(const std::vector<double>& freqs, const std::vector<cd>& z) {
  SeriesEntry best;
  double best_residual = fit_series_entry(freqs, z, 0, &best);
  if (z.size() < 2) return best;
  for (double f_s : log_space(1e2, 1e9, 113)) {
    SeriesEntry e;
    const double r = fit_series_entry(freqs, z, f_s, &e);
    if (r < best_residual && e.b >= 0) best = e, best_residual = r;
  }
  return best;
}

// One point's pi section (2 x 2 single-ended, 1 x 1 differential): the series impedance
// -(Y_tx,rx)^-1 and each end's shunt Y_end + Y_tx,rx, corrected to second order for a line's
// distribution (below).
struct PiSection {
  Eigen::MatrixXcd z, ya, yb;
};

PiSection pi_section(const Eigen::MatrixXcd& y) {
  const int h = static_cast<int>(y.rows()) / 2;
  const Eigen::MatrixXcd z_pi = (-y.block(0, h, h, h)).inverse();
  const Eigen::MatrixXcd a = y.block(0, 0, h, h) + y.block(0, h, h, h);
  const Eigen::MatrixXcd b = y.block(h, h, h, h) + y.block(h, 0, h, h);
  const Eigen::MatrixXcd z = z_pi - z_pi * (a + b) * z_pi / 6.0;
  return {z, a + a * z * a / 6.0, b + b * z * b / 6.0};
}

// The pi sections of the lowest points (up to 5) over which the cable is electrically short:
// |(gamma l)^2| = |Z Y_shunt| at most 0.15, where the section corrected to second order is within
// a few tenths of a percent of a line's. At least the first point.
std::vector<PiSection> short_line_sections(const std::vector<Eigen::MatrixXcd>& y) {
  std::vector<PiSection> out;
  while (out.size() < 5 && out.size() < y.size()) {
    PiSection p = pi_section(y[out.size()]);
    if (!out.empty() && !((p.z * (p.ya + p.yb)).cwiseAbs().maxCoeff() <= 0.15)) break;
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

// Below the band (contract: touchstone_cable.h). At the lowest points over which the cable is
// electrically short (short_line_sections): the series impedance Z = -(Y_tx,rx)^-1 (2 x 2
// single-ended, 1 x 1 differential) and each end's shunt admittance Y_a = Y_end + Y_tx,rx,
// corrected to second order for a line's distribution (Z_pi = Z + Z Y Z / 6, Y_a = Y / 2 - Y Z Y /
// 24 for a uniform line of series Z and shunt Y: Z = Z_pi - Z_pi Y Z_pi / 6, Y / 2 = Y_a + Y_a Z
// Y_a / 6). The series impedance's diagonal is fitted as a round wire's skin effect plus an
// external inductance (fit_series_diagonal: a VNA's sweep from 300 kHz is already in the skin
// effect's transition for 24 AWG, where a + b f^2 from the first point alone put R_dc 35 % high and
// L 1 % low), its off-diagonal as a + j w l; each end's shunt as j w C (loss-free), C extrapolated
// as a + b f^2. Each point weighs as the first frequency over its own: the extrapolation is for
// below the first (from 10 kHz, equal weights left a 2 m link 0.46 mV off the native cable, these
// 0.01 mV). At DC: R alone, no conductance to the chassis or between the lines. Points at DC and
// from 1e-3 of the first frequency up to it, 4 a decade, join the data (with 3 of them, 0.1 of the
// first frequency the highest, the fit was free in between: 0.85 mV on the same link).
// Extrapolating S instead is ill-conditioned here: through an ohm against 50 ohm, a 1e-4 error of
// S(0) is a 100 ohm path between P and N.
Status extend_below_band(std::vector<double>& freqs, std::vector<Eigen::MatrixXcd>& y,
                         Eigen::MatrixXd* r_dc) {
  const int n = static_cast<int>(y[0].rows()), h = n / 2;
  const std::vector<PiSection> sections = short_line_sections(y);
  const int k = static_cast<int>(sections.size());
  const std::vector<double> low(freqs.begin(), freqs.begin() + k);
  std::vector<std::vector<SeriesEntry>> series(h, std::vector<SeriesEntry>(h));
  Eigen::MatrixXd r(h, h), c1(h, h), c2(h, h);
  for (int i = 0; i < h; ++i)
    for (int j = 0; j < h; ++j) {
      std::vector<cd> zij;
      std::vector<double> va, vb;
      for (int q = 0; q < k; ++q) {
        const double w = 2 * std::numbers::pi * low[q];
        zij.push_back(sections[q].z(i, j));
        va.push_back(sections[q].ya(i, j).imag() / w);
        vb.push_back(sections[q].yb(i, j).imag() / w);
      }
      if (i == j)
        series[i][j] = fit_series_diagonal(low, zij);
      else
        fit_series_entry(low, zij, 0, &series[i][j]);
      r(i, j) = series[i][j].r_dc();
      c1(i, j) = even_extrapolation(low, va), c2(i, j) = even_extrapolation(low, vb);
    }
  r = (r + r.transpose()) / 2;
  *r_dc = r;
  if (!r.allFinite() || !(r.diagonal().minCoeff() > 0)) return Status::Error("");
  std::vector<double> fs = {0.0};
  for (double x = 1e-3; x < 0.9; x *= std::pow(10.0, 0.25)) fs.push_back(x * freqs[0]);
  std::vector<Eigen::MatrixXcd> ys;
  for (double f : fs) {
    const double w = 2 * std::numbers::pi * f;
    Eigen::MatrixXcd z(h, h);
    for (int i = 0; i < h; ++i)
      for (int j = 0; j < h; ++j) z(i, j) = f == 0 ? cd(r(i, j)) : series[i][j].at(f);
    z = (z + z.transpose()) / 2.0;
    const Eigen::MatrixXcd zi = z.inverse();
    Eigen::MatrixXcd m(n, n);
    m << zi + cd(0, w) * c1, -zi, -zi, zi + cd(0, w) * c2;
    ys.push_back((m + m.transpose()) / 2.0);
  }
  freqs.insert(freqs.begin(), fs.begin(), fs.end());
  y.insert(y.begin(), ys.begin(), ys.end());
  return Status::Ok();
}

namespace {

// The cable's ports (tx P, tx N, rx P, rx N; a 2-port: tx, rx) combined end with end,
// (tx + rx) / sqrt 2 and (tx - rx) / sqrt 2 for each line: the first see the shunt alone (j w C,
// no conductance at DC), the second the series path too (1/R at DC). Fitted in these (solver/
// vector_fit.h, Weighting), the shunt keeps its own accuracy beside a series admittance 1e5 times
// larger.
Eigen::MatrixXd end_sum_and_difference(int n) {
  const int h = n / 2;
  const double r = 1 / std::sqrt(2.0);
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < h; ++i) {
    t(i, i) = t(i, h + i) = r;
    t(h + i, i) = r, t(h + i, h + i) = -r;
  }
  return t;
}

// The RMS of |S_line - S| over freqs (y: the file's admittances), S at reference z0; fit's error
// fields set to the line's.
double line_rms_error(const MeasuredLine& line, const std::vector<double>& freqs,
                      const std::vector<Eigen::MatrixXcd>& y, double z0, FitResult* fit) {
  const int n = static_cast<int>(y[0].rows());
  fit->entry_error = Eigen::MatrixXd::Zero(n, n);
  fit->error = 0;
  double sum = 0;
  for (size_t k = 0; k < freqs.size(); ++k) {
    const Eigen::MatrixXd e =
        (s_from_y(uniform_line_y(line, freqs[k]), z0) - s_from_y(y[k], z0)).cwiseAbs();
    fit->entry_error = fit->entry_error.cwiseMax(e);
    sum += e.squaredNorm();
    if (e.maxCoeff() > fit->error) fit->error = e.maxCoeff(), fit->error_frequency = freqs[k];
  }
  fit->rms_error = std::sqrt(sum / (double(freqs.size()) * n * n));
  if (!std::isfinite(fit->rms_error)) fit->rms_error = INFINITY;
  return fit->rms_error;
}

std::vector<Eigen::MatrixXcd> scattering(const std::vector<Eigen::MatrixXcd>& y, double z0) {
  std::vector<Eigen::MatrixXcd> s;
  for (const Eigen::MatrixXcd& yk : y) s.push_back(s_from_y(yk, z0));
  return s;
}

// The RMS of |S_model - S| over the fitted points (s_data: the data's S at reference z0): the
// model as it is simulated, after the passivity enforcement.
// The largest entry error goes to *largest when given.
double enforced_rms_error(const RationalModel& m, const std::vector<double>& freqs,
                          const std::vector<Eigen::MatrixXcd>& s_data, double z0,
                          double* largest = nullptr) {
  double sum = 0, top = 0;
  for (size_t k = 0; k < freqs.size(); ++k) {
    const Eigen::MatrixXcd e =
        s_from_y(m.eval(cd(0, 2 * std::numbers::pi * freqs[k])), z0) - s_data[k];
    sum += e.squaredNorm();
    top = std::max(top, e.cwiseAbs().maxCoeff());
  }
  const double r = std::sqrt(sum / (double(freqs.size()) * m.ports * m.ports));
  if (largest != nullptr) *largest = std::isfinite(top) ? top : INFINITY;
  return std::isfinite(r) ? r : INFINITY;
}

// The passivity enforcement must not undo the fit. The order that fitted best can bend Re Y
// negative just past the band where the residue perturbation cannot lift it (cap_2m's own S
// from 10 kHz: -2.3 mS at 561 MHz with 48 poles), or lifts it only by moving the model far from
// the data elsewhere (cap_2m, 43 poles: a 6 uS violation at 562 MHz, and the model after it
// 6.5e-4 off S at 10 kHz, 7 mV on the link). Another order within the tolerance bends
// differently: when the enforced model is more than kEnforcedErrorRatio times the fit's error
// off the data, in RMS or in its largest entry error (or needed a shunt), the best order's
// neighbours (then the other orders tried
// that met the tolerance) are fitted and enforced, and the one closest to the data after
// enforcement is kept, `out`'s own among them. Leaves `out` as it was when none does better.
constexpr double kEnforcedErrorRatio = 10;
constexpr double kEnforcedLargestRatio = 5;
// s_data: the data's S at opt.z0.
void refit_until_passive(const std::vector<double>& freqs, const std::vector<Eigen::MatrixXcd>& y,
                         const std::vector<Eigen::MatrixXcd>& s_data, const FitOptions& opt,
                         TouchstoneCable* out) {
  double own_largest = INFINITY;
  const double own = out->passivity.added_conductance > 1e-9
                         ? INFINITY
                         : enforced_rms_error(out->fit.model, freqs, s_data, opt.z0, &own_largest);
  // The largest error too: a perturbation that moves one band (the python tests' 1 m cable: 1.6e-4
  // at 2 MHz, 6.7 times the fit's largest, 5.1 times its RMS) moves the waveform by millivolts.
  if (own <= kEnforcedErrorRatio * out->fit.rms_error &&
      own_largest <= kEnforcedLargestRatio * out->fit.error)
    return;
  const std::vector<int> orders = out->fit.orders_tried;
  const std::vector<double> errors = out->fit.errors;
  const size_t best =
      static_cast<size_t>(std::min_element(errors.begin(), errors.end()) - errors.begin());
  // The best order's neighbours first (the closest fits), then the other orders tried.
  std::vector<int> candidates;
  for (int d : {2, -2, 4, -4, 6, -6})
    if (orders[best] + d >= opt.min_order) candidates.push_back(orders[best] + d);
  for (size_t k = 0; k < orders.size(); ++k)
    if (k != best && errors[k] <= opt.tolerance) candidates.push_back(orders[k]);
  std::optional<FitResult> kept;
  PassivityReport kept_report;
  int kept_order = 0;
  double kept_error = own, kept_largest = own_largest;
  for (size_t c = 0; c < candidates.size(); ++c) {
    // A neighbour made passive within the ratios of its fit: enough.
    if (kept && c >= 6 && kept_error <= kEnforcedErrorRatio * kept->rms_error &&
        kept_largest <= kEnforcedLargestRatio * kept->error)
      break;
    const int order = candidates[c];
    FitOptions one = opt;
    one.min_order = one.max_order = order;
    StatusOr<FitResult> refit = vector_fit(freqs, y, one);
    if (!refit || !refit->converged) continue;
    PassivityReport report = enforce_passivity(refit->model, freqs, opt.z0);
    if (report.added_conductance > 1e-9) continue;
    double largest = INFINITY;
    const double e = enforced_rms_error(refit->model, freqs, s_data, opt.z0, &largest);
    if (!(e < kept_error)) continue;
    kept = std::move(*refit);
    kept_report = report;
    kept_order = order;
    kept_error = e;
    kept_largest = largest;
  }
  if (kept) {
    kept->orders_tried = orders;
    kept->errors = errors;
    kept->orders_tried.push_back(kept_order);
    kept->errors.push_back(kept->rms_error);
    out->fit = std::move(*kept);
    out->passivity = kept_report;
  }
}

}  // namespace

Eigen::MatrixXcd TouchstoneCable::y(double f) const {
  if (line) return uniform_line_y(*line, f);
  return fit.model.eval(cd(0, 2 * std::numbers::pi * f));
}

StatusOr<std::shared_ptr<const TouchstoneCable>> fit_touchstone_cable(const Touchstone& data,
                                                                      std::vector<int> ports,
                                                                      double tolerance,
                                                                      bool long_line) {
  auto out = std::make_shared<TouchstoneCable>();
  out->data = data;
  const std::string& name = data.source;
  if (data.ports == 2) {
    if (!ports.empty())
      return Status::Error(
          fmt::format("{}: a 2-port (differential) file takes no ports mapping", name));
    out->differential = true;
    ports = {1, 2};
  } else if (data.ports == 4) {
    if (ports.empty()) ports = {1, 2, 3, 4};
    if (ports.size() != 4)
      return Status::Error(
          fmt::format("{}: ports names 4 file ports (tx P, tx N, rx P, rx N)", name));
    for (size_t i = 0; i < 4; ++i) {
      if (ports[i] < 1 || ports[i] > 4)
        return Status::Error(
            fmt::format("{}: port {} is not a port of this 4-port", name, ports[i]));
      for (size_t j = 0; j < i; ++j)
        if (ports[j] == ports[i])
          return Status::Error(fmt::format("{}: port {} is named twice in ports", name, ports[i]));
    }
  } else {
    return Status::Error(fmt::format(
        "{}: a {}-port file; the cable is a 4-port (single-ended) or a 2-port (differential)", name,
        data.ports));
  }
  out->ports = ports;
  const int n = static_cast<int>(ports.size());
  std::vector<Eigen::MatrixXcd> y;
  for (size_t k = 0; k < data.freqs.size(); ++k) {
    Eigen::MatrixXcd s(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) s(i, j) = data.s[k](ports[i] - 1, ports[j] - 1);
    const Eigen::MatrixXcd yk = y_from_s(s, data.z0);
    if (!yk.allFinite())
      return Status::Error(
          fmt::format("{}: at {:g} Hz the S matrix has no admittance (I + S is singular)", name,
                      data.freqs[k]));
    y.push_back(yk);
  }
  std::vector<double> freqs = data.freqs;
  // The fit's cost grows with the points: a file of more than kMaxFitPoints is fitted on every
  // k-th of them (the last kept), and scored on those.
  constexpr size_t kMaxFitPoints = 1000;
  if (freqs.size() > kMaxFitPoints) {
    const size_t step = (freqs.size() + kMaxFitPoints - 1) / kMaxFitPoints;
    std::vector<double> f2;
    std::vector<Eigen::MatrixXcd> y2;
    for (size_t k = 0; k < freqs.size(); k += step) f2.push_back(freqs[k]), y2.push_back(y[k]);
    if (f2.back() != freqs.back()) f2.push_back(freqs.back()), y2.push_back(y.back());
    freqs = std::move(f2);
    y = std::move(y2);
  }
  if (freqs.front() > 0) {
    if (!extend_below_band(freqs, y, &out->dc_resistance).ok())
      return Status::Error(fmt::format(
          "{}: the series resistance extrapolated to DC is not positive (a cable conducts each "
          "line end to end)",
          name));
    out->dc_extrapolated = true;
  }
  // A long line: first as a uniform line, kept when within the tolerance of the file.
  if (long_line)
    if (std::optional<MeasuredLine> line = fit_uniform_line(freqs, y, out->differential);
        line && line->delay_diff * freqs.back() >= kLongLineCycles) {
      FitResult scored;
      out->line_rms_error = line_rms_error(*line, freqs, y, data.z0, &scored);
      if (out->line_rms_error <= tolerance) {
        scored.model.ports = n;
        scored.model.d = Eigen::MatrixXd::Zero(n, n);
        scored.converged = true;
        out->fit = std::move(scored);
        out->line = std::move(line);
        out->dc_conductance = out->y(0).real();
        return std::shared_ptr<const TouchstoneCable>(std::move(out));
      }
    }
  FitOptions opt;
  opt.tolerance = tolerance;
  opt.z0 = data.z0;
  opt.transform = end_sum_and_difference(n);
  StatusOr<FitResult> fit = vector_fit(freqs, y, opt);
  if (!fit) return Status::Error(fmt::format("{}: {}", name, fit.status().message()));
  if (!fit->converged)
    return Status::Error(fmt::format(
        "{}: the rational fit reached {} poles with an RMS S error of {:.3g}, above the tolerance "
        "{:.3g} ({}; give a narrower band or a larger cable.tolerance)",
        name, fit->model.poles.size(), fit->rms_error, tolerance,
        out->line_rms_error > 0
            ? fmt::format("as a uniform line it is {:.3g} RMS off: not uniform enough",
                          out->line_rms_error)
            : "a long line over a wide band needs more poles than isolink fits"));
  out->fit = std::move(*fit);
  out->passivity = enforce_passivity(out->fit.model, freqs, opt.z0);
  const std::vector<Eigen::MatrixXcd> s_data = scattering(y, opt.z0);
  refit_until_passive(freqs, y, s_data, opt, out.get());
  // The last resort's shunt conductance changes the link (a 1 uS shunt is 1 Mohm at each port,
  // against the cable's 10 Mohm bleed): refused beyond a nanosiemens.
  if (out->passivity.added_conductance > 1e-9)
    return Status::Error(fmt::format(
        "{}: the fit is not passive (Re Y has an eigenvalue of {:.3g} S at {:.4g} Hz) and the "
        "residue perturbation did not make it so; a measurement's noise is the usual cause "
        "(a larger cable.tolerance lets a lower order smooth it)",
        name, out->passivity.min_eigenvalue, out->passivity.at_frequency));
  // The model as simulated is the enforced one: it must meet the tolerance the fit did.
  if (const double e = enforced_rms_error(out->fit.model, freqs, s_data, opt.z0); e > tolerance)
    return Status::Error(fmt::format(
        "{}: made passive, the fit is {:.3g} RMS off the file, above the tolerance {:.3g} (the "
        "fit itself: {:.3g}); a larger cable.tolerance lets a lower order smooth it",
        name, e, tolerance, out->fit.rms_error));
  out->dc_conductance = out->y(0).real();
  if (!out->fit.model.d.allFinite() || !out->dc_conductance.allFinite())
    return Status::Error(fmt::format("{}: the fit is not finite", name));
  return std::shared_ptr<const TouchstoneCable>(std::move(out));
}

StatusOr<std::shared_ptr<const TouchstoneCable>> touchstone_cable(const CableSpec& spec) {
  StatusOr<std::string> text = read_input_file(spec.touchstone);
  if (!text) return text.status();
  std::string key = fmt::format("{:x}|{}|{:a}|{}|", std::hash<std::string>{}(*text),
                                spec.touchstone, spec.fit_tolerance, spec.uniform_line);
  for (int p : spec.ports) key += fmt::format("{},", p);
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const TouchstoneCable>> kept;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = kept.find(key); it != kept.end()) return it->second;
  }
  StatusOr<Touchstone> data = read_touchstone_text(*text, spec.touchstone);
  if (!data) return data.status();
  auto fit = fit_touchstone_cable(*data, spec.ports, spec.fit_tolerance, spec.uniform_line);
  if (!fit) return fit.status();
  std::lock_guard<std::mutex> lock(mutex);
  if (kept.size() >= 16) kept.clear();
  kept.emplace(key, *fit);
  return *fit;
}

void add_rational_cards(std::vector<Card>& cards, const std::string& prefix, const RationalModel& m,
                        const std::vector<std::pair<std::string, std::string>>& port_nodes) {
  const int n = m.ports;
  auto g = [&](const std::string& name, const std::pair<std::string, std::string>& out,
               const std::pair<std::string, std::string>& in, double gm) {
    if (gm == 0) return;
    cards.push_back(make_card('g', "g" + prefix + "_" + name,
                              {out.first, out.second, in.first, in.second}, {number_arg(gm)}));
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      g(fmt::format("d{}{}", i + 1, j + 1), port_nodes[i], port_nodes[j], m.d(i, j));
  for (size_t k = 0; k < m.poles.size(); ++k) {
    const cd p = m.poles[k];
    // States scaled by |Re p|: z = |Re p| v / (s - p) peaks at |v| at the pole's own frequency
    // (the reduced model's Krylov vectors then see node voltages and states alike).
    const double w = std::abs(p.real());
    const bool pair = p.imag() > 0;
    for (int j = 0; j < n; ++j) {
      // State nodes of pole k driven by port j: z (real pole) or zr, zi (pair).
      const std::string base = fmt::format("{}_y{}_{}", prefix, k, j + 1);
      const std::vector<std::string> states =
          pair ? std::vector<std::string>{base + "r", base + "i"} : std::vector<std::string>{base};
      for (const std::string& z : states) {
        const std::string tail = z.substr(prefix.size() + 1);
        cards.push_back(card('c', "c" + prefix + "_" + tail, {z, "0"}, 1.0 / w));
        cards.push_back(card('r', "r" + prefix + "_" + tail, {z, "0"}, w / -p.real()));
      }
      const std::string t0 = states[0].substr(prefix.size() + 1);
      g(t0 + "_in", {states[0], "0"}, port_nodes[j], -1.0);
      if (pair) {
        const std::string t1 = states[1].substr(prefix.size() + 1);
        g(t0 + "_x", {states[0], "0"}, {states[1], "0"}, p.imag() / w);
        g(t1 + "_x", {states[1], "0"}, {states[0], "0"}, -p.imag() / w);
      }
      for (int i = 0; i < n; ++i) {
        const cd r = m.residues[k](i, j);
        if (pair) {
          g(fmt::format("{}_o{}", t0, i + 1), port_nodes[i], {states[0], "0"}, 2 * r.real() / w);
          g(fmt::format("{}_o{}", states[1].substr(prefix.size() + 1), i + 1), port_nodes[i],
            {states[1], "0"}, -2 * r.imag() / w);
        } else {
          g(fmt::format("{}_o{}", t0, i + 1), port_nodes[i], {states[0], "0"}, r.real() / w);
        }
      }
    }
  }
}

Status add_touchstone_cable(std::vector<Card>& cards, const std::string& prefix,
                            const std::string& a_p, const std::string& a_n, const std::string& b_p,
                            const std::string& b_n, const CableSpec& spec, double edge_time,
                            int* segments) {
  auto cable = touchstone_cable(spec);
  if (!cable) return cable.status();
  const TouchstoneCable& c = **cable;
  int n = 0;
  if (c.line) {
    const double delay = std::max(c.line->delay_diff, c.line->delay_cm);
    n = static_cast<int>(std::clamp(std::ceil(delay / (edge_time / 10) - 1e-9), 2.0, 200.0));
    add_cable_ladder(cards, prefix, a_p, a_n, b_p, b_n, c.line->model, n, loss_stride(n));
  } else if (c.differential) {
    add_rational_cards(cards, prefix, c.fit.model, {{a_p, a_n}, {b_p, b_n}});
  } else {
    add_rational_cards(cards, prefix, c.fit.model,
                       {{a_p, "0"}, {a_n, "0"}, {b_p, "0"}, {b_n, "0"}});
  }
  if (segments != nullptr) *segments = n;
  return Status::Ok();
}

}  // namespace isolink::link
