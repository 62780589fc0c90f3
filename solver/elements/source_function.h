// SourceFunction: the time dependence of an independent source (DC, PULSE, PWL, SIN, EXP).
// PWL takes ngspice's td= (delay) and r= (repeat from that time to the last) as card params.
//
//   auto f = SourceFunction::Parse(card);   // from "DC 2.5", "PULSE(...)", "PWL(...)", "SIN(...)"
//   f->bind_time(tstep, tstop);             // ngspice defaults that depend on the analysis
//   double v = f->value(t);  f->breakpoints(tstop, out);
#pragma once

#include <vector>

#include "solver/card.h"
#include "base/status.h"

namespace isolink {

class SourceFunction {
 public:
  enum class Kind { Dc, Pulse, Pwl, Sin, Exp };

  // Reads the card's positional values; errors point at the offending value.
  static StatusOr<SourceFunction> Parse(const Card& card);

  void bind_time(double tstep, double tstop);
  double value(double t) const;
  double dc_value() const { return value(0.0); }
  void breakpoints(double tstop, std::vector<double>& out) const;
  Kind kind() const { return kind_; }

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
