// A measured cable: a Touchstone file's S-parameters fitted with a rational admittance and built
// into the circuit as an equivalent network of R, C and G (VCCS) cards, which the transient
// engine, the LTI engine's reduced model, the AC analysis and ngspice all take unchanged.
//
//   link spec:  cable: {touchstone: harness.s4p, ports: [1, 2, 3, 4], tolerance: 1e-3}
//   StatusOr<std::shared_ptr<const TouchstoneCable>> c = touchstone_cable(spec);  // cached
//   add_touchstone_cable(cards, "cab", "ap", "an", "bp", "bn", spec);
//
// Ports. A 4-port is single-ended to the chassis reference (node 0): by default port 1 = tx P,
// 2 = tx N, 3 = rx P, 4 = rx N; `ports: [a, b, c, d]` names the file's ports for those four. A
// 2-port is differential (port 1 across tx P-N, port 2 across rx P-N, at the file's reference,
// 100 ohm for a mixed-mode export); its common mode is assumed open: the cable joins no
// common-mode current between the ends and adds no capacitance to the chassis (a question about
// the common mode, isolink noise, needs the 4-port).
//
// Fit (solver/vector_fit.h): Y = y_from_s(S) over the file's band, relaxed vector fitting with
// common poles, the order raised until the RMS S error is under the tolerance; then passivity
// enforced. Below the first frequency: a file without a DC point gets one, the conductors'
// series resistance extrapolated to DC and nothing else (touchstone_cable.cpp,
// dc_extrapolation), and the fit passes through it
// (stated in `isolink touchstone`'s output with the DC conductances). A fit that does not reach
// the tolerance is an error naming the error reached.
//
// Long lines (docs/touchstone.md, "Long lines"): a line of many wavelengths over the band (its
// differential delay times the top frequency at least kLongLineCycles) would need hundreds of
// poles. It is fitted first as a uniform line (netlists/link/measured_line.h) and built as the
// native cable's ladder, which carries the delay; when that line is not within the tolerance of
// the file (connectors, splices), the rational fit below is tried as for any file.
//
// Realization (docs/touchstone.md): Y(s) = D + sum_k R_k / (s - p_k). For each pole and each
// port j a state node z with C = 1/|Re p| and 1 ohm to ground, driven by a G card with the
// port's voltage (so z = |Re p| v_j / (s - p), at most |v_j|); a pair's two states are coupled
// by G cards with Im p / |Re p|. Each port's current is D v plus G cards from the states with
// the residues over |Re p|. The states stay the size of the port voltages at any frequency.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "netlists/link/cable.h"
#include "netlists/link/measured_line.h"
#include "netlists/touchstone.h"
#include "solver/card.h"
#include "solver/vector_fit.h"

namespace isolink::link {

// A file is tried as a uniform line when the line's differential delay spans at least this many
// periods of the band's top frequency (a rational fit needs about 4 poles a period).
inline constexpr double kLongLineCycles = 8;

struct TouchstoneCable {
  Touchstone data;            // as read, ports in the file's order
  std::vector<int> ports;     // file ports (1-based) for tx P, tx N, rx P, rx N (4-port)
  bool differential = false;  // a 2-port: ports across the pairs
  FitResult fit;              // of Y in the link's port order
  PassivityReport passivity;
  Eigen::MatrixXd dc_conductance;  // Y(0) of the fitted model, S
  bool dc_extrapolated = false;    // the file has no DC point: Y(0) from dc_resistance
  Eigen::MatrixXd dc_resistance;   // ohm, the conductors' series R extrapolated to DC (P, N)
  // A long line fitted as a uniform line: the cable is its ladder, fit.model has no poles and
  // fit's errors are the line's. Else the rational fit alone.
  std::optional<MeasuredLine> line;
  double line_rms_error = 0;  // the uniform line's RMS |S - S_file| where one was tried, else 0
  // The model's admittance at f (Hz) in the link's port order (the line's exact, not its ladder).
  Eigen::MatrixXcd y(double f) const;
};

// Below the first frequency a VNA measures (10-300 kHz): the cable as its lumped pi section,
// exact as f -> 0 for any line. freqs (ascending, the first > 0) and y (admittances in the link's
// port order, 2h x 2h: the ends' h lines) gain points at DC and from 1e-3 of the first frequency
// up to it, 4 a decade; *r_dc becomes the conductors' series resistance at DC (h x h). The
// series impedance is taken from the lowest points over which the cable is electrically short
// (|Z Y| <= 0.15, up to 5, at least 1), corrected to second order for a line's distribution, and
// fitted as a round wire's skin effect plus an inductance (each point weighted by the first
// frequency over its own); each end's shunt is j w C. At DC: R alone, no conductance to the
// chassis or between the lines. Error (empty message): the DC resistance is not positive.
Status extend_below_band(std::vector<double>& freqs, std::vector<Eigen::MatrixXcd>& y,
                         Eigen::MatrixXd* r_dc);

// Reads and fits a spec's file (spec.touchstone, spec.ports, spec.fit_tolerance,
// spec.uniform_line). Fits are kept, keyed by the file's bytes and those.
StatusOr<std::shared_ptr<const TouchstoneCable>> touchstone_cable(const CableSpec& spec);
// The same from data in memory (isolink touchstone, tests).
StatusOr<std::shared_ptr<const TouchstoneCable>> fit_touchstone_cable(const Touchstone& data,
                                                                      std::vector<int> ports,
                                                                      double tolerance,
                                                                      bool long_line = true);

// The equivalent network of a fitted model between port node pairs (plus, minus): minus "0" for
// a single-ended port. Element and node names start with prefix as add_cable's do.
void add_rational_cards(std::vector<Card>& cards, const std::string& prefix, const RationalModel& m,
                        const std::vector<std::pair<std::string, std::string>>& port_nodes);

// The cable's cards between the ends (a_p, a_n) and (b_p, b_n); a uniform line as a ladder whose
// segments are at most edge_time / 10 of delay (within [2, 200]; their count to *segments).
Status add_touchstone_cable(std::vector<Card>& cards, const std::string& prefix,
                            const std::string& a_p, const std::string& a_n, const std::string& b_p,
                            const std::string& b_n, const CableSpec& spec, double edge_time,
                            int* segments = nullptr);

}  // namespace isolink::link
