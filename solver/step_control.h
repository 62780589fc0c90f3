// StepControl: the step-size rules the transient engine and the LTI march share: the ladder of
// step sizes, the shrink after a rejected step and the growth after an accepted one.
//
//   StepControl control{.hmax = 1e-9, .hmin = 1e-19, .error_order = 3};
//   double h = control.ladder(0.1 * hmax);             // a rung: hmax / 2^k
//   ... a step of `step` with error / tolerance `ratio` ...
//   if (ratio > 1) h = control.shrink(step, ratio);    // check h >= hmin, then ladder(h)
//   else h = control.grow(step, ratio);                // already a rung
//
// Steps are rungs hmax / 2^k so that a step size comes back often and its factorization is reused
// (KluSolver caches them by the matrix key). error_order is the power of h the controlled error
// grows with: 3 for the local truncation error of a second-order method (the transient: the
// trapezoidal rule and Gear-2), 2 for that error per unit time (the LTI march), 2 also for the
// backward-Euler start step's error. A step's error ratio r then asks for the step scaled by
// 0.9 r^(-1/error_order): the root is std::cbrt or std::sqrt, exactly as the engines wrote it.
#pragma once

#include <algorithm>
#include <cmath>

namespace isolink {

// (1 / ratio)^(1 / order) for order 2 or 3 (sqrt, cbrt: correctly rounded, unlike pow).
inline double error_root(double ratio, int order) {
  return order == 3 ? std::cbrt(1.0 / ratio) : std::sqrt(1.0 / ratio);
}

struct StepControl {
  double hmax = 0.0;    // s, the top rung (> 0)
  double hmin = 0.0;    // s, the floor: the engines give up below it (grow never goes under it)
  int error_order = 3;  // 2 or 3, see above

  // The largest rung hmax / 2^k not above h (up to rounding: log2 is taken with 1e-9 slack);
  // hmax for h >= hmax. An h of 0 (or below hmax 2^-1074) makes log2 infinite, whose conversion
  // to int is undefined behaviour (UBSan: negation of INT_MIN): k is clamped to 1100, so the
  // result is 0 or a subnormal, below any hmin, and the caller's step-size floor reports.
  double ladder(double h) const {
    if (h >= hmax) return hmax;
    const double k = std::ceil(std::log2(hmax / h) - 1e-9);
    return std::ldexp(hmax, k < 1100 ? -static_cast<int>(k) : -1100);
  }

  // The retry size after a step of `step` was rejected with error / tolerance `ratio` (> 1):
  // step * max(floor, 0.9 ratio^(-1/error_order)). Not a rung: compare it with hmin (to report a
  // step that does not converge), then take ladder() of it.
  double shrink(double step, double ratio, double floor = 0.25) const {
    return shrink_by_order(step, ratio, error_order, floor);
  }
  // The same for an error of another order (the transient's backward-Euler start step: 2).
  static double shrink_by_order(double step, double ratio, int order, double floor) {
    return step * std::max(floor, 0.9 * error_root(ratio, order));
  }

  // The next step after an accepted step of `step` with error / tolerance `ratio` (<= 1; 0 when
  // no error was estimated): grown by 0.9 ratio^(-1/error_order), at most 2x, at least 0.5x, never
  // below hmin, as a rung.
  double grow(double step, double ratio) const {
    const double factor = ratio > 0 ? std::min(2.0, 0.9 * error_root(ratio, error_order)) : 2.0;
    return ladder(std::max(step * std::max(factor, 0.5), hmin));
  }
};

}  // namespace isolink
