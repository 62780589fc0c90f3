// Twisted-pair cable between two boards: two coupled conductors over a reference (chassis),
// with skin effect and dielectric loss, as a chain of lumped segments of ordinary R, L, C and K
// elements that the transient engine and the AC analysis both take.
//
//   CableSpec spec;                 // 1 m, PP, 24 AWG, 25 degC (or explicit r, l, c, g)
//   spec.length = 10;
//   StatusOr<CableModel> m = cable_model(spec);     // per-metre figures and the fitted ladders
//   std::vector<Card> cards;
//   add_cable(cards, "cab", "ap", "an", "bp", "bn", spec, 10e-9);   // 10 ns edges
//   add_cards(circuit, cards);                                       // netlists/link/cards.h
//
// Model (formulas, sources, fit errors and limits: netlists/link/README.md, "Cable"):
//   - Geometry from the gauge: AWG wire diameter, an insulation wall per gauge, centre spacing
//     D = diameter + 2 walls, the pair 20 mm above the chassis (the common-mode reference).
//   - Per conductor: R_dc (copper, 0.00393/K) plus the skin effect's internal impedance (round
//     wire, Bessel functions; times the pair's proximity factor above the skin corner), fitted
//     over 0.1-100 MHz with series R_i || L_i sections; external self inductance l_self and
//     coupling k_pn between the two conductors.
//   - Capacitance line to line c_pn and each line to the reference c_g. Dielectric loss with a
//     constant loss tangent (causal wideband Debye model) on the differential capacitance, fitted
//     with c_pn || (R_i - C_i) branches across the pair; c_g is loss-free (the common mode's
//     field is almost all in air).
//   - Segments are pi-shaped (half the shunt elements at each end); the external inductors of
//     neighbouring segments are coupled with kappa = 1/10, which cancels the lumped ladder's
//     leading dispersion error ((w t)^2 / 24 -> (w t)^4 / 480 in the delay, t = segment delay).
// Per-metre figures are per metre of cable; twist take-up is not added.
#pragma once

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "solver/card.h"

namespace isolink::link {

// The lengths the cable model is valid for (CableSpec::validate refuses others).
inline constexpr double kMinCableLength = 0.01;  // m
inline constexpr double kMaxCableLength = 100;   // m

struct CableSpec {
  double length = 1.0;          // m, > 0
  std::string material = "pp";  // pp | pvc (insulation)
  int gauge = 24;               // AWG, 18..30
  double temperature = 25.0;    // degC, -40..125 (PVC: -40..105); copper R and PVC er, tan delta
  // Explicit per-metre overrides; each replaces the preset's value:
  //   r: DC resistance of one conductor (ohm/m), used as given (no temperature correction);
  //      0 = no resistance. The skin effect still scales from it.
  //   l: differential loop inductance, external (H/m): the high-frequency limit; the wires'
  //      internal inductance comes with the skin model. The common-mode inductance stays.
  //   c: differential capacitance (F/m) at the reference frequency 1 MHz, c_pn + c_g / 2; the
  //      capacitance of each line to the reference (c_g) stays the preset's.
  //   g: differential conductance (S/m) at 1 MHz: sets the effective loss tangent
  //      g / (2 pi 1 MHz c); G then grows with frequency (constant loss tangent). 0 = no loss.
  std::optional<double> r, l, c, g;
  //   chassis_c: each conductor's capacitance to the chassis (F/m), replacing the geometry's c_g
  //      (the pair 20 mm over the chassis: 6.7 pF/m for 24 AWG PP); c stays as given or preset.
  std::optional<double> chassis_c;
  int segments = 0;         // 0: chosen from the edge time (cable_segments)
  int loss_stride = 0;      // segments per loss section; 0: automatic (loss_stride()); else 1..1000
  bool skin_effect = true;  // false: DC resistance only, no internal inductance
  bool dielectric_loss = true;  // false: loss-free dielectric, capacitances constant
  // A measured cable instead of the model above (netlists/link/touchstone_cable.h): a Touchstone
  // file (.s4p single-ended, .s2p differential), the file's ports for tx P, tx N, rx P, rx N
  // (empty: 1 2 3 4) and the fit's tolerance (RMS of |S_fit - S|). `length` then only names the
  // hop's length for the pack's timing; no other key of the model applies.
  std::string touchstone;
  std::vector<int> ports;
  double fit_tolerance = 1e-3;
  bool uniform_line = true;  // a long line tried as a uniform line first (touchstone_cable.h)

