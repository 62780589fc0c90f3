// A long measured cable as a uniform coupled line: its per-metre series impedance and shunt
// admittance, read off the file's propagation and characteristic impedance per mode, fitted with
// the native cable's ladders (netlists/link/cable.h), and built as the native cable is, in
// segments of at most a tenth of the edge time. The line's delay is then carried by the ladder,
// as the native cable's is, where a rational fit of e^{-s tau} would need hundreds of poles.
//
//   std::optional<MeasuredLine> line = fit_uniform_line(freqs, y, false);   // y: Y per frequency
//   if (line && line_rms_error(*line, freqs, s, z0) <= tolerance) ...        // use it
//   add_cable_ladder(cards, prefix, ap, an, bp, bn, line->model, n, stride);
//
// Method (docs/touchstone.md, "Long lines"):
// - Modes: a 4-port's ends as (P - N) / sqrt 2 (differential) and (P + N) / sqrt 2 (common), a
//   2-port's pair alone. For a uniform line each mode's 2-port admittance gives
//   cosh(gamma) = -(y11 + y22) / (2 y12) and Zc = 1 / sqrt(y11 y22 - y12^2); gamma's phase is
//   unwrapped over frequency (each point's branch the one nearest the previous phase delay), so
//   the file must sample the line at least a few points per period of its delay.
// - Per metre (the line is taken as 1 m long): Z' = gamma Zc and Y' = gamma / Zc. The
//   differential mode's Z' = R_dc + skin sections (R_i || L_i) + j w (l_self - M), the common
//   mode's the same internal impedance + j w (l_self + M); Y' = j w (c_g + 2 c_pn c(f)) and
//   j w c_g, c(f) the dielectric ladder. Every term is a non-negative least-squares fit with
//   corners log-spaced over the file's band, so the ladder is passive by construction.
// - A line is used only where its exact admittance (the ladders as functions of frequency, not
//   yet lumped) is within the cable's tolerance of the file (line_rms_error): a harness whose
//   connectors or splices reflect is not a uniform line, and is fitted rationally instead.
#pragma once

#include <Eigen/Dense>
#include <optional>
#include <vector>

#include "netlists/link/cable.h"

namespace isolink::link {

struct MeasuredLine {
  CableModel model;           // 1 m long: its figures are the whole line's
  bool differential = false;  // a 2-port: the pair alone, no common mode (c_g = 0, k_pn = 0)
  // Loss-free high-frequency figures, for reports.
  double delay_diff = 0;  // s
  double z_diff = 0;      // ohm, P to N
  double delay_cm = 0;    // s (a 4-port)
  double z_cm = 0;        // ohm, both lines against the chassis (a 4-port)
};

// The uniform line that best fits y (the link's port order: tx P, tx N, rx P, rx N, or tx, rx of
// a 2-port) over freqs (points at 0 Hz are skipped; the band is read up to where a mode is
// attenuated by 40 dB), or nothing where a mode is not finite, has under 10 points, or a fitted
// term is not physical (an inductance or capacitance that is not positive).
std::optional<MeasuredLine> fit_uniform_line(const std::vector<double>& freqs,
                                             const std::vector<Eigen::MatrixXcd>& y,
                                             bool differential);

// The line's exact admittance at f (Hz; below 1 mHz taken at 1 mHz), the link's port order.
Eigen::MatrixXcd uniform_line_y(const MeasuredLine& line, double f);

}  // namespace isolink::link
