// What the LTI engine's two sources share (solver/lti.cpp, solver/lti_modal.cpp); internal to
// solver/. phi: a mode's step terms over a step h (pure; complex in, complex out).
// coarsest_grid_step: the output grid rule's first level for a span in seconds. Rows: probe
// values by row, [probe][row], in the probe's unit (V or A).
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

namespace isolink::lti_internal {

using Rows = std::vector<std::vector<double>>;  // [probe][row]

// e^x, phi1(x) = (e^x - 1) / x and phi2(x) = (e^x - 1 - x) / x^2: a mode x' = p x + u(t) moves
// over a step h, with u = b + g t on it, to e^{ph} x + h phi1(ph) b + h^2 phi2(ph) g.
struct Phi {
  std::complex<double> e, phi1, phi2;
};
inline Phi phi(std::complex<double> x) {
  Phi f;
  if (std::abs(x) < 1e-2) {  // series: the next terms are below 1e-16 relative
    f.phi2 = 0.5 + x * (1.0 / 6 + x * (1.0 / 24 + x * (1.0 / 120 + x * (1.0 / 720))));
    f.phi1 = 1.0 + x * f.phi2;
    f.e = 1.0 + x * f.phi1;
    return f;
  }
  f.e = std::exp(x);
  f.phi1 = (f.e - 1.0) / x;
  f.phi2 = (f.phi1 - 1.0) / x;
  return f;
}

// The output grid rule's first level: 20 ns or finer on a link's microseconds, but never more
// than 65,536 rows to start with, so a run of seconds (an RC of 1 s over 7 s: 350 million rows
// at 20 ns) starts coarse and is refined only as far as the 1 mV rule asks.
inline double coarsest_grid_step(double span) {
  return std::max(20e-9, span / 65536.0);
}

}  // namespace isolink::lti_internal