  // Names the field, its value and the rule: "cable.length = -1: must be > 0".
  Status validate() const;
};

// Series R_i || L_i section of the skin ladder (per conductor, per metre).
struct SkinSection {
  double r = 0;  // ohm/m
  double l = 0;  // H/m
};

// Series R-C branch of the dielectric ladder, normalised: for a differential capacitance C (at
// 1 MHz) the branch is C_i = C * c, R_i = tau / C_i.
struct DielectricBranch {
  double c = 0;    // fraction of the capacitance at the reference frequency
  double tau = 0;  // s, R_i C_i
};

struct CableModel {
  static constexpr double kReferenceFrequency = 1e6;  // Hz: c, g, er, tan delta are quoted here
  static constexpr double kHeight = 20e-3;            // m, pair above the chassis (assumed)
  static constexpr double kFitLow = 0.1e6;            // Hz, band the ladders are fitted over
  static constexpr double kFitHigh = 100e6;

  double length = 1.0;  // m
  std::string material;
  int gauge = 24;
  double temperature = 25.0;

  // Geometry (m).
  double wire_diameter = 0;
  double wall = 0;     // insulation wall thickness
  double spacing = 0;  // centre to centre, wire_diameter + 2 wall
  double height = kHeight;

  // Materials at the temperature and the reference frequency.
  double er = 1;             // insulation relative permittivity
  double tan_delta = 0;      // insulation loss tangent
  double er_eff = 1;         // differential mode, effective (insulation + air)
  double er_eff_cm = 1;      // common mode to the reference
  double tan_delta_eff = 0;  // differential mode, effective (0 when dielectric_loss is off)

  // Per metre, per conductor.
  double r_dc = 0;       // ohm/m, DC resistance of one conductor at the temperature
  double proximity = 1;  // high-frequency resistance factor of the pair, (D/2a) / sqrt((D/2a)^2-1)
  double l_self = 0;     // H/m, external partial self inductance of one conductor
  double k_pn = 0;       // coupling between the conductors, M = k l_self
  double l_diff = 0;     // H/m, 2 l_self (1 - k): differential loop inductance (mu0/pi acosh(D/2a))
  double l_cm = 0;  // H/m, l_self (1 + k) / 2: both conductors in parallel against the reference
  // Per metre at the reference frequency (F/m).
  double c_pn = 0;  // line to line
  double c_g = 0;   // each line to the reference
  double c_diff() const { return c_pn + c_g / 2; }
  double c_cm() const { return 2 * c_g; }
  double g_diff() const;  // S/m at the reference frequency

  bool skin_effect = true;
  bool dielectric_loss = true;
  // Skin ladder, per conductor and metre (empty when skin_effect is off or r_dc is 0).
  std::vector<SkinSection> skin;
  // Dielectric ladder, normalised to the differential capacitance: c_diff * c_inf between the
  // lines (less c_g / 2, which the lines' capacitances to the reference supply) plus the branches
  // (c_inf = 1 and no branches when the dielectric is loss-free).
  double c_inf = 1;
  std::vector<DielectricBranch> dielectric;
  // Causal constant-loss-tangent target (Djordjevic-Sarkar wideband Debye), normalised to a real
  // part of 1 at the reference frequency:
  //   c(f) = dc_inf + dc_delta ln((f2 + j f) / (f1 + j f)) / ln(f2 / f1).
  double debye_f1 = 1e3, debye_f2 = 10e9;  // Hz
  double dc_inf = 1, dc_delta = 0;

