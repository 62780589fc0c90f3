// Vector fitting: a rational model with one pole set common to every entry of a symmetric
// N x N frequency response (an N-port's admittance Y), and its passivity check and enforcement.
//
//   std::vector<Eigen::MatrixXcd> y = ...;          // Y(j 2 pi f_i), one N x N matrix per f
//   StatusOr<FitResult> fit = vector_fit(freqs, y, FitOptions{});
//   fit->model.eval(s);                             // D + sum_k R_k / (s - p_k) (+ conjugates)
//   PassivityReport p = enforce_passivity(fit->model, freqs);
//
// Method (docs/touchstone.md has the derivation and the guarantees):
// - Relaxed vector fitting (Gustavsen and Semlyen 1999; the relaxation of Gustavsen 2006) with
//   the fast per-entry QR of Deschrijver et al. 2008: sigma(s) f(s) = p(s) is solved for the
//   entries' numerators and one common sigma (whose zeros are the next poles) by least squares;
//   unstable poles are reflected into the left half plane; a few iterations per order.
// - Starting poles: complex pairs with imaginary parts spaced linearly over the band and real
//   parts 1/100 of them (resonant data), plus real poles log-spaced below the band's first point
//   (the DC extrapolation: a cable's series R-L corner often lies below a VNA's first point).
// - The order rises in steps until the fit error (below) is at most the tolerance, or the
//   largest order is reached, or, once within the tolerance, until two steps in a row each gain
//   less than a fifth of the error (the data's noise floor); the best fit is returned, marked
//   converged when its error is within the tolerance. The fit error is the RMS of |S_fit - S| over
//   the entries and the band (robust to a measurement's noise); the largest |S_fit - S| is reported
//   beside it.
// - Weighting: rows are weighted per frequency by 1 / (1/z0 + max |Y_ij|): the error that
//   matters is in the scattering parameters, and dS ~ dY / (1 + z0 |Y|). With a transform T
//   (FitOptions::transform), the fitted entries are those of T Y T^T, each weighted by
//   1 / (1/z0 + |its own value|): a line's admittance in its tx + rx and tx - rx combinations
//   has a large block (the series path, 1/R at DC) and a small one (the shunt capacitance, j w C),
//   and a weight shared per frequency fits the small one only to the large one's rounding.
// - The error reported is in S (reference z0): max over the band of |S_fit - S| per entry.
// - Passivity of an admittance: the eigenvalues of Re Y(j w) (real symmetric for a reciprocal
//   N-port) non-negative at every w, an eigenvalue above -1e-12 times the largest counting as
//   rounding. Checked on a dense sweep from DC to 10 times the band's top and at infinity (D);
//   enforced by residue perturbation: the smallest change of the residues and D (weighted as the
//   fit's error in the band, lightly above it) that keeps every eigenvalue at every sweep point,
//   linearised, at a small margin or above (inequalities, solved exactly as a least-distance
//   problem), iterated; only when that fails by a shunt conductance at each port, which lifts
//   every eigenvalue at every frequency by the same amount.
#pragma once

#include <Eigen/Dense>
#include <complex>
#include <vector>

#include "base/status.h"

namespace isolink {

// Y(s) = D + sum_k R_k / (s - p_k), summed over the conjugate pole and residue too when Im p_k > 0.
// Poles in rad/s, Re p < 0; residues complex symmetric, D real symmetric.
struct RationalModel {
  int ports = 0;
  std::vector<std::complex<double>> poles;  // real poles (Im = 0) and one of each pair (Im > 0)
  std::vector<Eigen::MatrixXcd> residues;   // one per pole
  Eigen::MatrixXd d;
  // The number of states of a realization: 1 per real pole, 2 per pair, times the ports.
  int order() const;
  Eigen::MatrixXcd eval(std::complex<double> s) const;
};

struct FitOptions {
  double tolerance = 1e-3;  // the RMS of |S_fit - S| over the entries and the band, accepted
  double target = 1e-7;     // the order rises until the RMS error is below this, or stalls
  double z0 = 50;           // ohm, the reference of the S error and of the weighting
  int min_order = 8;        // poles (a pair counts 2)
  int order_step = 8;
  int max_order = 160;
  int iterations = 8;  // pole relocations per order
  // Header, Weighting: an orthogonal N x N matrix T (empty: none). The fit is of T Y T^T, each
  // entry weighted by 1 / (1/z0 + |entry|), and the model returned is of Y.
  Eigen::MatrixXd transform;
};

struct FitResult {
  RationalModel model;
  double error = 0;               // max |S_fit - S| over entries and the band
  double rms_error = 0;           // RMS of |S_fit - S| over entries and the band
  Eigen::MatrixXd entry_error;    // N x N, max |S_fit - S|_ij over the band
  double error_frequency = 0;     // Hz, where the largest error is
  bool converged = false;         // rms_error <= tolerance
  std::vector<int> orders_tried;  // pole counts, in order
  std::vector<double> errors;     // the RMS error of each
};

// freqs strictly increasing, >= 0 (Hz; a DC point is taken); y one N x N matrix per frequency
// (averaged with its transpose: the model is reciprocal). Errors: fewer points than needed for the
// smallest order, non-finite data.
StatusOr<FitResult> vector_fit(const std::vector<double>& freqs,
                               const std::vector<Eigen::MatrixXcd>& y, const FitOptions& opt);

// Scattering from admittance and back, reference z0 at every port: S = (I - z0 Y)(I + z0 Y)^-1.
Eigen::MatrixXcd s_from_y(const Eigen::MatrixXcd& y, double z0);
Eigen::MatrixXcd y_from_s(const Eigen::MatrixXcd& s, double z0);

struct PassivityReport {
  double min_eigenvalue = 0;           // S, the smallest eigenvalue of Re Y over the sweep (before)
  double at_frequency = 0;             // Hz, where it is (infinity: D itself)
  bool passive = true;                 // before enforcement
  int perturbation_iterations = 0;     // residue perturbations enforce_passivity needed
  double added_conductance = 0;        // S added to D's diagonal as the last resort (0: none)
  double enforced_min_eigenvalue = 0;  // S, the smallest eigenvalue after enforcement
  int sweep_points = 0;
};
// The check alone; f_top (Hz) the band's top (the sweep goes to 10 f_top).
PassivityReport check_passivity(const RationalModel& m, double f_top);
// The check, then, while it fails (at most 20 times), the residue perturbation: the smallest
// change of the residues and D (Y's change over DC .. 10 f_top weighted by 1 / (1/z0 + |Y|),
// a hundredth above f_top) that keeps every eigenvalue at or above a small margin. As the last
// resort D += (violation + margin) I. The report is the first check's, with the perturbations and
// any added conductance.
PassivityReport enforce_passivity(RationalModel& m, const std::vector<double>& freqs,
                                  double z0 = 50);

}  // namespace isolink
