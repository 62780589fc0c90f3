#include "reports/touchstone_png.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "reports/plot.h"

namespace isolink::reports {
namespace {

constexpr int kW = 1800, kH = 1500, kFont = 20, kLeft = 150, kRight = 60;
constexpr Color kFileColor = rgb(0x9ECAE9);  // the measurement: wide and light
constexpr Color kFitColor = rgb(0x1F3A5F);   // the fit: narrow and dark over it
constexpr Color kReflFile = rgb(0xFDD0A2);
constexpr Color kReflFit = rgb(0xA63603);

using Cx = std::complex<double>;

// The file's S in the link's port order (tx P, tx N, rx P, rx N; a 2-port as it is).
Eigen::MatrixXcd file_s(const link::TouchstoneCable& c, size_t k) {
  if (c.differential || c.ports.size() != 4) return c.data.s[k];
  Eigen::MatrixXcd s(4, 4);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) s(i, j) = c.data.s[k](c.ports[i] - 1, c.ports[j] - 1);
  return s;
}

// (Sdd21, Sdd11) of a matrix in the link's order.
std::pair<Cx, Cx> differential(const Eigen::MatrixXcd& s) {
  if (s.rows() == 2) return {s(1, 0), s(0, 0)};
  Eigen::MatrixXcd m = Eigen::MatrixXcd::Zero(2, 4);
  m(0, 0) = m(1, 2) = 1 / std::numbers::sqrt2;
  m(0, 1) = m(1, 3) = -1 / std::numbers::sqrt2;
  const Eigen::MatrixXcd sdd = m * s * m.transpose();
  return {sdd(1, 0), sdd(0, 0)};
}

double db(Cx x) {
  return 20 * std::log10(std::max(std::abs(x), 1e-12));
}

// Phase in degrees, unwrapped along the frequencies.
std::vector<double> unwrapped_deg(const std::vector<Cx>& v) {
  std::vector<double> out;
  double prev = 0, offset = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const double a = std::arg(v[i]);
    if (i > 0) {
      const double d = a - prev;
      if (d > std::numbers::pi) offset -= 2 * std::numbers::pi;
      if (d < -std::numbers::pi) offset += 2 * std::numbers::pi;
    }
    prev = a;
    out.push_back((a + offset) * 180 / std::numbers::pi);
  }
  return out;
}

struct Panel {
  PlotArea area;
  AxisTicks xt, yt;
};

Panel panel(Canvas& c, Rect r, const std::vector<double>& logf, double ylo, double yhi, bool ylog,
            const std::string& title, const std::string& y_title) {
  Panel p;
  const double pad = 0.05 * std::max(yhi - ylo, 1e-9);
  p.area = PlotArea::make(r, logf.front(), logf.back(), ylo - pad, yhi + pad);
  p.xt = decade_ticks(logf.front(), logf.back(), "Hz", si_label);
  p.yt = ylog ? decade_ticks(ylo - pad, yhi + pad, "", si_label)
              : make_ticks(p.area.y, UnitScale{1, y_title == "phase" ? "deg" : "dB"}, 7);
  draw_grid(c, p.area, p.xt, p.yt);
  draw_axes(c, p.area, p.xt, p.yt, "frequency", y_title, kFont - 2);
  c.text(r.x0, r.y0 - 12, title, kFont, kInk, FontFace::kBold);
  return p;
}

std::pair<double, double> range(std::initializer_list<const std::vector<double>*> vs) {
  double lo = 1e300, hi = -1e300;
  for (const auto* v : vs)
    for (double x : *v)
      if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  return {lo, hi};
}

}  // namespace

TouchstoneCurves touchstone_curves(const link::TouchstoneCable& c) {
  TouchstoneCurves k;
  k.freqs = c.data.freqs;
  double sum2 = 0, n = 0;
  for (size_t i = 0; i < k.freqs.size(); ++i) {
    const Eigen::MatrixXcd s = file_s(c, i);
    const Eigen::MatrixXcd fit = s_from_y(c.y(k.freqs[i]), c.data.z0);
    const auto [t_file, r_file] = differential(s);
    const auto [t_fit, r_fit] = differential(fit);
    k.sdd21_file.push_back(t_file), k.sdd11_file.push_back(r_file);
    k.sdd21_fit.push_back(t_fit), k.sdd11_fit.push_back(r_fit);
    k.entry_error.push_back((fit - s).cwiseAbs().maxCoeff());
    sum2 += (fit - s).cwiseAbs2().sum();
    n += static_cast<double>(s.size());
    if (k.entry_error.back() > k.max_error)
      k.max_error = k.entry_error.back(), k.max_error_hz = k.freqs[i];
  }
  k.rms_error = n > 0 ? std::sqrt(sum2 / n) : 0;
  return k;
}