  // Loss-free characteristic figures (external l, c at 1 MHz).
  double z_diff() const;    // ohm, sqrt(l_diff / c_diff)
  double velocity() const;  // m/s, 1 / sqrt(l_diff c_diff)
  double z_cm() const;      // ohm, sqrt(l_cm / c_cm): both lines against the reference
  double velocity_cm() const;

  // Internal impedance of one conductor per metre (ohm/m).
  std::complex<double> internal_impedance(double f) const;         // fitted ladder
  std::complex<double> target_internal_impedance(double f) const;  // Bessel formula
  // Normalised differential capacitance c(f) / c(1 MHz), complex (loss: negative imaginary part).
  std::complex<double> capacitance_factor(double f) const;         // fitted ladder
  std::complex<double> target_capacitance_factor(double f) const;  // wideband Debye
  // Differential mode per metre: Z = 2 Z_int + j w l_diff, Y = j w c_diff c(f).
  std::complex<double> series_impedance_diff(double f) const;
  std::complex<double> shunt_admittance_diff(double f) const;
  std::complex<double> target_series_impedance_diff(double f) const;
  std::complex<double> target_shunt_admittance_diff(double f) const;
  // Propagation constant sqrt(Z Y) (1/m; real part: attenuation in Np/m) and Z0 = sqrt(Z / Y).
  std::complex<double> gamma_diff(double f) const;
  std::complex<double> target_gamma_diff(double f) const;
  std::complex<double> target_z0_diff(double f) const;
};

// Resolves the spec into per-metre figures and fits the ladders. Errors as validate(), plus
// overrides that do not fit the geometry (an l of 4 l_cm or more, a c below c_g / 2).
StatusOr<CableModel> cable_model(const CableSpec& spec);

// A solid round wire's internal impedance over its DC resistance, (z / 2) J0(z) / J1(z) with
// z^2 = -j x, x = f / f_s (f_s = R_dc / (2 mu0) for R_dc in ohm per metre): 1 at DC, rising as
// sqrt(x) with an equal reactance in the skin-effect regime.
std::complex<double> round_wire_skin_factor(double x);

// n points from lo to hi, evenly spaced in log (the ladders' corners and fit frequencies; a
// measured line's too, measured_line.cpp).
std::vector<double> log_space(double lo, double hi, int n);

// Segment count: spec.segments when > 0, else the smallest count whose segment delay
// (length / velocity / n) is at most edge_time / 10, within [2, 200] (200 for an edge_time that
// is not > 0).
int cable_segments(const CableSpec& spec, const CableModel& m, double edge_time);
// Segments per loss section: the skin ladders and dielectric branches are lumped every this many
// segments (segments / 8, within [1, 4]), scaled by the length they stand for.
int loss_stride(int segments);
int loss_stride(const CableSpec& spec, int segments);  // spec.loss_stride when > 0

// Appends the cable's element cards between the ends (a_p, a_n) and (b_p, b_n); node "0" is the
// reference (chassis). Element names are the element letter, then prefix, then "_..." (SPICE
// style, as the pin models: "lcab_p3", "kcab_3", "ccab_pn0"); internal nodes are
// "<prefix>_...". edge_time (s, > 0) sets the segment count when spec.segments is 0; the count
// used goes to *segments when given. A spec with a touchstone file adds its fitted network
// (add_touchstone_cable) and reports its ladder's segments when it was read as a uniform line,
// else 0.
Status add_cable(std::vector<Card>& cards, const std::string& prefix, const std::string& a_p,
                 const std::string& a_n, const std::string& b_p, const std::string& b_n,
                 const CableSpec& spec, double edge_time = 10e-9, int* segments = nullptr);

// add_cable's ladder for a resolved model: n segments, the loss ladders every `stride` of them.
// A model with c_g = 0 gets no capacitance to the reference (a measured 2-port's extracted delay
// line, touchstone_cable.h).
void add_cable_ladder(std::vector<Card>& cards, const std::string& prefix, const std::string& a_p,
                      const std::string& a_n, const std::string& b_p, const std::string& b_n,
                      const CableModel& m, int n, int stride);

}  // namespace isolink::link
