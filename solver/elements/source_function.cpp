#include "solver/elements/source_function.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace isolink {

namespace {
double or_default(const std::vector<double>& p, size_t i, double d) {
  return i < p.size() && !std::isnan(p[i]) ? p[i] : d;
}
}  // namespace

StatusOr<SourceFunction> SourceFunction::Parse(const Card& card) {
  SourceFunction f;
  bool have_value = false;
  const auto& args = card.args;
  if (const CardArg* dc = card.param("dc")) {  // dc=1, as DC 1
    if (dc->kind != CardArg::Kind::Number) return error_at(dc->loc, "expected a number for dc=");
    f.dc_ = dc->number;
  }
  for (size_t i = 0; i < args.size(); ++i) {
    const CardArg& a = args[i];
    if (a.kind == CardArg::Kind::Number) {
      if (have_value)
        return error_at(a.loc, "unexpected extra value for source '" + card.name + "'");
      f.dc_ = a.number;
      have_value = true;
    } else if (a.kind == CardArg::Kind::Word) {
      if (a.word == "dc") {
        if (i + 1 >= args.size() || args[i + 1].kind != CardArg::Kind::Number)
          return error_at(a.loc, "expected a number after DC");
        f.dc_ = args[++i].number;
        have_value = true;
      } else if (a.word == "ac") {
        // AC magnitude/phase: no small-signal analysis here; skip its numbers.
        while (i + 1 < args.size() && args[i + 1].kind == CardArg::Kind::Number) ++i;
      } else {
        return error_at(a.loc, "expected DC, PULSE, PWL or SIN in source '" + card.name +
                                   "', found '" + a.word + "'");
      }
    } else {  // Call
      if (a.word == "pulse") {
        if (a.call.size() < 2 || a.call.size() > 8)
          return error_at(a.loc, "PULSE takes 2 to 8 values (V1 V2 TD TR TF PW PER NP), got " +
                                     std::to_string(a.call.size()));
        f.kind_ = Kind::Pulse;
        f.p_ = a.call;
        for (size_t k = 2; k < a.call.size(); ++k)
          if (a.call[k] < 0) return error_at(a.loc, "PULSE timing values must not be negative");
      } else if (a.word == "sin") {
        if (a.call.size() < 3 || a.call.size() > 6)
          return error_at(a.loc, "SIN takes 3 to 6 values (VO VA FREQ TD THETA PHASE), got " +
                                     std::to_string(a.call.size()));
        f.kind_ = Kind::Sin;
        f.p_ = a.call;
      } else if (a.word == "exp") {
        if (a.call.size() < 2 || a.call.size() > 6)
          return error_at(a.loc, "EXP takes 2 to 6 values (V1 V2 TD1 TAU1 TD2 TAU2), got " +
                                     std::to_string(a.call.size()));
        f.kind_ = Kind::Exp;
        f.p_ = a.call;
        for (size_t k = 2; k < a.call.size(); ++k)
          if (a.call[k] < 0) return error_at(a.loc, "EXP times must not be negative");
      } else if (a.word == "trnoise" || a.word == "trrandom" || a.word == "sffm" ||
                 a.word == "am") {
        const char* what = a.word == "trnoise"    ? "TRNOISE (transient noise source)"
                           : a.word == "trrandom" ? "TRRANDOM (random source)"
                           : a.word == "sffm"     ? "SFFM (frequency-modulated source)"
                                                  : "AM (amplitude-modulated source)";
        return error_at(a.loc, std::string(what) +
                                   " is not supported (isolink's sources are DC, PULSE, PWL, SIN "
                                   "and EXP; isolink's link specs add crosstalk and noise to "
                                   "the received eye instead)");
      } else if (a.word == "pwl") {
        if (a.call.size() < 2 || a.call.size() % 2 != 0)
          return error_at(a.loc, "PWL takes time/value pairs, got " +
                                     std::to_string(a.call.size()) + " values");
        f.kind_ = Kind::Pwl;
        for (size_t k = 0; k < a.call.size(); k += 2) {
          double t = a.call[k];
          if (t < 0) return error_at(a.loc, fmt::format("PWL time {:g} s is negative", t));
          if (!f.pwl_t_.empty() && t <= f.pwl_t_.back())
            return error_at(a.loc, fmt::format("PWL times must increase: point {} has t={:g} s "
                                               "after t={:g} s",
                                               k / 2 + 1, t, f.pwl_t_.back()));
          f.pwl_t_.push_back(t);
          f.pwl_v_.push_back(a.call[k + 1]);
        }
      } else {
        return error_at(
            a.loc, "unknown source function '" + a.word + "' (expected PULSE, PWL, SIN or EXP)");
      }
      have_value = true;
    }
  }
  // PWL(...) td=DELAY r=REPEAT_FROM, as ngspice.
  for (const char* key : {"td", "r"}) {
    const CardArg* p = card.param(key);
    if (!p) continue;
    if (f.kind_ != Kind::Pwl)
      return error_at(p->loc, std::string(key) + "= applies to a PWL source only");
    if (p->kind != CardArg::Kind::Number)
      return error_at(p->loc, std::string("expected a number for ") + key + "=");
    if (key[0] == 't') {
      if (p->number < 0)
        return error_at(p->loc, fmt::format("PWL td={:g} s is negative", p->number));
      f.pwl_td_ = p->number;
      continue;
    }
    const double r = p->number;
    if (r == -1.0) continue;  // the table's "no repeat"
    auto it = std::find(f.pwl_t_.begin(), f.pwl_t_.end(), r);
    if (r < 0 || it == f.pwl_t_.end() || it + 1 == f.pwl_t_.end())
      return error_at(p->loc, fmt::format("PWL r={:g} s must be one of the PWL's times other than "
                                          "the last (the repeat runs from r to the last time)",
                                          r));
    f.pwl_repeat_ = static_cast<int>(it - f.pwl_t_.begin());
  }
  f.bind_time(0.0, 0.0);
  return f;
}