Status write_touchstone_png(const link::TouchstoneCable& c, const std::string& path) {
  const TouchstoneCurves k = touchstone_curves(c);
  if (k.freqs.size() < 2 || k.freqs.front() <= 0)
    return Status::Error(path + ": error: the plot needs two frequencies above 0 Hz");
  StatusOr<Canvas> cv = Canvas::create(kW, kH);
  if (!cv) return cv.status();
  Canvas& cn = *cv;
  std::vector<double> logf, t_file, t_fit, r_file, r_fit, err;
  for (size_t i = 0; i < k.freqs.size(); ++i) {
    logf.push_back(std::log10(k.freqs[i]));
    t_file.push_back(db(k.sdd21_file[i])), t_fit.push_back(db(k.sdd21_fit[i]));
    r_file.push_back(db(k.sdd11_file[i])), r_fit.push_back(db(k.sdd11_fit[i]));
    err.push_back(std::log10(std::max(k.entry_error[i], 1e-12)));
  }
  const FitResult& f = c.fit;
  cn.text(40, 24, "isolink touchstone: " + c.data.source, 26, kInk, FontFace::kBold, HAlign::kLeft,
          VAlign::kTop);
  cn.text(
      40, 66,
      fmt::format("{}-port {}, {} points {} .. {}Hz, reference {:g} ohm; fit: {}, RMS "
                  "|S_fit - S| {:.3g}, largest {:.3g} at {}Hz{}",
                  c.data.ports, c.differential ? "(differential)" : "(single-ended)",
                  k.freqs.size(), si_label(k.freqs.front()), si_label(k.freqs.back()), c.data.z0,
                  c.line ? fmt::format("a uniform line, {:.4g} ns, {:.4g} ohm differential",
                                       c.line->delay_diff * 1e9, c.line->z_diff)
                         : fmt::format("{} poles", f.model.poles.size()),
                  f.rms_error, f.error, si_label(f.error_frequency),
                  c.dc_extrapolated ? "; DC extrapolated below the first point" : ""),
      kFont - 2, kInk, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
  cn.text(40, 94,
          c.line ? std::string("passive by construction (every R, L and C of the line's ladder "
                               "is >= 0): the model simulated is the fit")
          : c.passivity.passive
              ? std::string("passive as fitted: the model simulated is the fit")
              : fmt::format("passivity enforced ({} perturbations): the model simulated has RMS "
                            "|S_fit - S| {:.3g}, largest {:.3g} at {}Hz (drawn below)",
                            c.passivity.perturbation_iterations, k.rms_error, k.max_error,
                            si_label(k.max_error_hz)),
          kFont - 2, c.passivity.passive ? kInk : kMuted, FontFace::kSans, HAlign::kLeft,
          VAlign::kTop);
  const std::string t_name = c.differential ? "S21" : "Sdd21",
                    r_name = c.differential ? "S11" : "Sdd11";
  const auto [mlo, mhi] = range({&t_file, &t_fit, &r_file, &r_fit});
  Panel p1 = panel(cn, {kLeft, 175, kW - kRight, 620}, logf, std::max(mlo, -80.0), mhi, false,
                   fmt::format("magnitude: {} (transmission), {} (reflection)", t_name, r_name),
                   "magnitude");
  const std::vector<double> ph_file = unwrapped_deg(k.sdd21_file),
                            ph_fit = unwrapped_deg(k.sdd21_fit);
  const auto [plo, phi] = range({&ph_file, &ph_fit});
  Panel p2 = panel(cn, {kLeft, 720, kW - kRight, 1040}, logf, plo, phi, false,
                   fmt::format("{} phase, unwrapped", t_name), "phase");
  auto [elo, ehi] = range({&err});
  elo = std::min(elo, std::log10(std::max(k.rms_error, 1e-12)));
  Panel p3 = panel(cn, {kLeft, 1140, kW - kRight, 1420}, logf, std::floor(elo), std::ceil(ehi),
                   true, "largest |S_fit - S| over the entries", "error");
  auto pair = [&](const Panel& p, const std::vector<double>& file, const std::vector<double>& fit,
                  Color cf, Color cl) {
    cn.series(p.area, logf, file, LineStyle{.color = cf, .width = 7});
    cn.series(p.area, logf, fit, LineStyle{.color = cl, .width = 2});
  };
  pair(p1, t_file, t_fit, kFileColor, kFitColor);
  pair(p1, r_file, r_fit, kReflFile, kReflFit);
  pair(p2, ph_file, ph_fit, kFileColor, kFitColor);
  cn.series(p3.area, logf, err, LineStyle{.color = kFitColor, .width = 2});
  const double rms = std::log10(std::max(k.rms_error, 1e-12));
  cn.hline(p3.area.py(rms), p3.area.rect.x0, p3.area.rect.x1,
           LineStyle{.color = kMuted, .width = 2, .dash = 10, .gap = 6});
  draw_label(cn, p3.area.rect.x1 - 8, p3.area.py(rms) - 4,
             fmt::format("RMS over the band {:.3g}", k.rms_error), kFont - 4, kMuted,
             HAlign::kRight, VAlign::kBottom);
  const std::vector<LegendEntry> legend = {
      {t_name + " file", LineStyle{.color = kFileColor, .width = 7}},
      {t_name + " fit", LineStyle{.color = kFitColor, .width = 2}},
      {r_name + " file", LineStyle{.color = kReflFile, .width = 7}},
      {r_name + " fit", LineStyle{.color = kReflFit, .width = 2}}};
  const Rect ls = legend_size(cn, legend, kFont - 4);
  draw_legend(cn, p1.area.rect.x1 - ls.width() - 12, p1.area.rect.y1 - ls.height() - 12, legend,
              kFont - 4);
  return cn.write_png(path);
}

}  // namespace isolink::reports
