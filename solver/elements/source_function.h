// SourceFunction: the time dependence of an independent source (DC, PULSE, PWL, SIN, EXP).
// PWL takes ngspice's td= (delay) and r= (repeat from that time to the last) as card params.
//
//   auto f = SourceFunction::Parse(card);   // from "DC 2.5", "PULSE(...)", "PWL(...)", "SIN(...)"
//   f->bind_time(tstep, tstop);             // ngspice defaults that depend on the analysis
//   double v = f->value(t);  f->breakpoints(tstop, out);
#pragma once

#include <vector>

#include "base/status.h"
#include "solver/card.h"

namespace isolink {

// A change of slope: from t on, the function's slope grows by `slope` (per second).
struct Ramp {
  double t = 0.0;
  double slope = 0.0;
};

class SourceFunction {
 public:
  enum class Kind { Dc, Pulse, Pwl, Sin, Exp };

  // Reads the card's positional values; errors point at the offending value.
  static StatusOr<SourceFunction> Parse(const Card& card);

  void bind_time(double tstep, double tstop);
  double value(double t) const;
  double dc_value() const { return value(0.0); }
  void breakpoints(double tstop, std::vector<double>& out) const;
  // How many corners breakpoints(tstop, out) lists, counted in closed form without listing them:
  // a long run of a periodic source has billions (PULSE(0 1 0 1n 1n 1u 2u) over 1000 s: 2e9),
  // so callers bound them before an engine lists them. Exact but for rounding at a corner that
  // falls on 0 or tstop.
  double corner_count(double tstop) const;
  Kind kind() const { return kind_; }
  // DC, PULSE and PWL are piecewise linear in t; SIN is not.
  // Piecewise linear and continuous (a sum of ramps): DC, PULSE, and PWL unless its r= repeat
  // jumps from the last value back to a different one.
  bool piecewise_linear() const {
    if (kind_ == Kind::Sin || kind_ == Kind::Exp) return false;
    return kind_ != Kind::Pwl || pwl_repeat_ < 0 || pwl_v_[pwl_repeat_] == pwl_v_.back();
  }
  // For a piecewise-linear function: its corners in [0, tstop] as ramps, in time order, so that
  // f(t) = f(0) + sum over ramps with t_k < t of slope_k * (t - t_k) on [0, tstop]. Corners closer
  // than 1e-12 * tstop merge (as the transient's breakpoints).
  std::vector<Ramp> ramps(double tstop) const;

 private:
  Kind kind_ = Kind::Dc;
  double dc_ = 0.0;
  std::vector<double> p_;              // PULSE / SIN parameters as given (missing = NaN)
  std::vector<double> pwl_t_, pwl_v_;  // PWL corners
  double pwl_td_ = 0.0;                // PWL td=
  int pwl_repeat_ = -1;                // PWL r=: index of the time the repeat starts from
  // PULSE resolved: v1 v2 td tr tf pw per np (EXP: v1 v2 td1 tau1 td2 tau2 in v1 v2 td tr pw tf)
  double v1_ = 0, v2_ = 0, td_ = 0, tr_ = 0, tf_ = 0, pw_ = 0, per_ = 0, np_ = 0;
};

}  // namespace isolink