void SourceFunction::bind_time(double tstep, double tstop) {
  if (kind_ == Kind::Exp) {  // ngspice: TD1 0, TAU1 TSTEP, TD2 TD1 + TSTEP, TAU2 TSTEP
    const double step = tstep > 0 ? tstep : 1e-12;
    v1_ = or_default(p_, 0, 0.0);
    v2_ = or_default(p_, 1, 0.0);
    td_ = or_default(p_, 2, 0.0);
    tr_ = or_default(p_, 3, 0.0);
    if (tr_ <= 0) tr_ = step;
    pw_ = or_default(p_, 4, 0.0);
    if (pw_ <= 0) pw_ = td_ + step;
    tf_ = or_default(p_, 5, 0.0);
    if (tf_ <= 0) tf_ = step;
    return;
  }
  if (kind_ != Kind::Pulse) return;
  v1_ = or_default(p_, 0, 0.0);
  v2_ = or_default(p_, 1, 0.0);
  td_ = or_default(p_, 2, 0.0);
  // ngspice: TR and TF default to TSTEP, PW and PER to TSTOP.
  tr_ = or_default(p_, 3, 0.0);
  tf_ = or_default(p_, 4, 0.0);
  if (tr_ <= 0) tr_ = tstep > 0 ? tstep : 1e-12;
  if (tf_ <= 0) tf_ = tstep > 0 ? tstep : 1e-12;
  pw_ = or_default(p_, 5, tstop > 0 ? tstop : 1.0);
  per_ = or_default(p_, 6, tstop > 0 ? tstop : 1.0);
  np_ = or_default(p_, 7, 0.0);
  if (per_ < tr_ + pw_ + tf_) per_ = tr_ + pw_ + tf_;
}

double SourceFunction::value(double t) const {
  switch (kind_) {
    case Kind::Dc:
      return dc_;
    case Kind::Pulse: {
      if (t <= td_) return v1_;
      double tt = t - td_;
      double k = std::floor(tt / per_);
      if (np_ > 0 && k >= np_) return v1_;
      tt -= k * per_;
      if (tt < tr_) return v1_ + (v2_ - v1_) * tt / tr_;
      if (tt <= tr_ + pw_) return v2_;
      if (tt < tr_ + pw_ + tf_) return v2_ + (v1_ - v2_) * (tt - tr_ - pw_) / tf_;
      return v1_;
    }
    case Kind::Exp: {  // v1_ v2_ td1 = td_, tau1 = tr_, td2 = pw_, tau2 = tf_
      if (t <= td_) return v1_;
      double v = v1_ + (v2_ - v1_) * (1 - std::exp(-(t - td_) / tr_));
      if (t > pw_) v += (v1_ - v2_) * (1 - std::exp(-(t - pw_) / tf_));
      return v;
    }
    case Kind::Pwl: {
      t -= pwl_td_;
      if (pwl_repeat_ >= 0 && t > pwl_t_.back()) {
        const double from = pwl_t_[pwl_repeat_], period = pwl_t_.back() - from;
        t = from + std::fmod(t - from, period);
      }
      if (t <= pwl_t_.front()) return pwl_v_.front();
      if (t >= pwl_t_.back()) return pwl_v_.back();
      size_t i = std::upper_bound(pwl_t_.begin(), pwl_t_.end(), t) - pwl_t_.begin();
      double f = (t - pwl_t_[i - 1]) / (pwl_t_[i] - pwl_t_[i - 1]);
      return pwl_v_[i - 1] + f * (pwl_v_[i] - pwl_v_[i - 1]);
    }
    case Kind::Sin: {
      double vo = or_default(p_, 0, 0), va = or_default(p_, 1, 0), freq = or_default(p_, 2, 0);
      double td = or_default(p_, 3, 0), theta = or_default(p_, 4, 0), ph = or_default(p_, 5, 0);
      double phase = ph * std::numbers::pi / 180.0;
      if (t <= td) return vo + va * std::sin(phase);
      double tt = t - td;
      return vo + va * std::exp(-tt * theta) * std::sin(2 * std::numbers::pi * freq * tt + phase);
    }
  }
  return 0.0;
}

void SourceFunction::breakpoints(double tstop, std::vector<double>& out) const {
  switch (kind_) {
    case Kind::Dc:
      return;
    case Kind::Pulse: {
      for (long k = 0;; ++k) {
        if (np_ > 0 && k >= np_) break;
        double base = td_ + static_cast<double>(k) * per_;
        if (base > tstop) break;
        for (double c : {base, base + tr_, base + tr_ + pw_, base + tr_ + pw_ + tf_})
          if (c > 0 && c <= tstop) out.push_back(c);
        if (per_ <= 0) break;
      }
      return;
    }
    case Kind::Exp:
      for (double c : {td_, pw_})
        if (c > 0 && c <= tstop) out.push_back(c);
      return;
    case Kind::Pwl: {
      for (double t : pwl_t_)
        if (t + pwl_td_ > 0 && t + pwl_td_ <= tstop) out.push_back(t + pwl_td_);
      if (pwl_repeat_ < 0) return;
      const double from = pwl_t_[pwl_repeat_], period = pwl_t_.back() - from;
      for (double base = pwl_t_.back() + pwl_td_; base <= tstop; base += period)
        for (size_t k = pwl_repeat_ + 1; k < pwl_t_.size(); ++k) {
          const double t = base + (pwl_t_[k] - from);
          if (t <= tstop) out.push_back(t);
        }
      return;
    }
    case Kind::Sin: {
      double td = or_default(p_, 3, 0);
      if (td > 0 && td <= tstop) out.push_back(td);
      return;
    }
  }
}

namespace {
// How many k >= 0 have base + k * period <= limit (one at most when period is not positive).
double steps_up_to(double base, double period, double limit) {
  if (!(base <= limit)) return 0.0;
  return period > 0 ? std::floor((limit - base) / period) + 1 : 1.0;
}
}  // namespace

double SourceFunction::corner_count(double tstop) const {
  switch (kind_) {
    case Kind::Dc:
      return 0;
    case Kind::Pulse: {
      double periods = steps_up_to(td_, per_, tstop);
      if (np_ > 0) periods = std::min(periods, std::ceil(np_));
      double n = 0;
      for (double c : {td_, td_ + tr_, td_ + tr_ + pw_, td_ + tr_ + pw_ + tf_})
        n += std::min(periods, steps_up_to(c, per_, tstop)) -
             std::min(periods, steps_up_to(c, per_, 0.0));  // those in (0, tstop]
      return n;
    }
    case Kind::Pwl: {
      double n = 0;
      for (double t : pwl_t_) n += t + pwl_td_ > 0 && t + pwl_td_ <= tstop ? 1 : 0;
      if (pwl_repeat_ < 0) return n;
      const double from = pwl_t_[pwl_repeat_], period = pwl_t_.back() - from;
      if (!(period > 0)) return n;
      for (size_t k = pwl_repeat_ + 1; k < pwl_t_.size(); ++k)
        n += steps_up_to(pwl_t_.back() + pwl_td_ + (pwl_t_[k] - from), period, tstop);
      return n;
    }
    case Kind::Exp:
    case Kind::Sin: {  // two corners at most
      std::vector<double> out;
      breakpoints(tstop, out);
      return static_cast<double>(out.size());
    }
  }
  return 0;
}

std::vector<Ramp> SourceFunction::ramps(double tstop) const {
  std::vector<Ramp> out;
  if (kind_ == Kind::Dc || !piecewise_linear() || !(tstop > 0)) return out;
  std::vector<double> corners{0.0};
  breakpoints(tstop, corners);
  corners.push_back(tstop);
  std::sort(corners.begin(), corners.end());
  const double tiny = tstop * 1e-12;
  std::vector<double> t;
  for (double c : corners)
    if (t.empty() || c - t.back() > tiny) t.push_back(c);
  double previous = 0.0;  // slope before t[0] = 0: the function is constant before its first corner
  for (size_t i = 0; i + 1 < t.size(); ++i) {
    // Exact on each segment: value() is linear between consecutive corners.
    const double slope = (value(t[i + 1]) - value(t[i])) / (t[i + 1] - t[i]);
    if (slope != previous) out.push_back({t[i], slope - previous});
    previous = slope;
  }
  return out;
}

}  // namespace isolink
