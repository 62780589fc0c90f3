// D: the SPICE junction diode, level 1, as ngspice computes it (src/spicelib/devices/dio):
// exponential forward current with series resistance, high injection (IKF) and recombination
// (ISR, NR), reverse current to -IS, breakdown fitted so that the current at -BV is -IBV,
// depletion charge (CJO, VJ, M, FC) and diffusion charge (TT * i), gmin (1e-12 S) across the
// junction, and the temperature update of IS, VJ, CJO and BV's knee at TEMP against TNOM.
//
//   .model DCLAMP D(IS=1e-14 N=1.05 RS=0.5 CJO=12p BV=27 IBV=1m)
//   D1 anode cathode DCLAMP [area] [off] [ic=V] [m=N] [temp=T]
//
// One nonlinear port (Element::eval_port) from the junction's anode side to the cathode: the
// anode itself, or with RS > 0 an internal node "NAME#internal" behind the series resistance,
// which is stamped as a constant conductance.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr double kBoltzmann = 1.38064852e-23;  // J/K, as ngspice's const.h
constexpr double kCharge = 1.6021766208e-19;   // C
constexpr double kCtoK = 273.15;
constexpr double kRefTemp = 300.15;  // K (27 degC)
constexpr double kGmin = 1e-12;      // S across the junction, as ngspice's default gmin
// Largest exponent evaluated exactly; beyond it the exponential continues linearly, so that a
// Newton iterate far out (before limiting takes hold) gives finite currents. e^80 * 1e-14 A is
// 5e20 A: no circuit's solution lies there.
constexpr double kMaxExponent = 80.0;

constexpr ParamSpec kModelParams[] = {
    {"is", 1e-14, "A", "saturation current"},
    {"n", 1.0, "", "emission coefficient"},
    {"rs", 0.0, "ohm", "series resistance (an internal node when positive)"},
    {"cjo", 0.0, "F", "zero-bias junction capacitance (also cj0, cj)"},
    {"vj", 1.0, "V", "junction potential (also pb)"},
    {"m", 0.5, "", "grading coefficient (also mj), below 1"},
    {"fc", 0.5, "", "forward-bias depletion capacitance coefficient, in [0, 1)"},
    {"tt", 0.0, "s", "transit time (diffusion charge tt * i)"},
    {"bv", NAN, "V", "reverse breakdown voltage (none: no breakdown)", true},
    {"ibv", 1e-3, "A", "current at the breakdown voltage"},
    {"nbv", NAN, "", "breakdown emission coefficient (none: n)", true},
    {"ikf", NAN, "A", "forward knee current, high injection (none: no knee)", true},
    {"isr", NAN, "A", "recombination saturation current (none: no recombination current)", true},
    {"nr", 2.0, "", "recombination emission coefficient"},
    {"eg", 1.11, "eV", "activation energy (temperature update of is)"},
    {"xti", 3.0, "", "saturation current temperature exponent"},
    {"tnom", 27.0, "degC", "temperature the parameters were measured at (.options tnom=)"},
    {"level", 1.0, "", "model level: 1 only"},
    {"kf", 0.0, "", "flicker noise coefficient: no effect on a transient (accepted)"},
    {"af", 1.0, "", "flicker noise exponent: no effect on a transient (accepted)"},
};
// Other names ngspice reads for the same parameters.
constexpr std::array<std::pair<const char*, const char*>, 5> kModelAliases = {{
    {"cj0", "cjo"},
    {"cj", "cjo"},
    {"pb", "vj"},
    {"mj", "m"},
    {"ik", "ikf"},
}};

constexpr ParamSpec kParams[] = {
    {"area", 1.0, "", "area factor (scales is, cjo, ikf, isr; divides rs)"},
    {"m", 1.0, "", "parallel multiplier"},
    {"ic", NAN, "V", "junction voltage Newton starts from (with off: 0)", true},
    {"temp", NAN, "degC", "temperature (none: the netlist's .temp or .options temp=, else 27)",
     true},
    {"dtemp", 0.0, "degC", "added to the circuit temperature"},
    {"tnom", NAN, "degC", "the circuit's .options tnom= (the model's tnom wins)", true},
};

// The model's values at the instance's temperature, area and multiplier.
struct Junction {
  double vt = 0, vte = 0, vtebrk = 0, vterec = 0;
  double csat = 0, csat_rec = 0, ikf = 0;  // ikf 0: none; csat_rec 0: no recombination
  double gspr = 0;                         // 1 / (rs / area / m); 0: no series resistance
  double czero = 0, vj = 1, grading = 0.5, fc = 0.5, tt = 0;
  double f1 = 0, f2 = 1, f3 = 1, depcap = 0.5;
  double bv = std::numeric_limits<double>::infinity();  // the fitted knee (ngspice tBrkdwnV)
  double vcrit = 0;
};

// e^x, continued linearly beyond kMaxExponent (value and slope match there).
double soft_exp(double x, double* slope) {
  if (x <= kMaxExponent) return *slope = std::exp(x);
  const double e = std::exp(kMaxExponent);
  *slope = e;
  return e * (1.0 + (x - kMaxExponent));
}

// SPICE's pnjlim: limits a junction voltage step beyond vcrit to a logarithmic one, and a
// reverse step to twice the old voltage. A saturation current above vte/sqrt(2) makes vcrit
// negative; SPICE's log(vnew/vt) from a reverse-biased start would then take the log of a
// negative voltage (NaN), so a step that ends at or below 0 V is limited as a reverse one.
double pnjlim(double vnew, double vold, double vt, double vcrit, bool* limited) {
  *limited = false;
  if (vnew > vcrit && vnew > 0 && std::fabs(vnew - vold) > vt + vt) {
    *limited = true;
    if (vold > 0) {
      const double arg = 1 + (vnew - vold) / vt;
      return arg > 0 ? vold + vt * std::log(arg) : vcrit;
    }
    return vt * std::log(vnew / vt);
  }
  if (vnew < 0) {
    const double arg = vold > 0 ? -vold - 1 : 2 * vold - 1;
    if (vnew < arg) {
      *limited = true;
      return arg;
    }
  }
  return vnew;
}

class Diode final : public Element {
 public:
  Diode(const Card& card, const Junction& j, bool off, std::optional<double> ic)
      : Element(card.name, card.loc), j_(j), off_(off), ic_(ic) {}

  std::vector<std::string> internal_node_names() const override {
    if (j_.gspr == 0) return {};
    return {name_ + "#internal"};
  }
  bool linear_time_invariant() const override { return false; }
  int nonlinear_port_count() const override { return 1; }
  NonlinearPort nonlinear_port(int) const override { return {junction_anode(), nodes_[1]}; }

  void stamp(MnaStamp& m) const override {
    const int a = junction_anode(), k = nodes_[1];
    // The port's entries, declared here with 0: the Newton iteration adds its linearisation.
    m.g(a, a, 0.0), m.g(k, k, 0.0), m.g(a, k, 0.0), m.g(k, a, 0.0);
    if (j_.gspr == 0) return;
    const int o = nodes_[0];
    m.g(o, o, j_.gspr), m.g(a, a, j_.gspr), m.g(o, a, -j_.gspr), m.g(a, o, -j_.gspr);
  }
  void dc_edges(std::vector<DcEdge>& out) const override {
    out.push_back({junction_anode(), nodes_[1], DcLink::Conductive});  // gmin at least
    if (j_.gspr != 0) out.push_back({nodes_[0], junction_anode(), DcLink::Conductive});
  }
  PortEval eval_port(int, double v) const override;
  double limit_port(int, double v_new, double v_old, bool* limited) const override;
  double port_start_voltage(int) const override {
    if (off_) return 0.0;
    return ic_ ? *ic_ : j_.vcrit;
  }

 private:
  int junction_anode() const { return j_.gspr == 0 ? nodes_[0] : nodes_[2]; }
  void junction_current(double v, double* i, double* g) const;
  void depletion_charge(double v, double* q, double* c) const;

  Junction j_;
  bool off_;
  std::optional<double> ic_;
};

void Diode::junction_current(double v, double* i, double* g) const {
  const Junction& j = j_;
  double cd = 0, gd = 0;
  if (v >= -3 * j.vte) {
    double slope = 0;
    const double e = soft_exp(v / j.vte, &slope);
    cd = j.csat * (e - 1), gd = j.csat * slope / j.vte;
    if (j.csat_rec > 0) {  // recombination current, with ngspice's generation factor
      double slope_r = 0;
      const double er = soft_exp(v / j.vterec, &slope_r);
      double cr = j.csat_rec * (er - 1), gr = j.csat_rec * slope_r / j.vterec;
      const double u = 1 - v / j.vj, t1 = u * u + 0.005;
      const double gen = std::pow(t1, j.grading / 2);
      const double gen_v = -j.grading * u * std::pow(t1, j.grading / 2 - 1);
      gr = gr * gen + cr * gen_v;
      cr *= gen;
      cd += cr, gd += gr;
    }
    if (j.ikf > 0 && cd > 1e-18) {  // high injection
      const double s = std::sqrt(cd / j.ikf);
      gd = ((1 + s) * gd - cd * gd / (2 * s * j.ikf)) / (1 + 2 * s + cd / j.ikf);
      cd = cd / (1 + s);
    }
  } else {
    double rec = 0;  // the recombination term is held at its value at -3 vte
    if (j.csat_rec > 0) {
      const double u = 1 + 3 * j.vte / j.vj;
      rec = std::pow(u * u + 0.005, j.grading / 2) * j.csat_rec *
            (std::exp(-3 * j.vte / j.vterec) - 1);
    }
    if (v >= -j.bv) {
      double arg = 3 * j.vte / (v * std::numbers::e);
      arg = arg * arg * arg;
      cd = -j.csat * (1 + arg) + rec, gd = j.csat * 3 * arg / v;
    } else {  // breakdown
      double slope = 0;
      const double e = soft_exp(-(j.bv + v) / j.vtebrk, &slope);
      cd = -j.csat * e + rec, gd = j.csat * slope / j.vtebrk;
    }
  }
  *i = cd + kGmin * v;
  *g = gd + kGmin;
}

void Diode::depletion_charge(double v, double* q, double* c) const {
  const Junction& j = j_;
  if (j.czero == 0) {
    *q = *c = 0;
  } else if (v < j.depcap) {
    const double arg = 1 - v / j.vj, sarg = std::exp(-j.grading * std::log(arg));
    *q = j.vj * j.czero * (1 - arg * sarg) / (1 - j.grading);
    *c = j.czero * sarg;
  } else {
    const double czof2 = j.czero / j.f2;
    *q = j.czero * j.f1 +
         czof2 * (j.f3 * (v - j.depcap) + (j.grading / (2 * j.vj)) * (v * v - j.depcap * j.depcap));
    *c = czof2 * (j.f3 + j.grading * v / j.vj);
  }
}

PortEval Diode::eval_port(int, double v) const {
  PortEval e;
  junction_current(v, &e.i, &e.g);
  depletion_charge(v, &e.q, &e.c);
  e.q += j_.tt * e.i;
  e.c += j_.tt * e.g;
  return e;
}

double Diode::limit_port(int, double v_new, double v_old, bool* limited) const {
  if (std::isfinite(j_.bv) && v_new < std::min(0.0, -j_.bv + 10 * j_.vtebrk)) {
    const double t = pnjlim(-(v_new + j_.bv), -(v_old + j_.bv), j_.vtebrk, j_.vcrit, limited);
    return -(t + j_.bv);
  }
  return pnjlim(v_new, v_old, j_.vte, j_.vcrit, limited);
}

// ---- parsing: the model's and the instance's values, then the temperature update ----------

// The model parameter's value: the card's (under any of its names), else the table's default.
// NaN for an optional parameter not given.
struct ModelValues {
  std::array<double, std::size(kModelParams)> v{};
  std::array<SourceLoc, std::size(kModelParams)> loc{};
  std::array<bool, std::size(kModelParams)> given{};
  double get(const char* name) const { return v[index(name)]; }
  bool has(const char* name) const { return given[index(name)]; }
  const SourceLoc& where(const char* name) const { return loc[index(name)]; }
  static std::size_t index(std::string_view name) {
    for (std::size_t k = 0; k < std::size(kModelParams); ++k)
      if (name == kModelParams[k].name) return k;
    return 0;  // not reached: the names above are the table's
  }
};

StatusOr<ModelValues> read_model(const Card& card) {
  if (!card.model)
    return error_at(card.loc, fmt::format("diode {} names no .model (usage: {})", card.name,
                                          "Dname n+ n- model [area] [off] [ic=V]"));
  const CardModel& model = *card.model;
  ModelValues mv;
  for (std::size_t k = 0; k < std::size(kModelParams); ++k) mv.v[k] = kModelParams[k].default_value;
  for (const auto& [raw_key, arg] : model.params) {
    std::string key = raw_key;
    for (const auto& [alias, name] : kModelAliases)
      if (key == alias) key = name;
    bool known = false;
    for (const ParamSpec& p : kModelParams) known = known || key == p.name;
    if (!known) {
      std::string names;
      for (const ParamSpec& p : kModelParams)
        names += (names.empty() ? "" : ", ") + std::string(p.name);
      return error_at(arg.loc, fmt::format("unknown diode model parameter '{}' in model {} "
                                           "(known: {}; aliases cj0, cj, pb, mj, ik)",
                                           raw_key, model.name, names));
    }
    if (arg.kind != CardArg::Kind::Number || !std::isfinite(arg.number))
      return error_at(arg.loc, fmt::format("diode model parameter {} of {} needs a finite number",
                                           raw_key, model.name));
    const std::size_t k = ModelValues::index(key);
    mv.v[k] = arg.number, mv.loc[k] = arg.loc, mv.given[k] = true;
  }
  return mv;
}

// The rules each model value must keep, checked at the value's own location.
Status check_model(const Card& card, const ModelValues& mv) {
  struct Rule {
    const char* name;
    bool (*ok)(double);
    const char* rule;
  };
  static constexpr Rule kRules[] = {
      {"is", [](double x) { return x > 0; }, "must be positive"},
      {"n", [](double x) { return x > 0; }, "must be positive"},
      {"rs", [](double x) { return x >= 0; }, "must not be negative"},
      {"cjo", [](double x) { return x >= 0; }, "must not be negative"},
      {"vj", [](double x) { return x > 0; }, "must be positive"},
      {"m", [](double x) { return x >= 0 && x <= 0.9; }, "must be in [0, 0.9]"},
      {"fc", [](double x) { return x >= 0 && x < 1; }, "must be in [0, 1)"},
      {"tt", [](double x) { return x >= 0; }, "must not be negative"},
      {"bv", [](double x) { return std::isnan(x) || x > 0; }, "must be positive"},
      {"ibv", [](double x) { return x > 0; }, "must be positive"},
      {"nbv", [](double x) { return std::isnan(x) || x > 0; }, "must be positive"},
      {"ikf", [](double x) { return std::isnan(x) || x > 0; }, "must be positive"},
      {"isr", [](double x) { return std::isnan(x) || x > 0; }, "must be positive"},
      {"nr", [](double x) { return x > 0; }, "must be positive"},
      {"eg", [](double x) { return x > 0; }, "must be positive"},
      {"tnom", [](double x) { return x > -kCtoK; }, "must be above absolute zero"},
      {"level", [](double x) { return x == 1; }, "must be 1 (isolink has the level-1 diode)"},
  };
  for (const Rule& r : kRules) {
    const double x = mv.get(r.name);
    if (r.ok(x)) continue;
    const SourceLoc& loc = mv.has(r.name) ? mv.where(r.name) : card.model->loc;
    return error_at(
        loc, fmt::format("diode model {}: {} = {:g} {}", card.model->name, r.name, x, r.rule));
  }
  return Status::Ok();
}

// ngspice's DIOtempUpdate for the parameters above: junction potential and capacitance through
// the silicon band gap, saturation currents through EG and XTI, the breakdown knee fitted so that
// i(-BV) = -IBV (a fixed-point iteration to reltol 1e-3, as ngspice's), vcrit for the limiting.
Junction junction_at(const ModelValues& mv, double temp_k, double area, double mult) {
  Junction j;
  const double tnom = mv.get("tnom") + kCtoK;
  j.vt = kBoltzmann * temp_k / kCharge;
  const double n = mv.get("n");
  j.vte = n * j.vt;
  j.vtebrk = (mv.has("nbv") ? mv.get("nbv") : n) * j.vt;
  j.vterec = mv.get("nr") * j.vt;
  j.grading = mv.get("m");
  j.fc = mv.get("fc");
  j.tt = mv.get("tt");
  const double vtnom = kBoltzmann * tnom / kCharge;
  auto pb_factor = [](double t, double vt) {
    const double egfet = 1.16 - (7.02e-4 * t * t) / (t + 1108);
    const double arg = -egfet / (2 * kBoltzmann * t) + 1.1150877 / (kBoltzmann * 2 * kRefTemp);
    return -2 * vt * (1.5 * std::log(t / kRefTemp) + kCharge * arg);
  };
  const double pbfact = pb_factor(temp_k, j.vt), pbfact1 = pb_factor(tnom, vtnom);
  const double fact1 = tnom / kRefTemp, fact2 = temp_k / kRefTemp;
  const double vj = mv.get("vj"), cjo = mv.get("cjo") * area * mult;
  const double pbo = (vj - pbfact1) / fact1, gmaold = (vj - pbo) / pbo;
  j.czero = cjo / (1 + j.grading * (400e-6 * (tnom - kRefTemp) - gmaold));
  j.vj = pbfact + fact2 * pbo;
  const double gmanew = (j.vj - pbo) / pbo;
  j.czero *= 1 + j.grading * (400e-6 * (temp_k - kRefTemp) - gmanew);
  const double ratio = temp_k / tnom, eg = mv.get("eg"), xti = mv.get("xti");
  auto sat = [&](double is, double vte_, double ncoef) {
    return is * area * mult * std::exp((ratio - 1) * eg / vte_ + xti / ncoef * std::log(ratio));
  };
  j.csat = sat(mv.get("is"), j.vte, n);
  if (mv.has("isr")) j.csat_rec = sat(mv.get("isr"), j.vterec, mv.get("nr"));
  if (mv.has("ikf")) j.ikf = mv.get("ikf") * area * mult;
  if (mv.get("rs") > 0) j.gspr = area * mult / mv.get("rs");
  const double xfc = std::log(1 - j.fc);
  j.f1 = j.vj * (1 - std::exp((1 - j.grading) * xfc)) / (1 - j.grading);
  j.depcap = j.fc * j.vj;
  j.vcrit = j.vte * std::log(j.vte / (std::sqrt(2.0) * j.csat));
  if (j.depcap > 1.0) j.vj = 1.0 / j.fc, j.depcap = j.fc * j.vj;  // ngspice's limit on VJ
  j.f2 = std::exp((1 + j.grading) * xfc);
  j.f3 = 1 - j.fc * (1 + j.grading);
  if (mv.has("bv")) {
    const double bv = mv.get("bv"), nbv_vt = j.vtebrk;
    double cbv = mv.get("ibv") * area * mult;
    double xbv = bv;
    if (cbv >= j.csat * bv / j.vt) {
      const double tol = 1e-3 * cbv;
      xbv = bv - nbv_vt * std::log(1 + cbv / j.csat);
      for (int iter = 0; iter < 25; ++iter) {
        xbv = bv - nbv_vt * std::log(cbv / j.csat + 1 - xbv / j.vt);
        const double xcbv = j.csat * (std::exp((bv - xbv) / nbv_vt) - 1 + xbv / j.vt);
        if (std::fabs(xcbv - cbv) <= tol) break;
      }
    }
    j.bv = xbv;
  }
  return j;
}

StatusOr<double> instance_value(const Card& card, const char* name, int index) {
  return card_value(card, kParams, name, index);
}

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<ModelValues> mv = read_model(card);
  if (!mv) return mv.status();
  if (Status s = check_model(card, *mv); !s.ok()) return s;
  // Positional values after the model: [area] [off]; "off" may stand anywhere among them.
  bool off = false;
  int area_index = -1, numbers = 0;
  for (std::size_t k = 0; k < card.args.size(); ++k) {
    const CardArg& a = card.args[k];
    if (a.kind == CardArg::Kind::Word && a.word == "off") {
      off = true;
      continue;
    }
    if (a.kind != CardArg::Kind::Number || numbers++ > 0)
      return error_at(a.loc, fmt::format("unexpected value for diode {} (usage: Dname n+ n- "
                                         "model [area] [off] [ic=V])",
                                         card.name));
    area_index = static_cast<int>(k);
  }
  StatusOr<double> area = instance_value(card, "area", area_index);
  if (!area) return area.status();
  if (Status s = require_positive(card, "area", area_index, *area, "area"); !s.ok()) return s;
  StatusOr<double> mult = instance_value(card, "m", -1);
  if (!mult) return mult.status();
  if (Status s = require_positive(card, "m", -1, *mult, "multiplier"); !s.ok()) return s;
  StatusOr<double> dtemp = instance_value(card, "dtemp", -1);
  if (!dtemp) return dtemp.status();
  double temp_c = 27.0;
  if (card.param("temp")) {
    StatusOr<double> t = instance_value(card, "temp", -1);
    if (!t) return t.status();
    temp_c = *t;
  }
  ModelValues values = *mv;
  if (!values.has("tnom") && card.param("tnom")) {
    StatusOr<double> t = instance_value(card, "tnom", -1);
    if (!t) return t.status();
    values.v[ModelValues::index("tnom")] = *t;
  }
  const double temp_k = temp_c + *dtemp + kCtoK;
  if (!(temp_k > 0))
    return error_at(value_loc(card, "temp", -1),
                    fmt::format("temperature of {} is below absolute zero", card.name));
  std::optional<double> ic;
  if (card.param("ic")) {
    StatusOr<double> v = instance_value(card, "ic", -1);
    if (!v) return v.status();
    ic = *v;
  }
  const Junction j = junction_at(values, temp_k, *area, *mult);
  if (!(j.vj > 0) || !(j.czero >= 0))
    return error_at(card.loc,
                    fmt::format("diode {}: at {:g} degC model {} gives a junction "
                                "potential of {:g} V and a capacitance of {:g} F (the "
                                "temperature is outside what the model describes)",
                                card.name, temp_k - kCtoK, card.model->name, j.vj, j.czero));
  const double knee = std::isinf(j.bv) ? 0.0 : j.bv;  // infinite: no breakdown
  for (double x : {j.csat, j.csat_rec, j.vj, j.czero, j.vcrit, knee})
    if (!std::isfinite(x))
      return error_at(card.loc, fmt::format("diode {}: model {} gives a non-finite value at "
                                            "{:g} degC (check is, n, eg, xti)",
                                            card.name, card.model->name, temp_k - kCtoK));
  return std::unique_ptr<Element>(std::make_unique<Diode>(card, j, off, ic));
}

}  // namespace

const ElementKind& diode_kind() {
  static const ElementKind kind{
      'd',   "diode", "Dname n+ n- model [area] [off] [ic=V] [m=N] [temp=T]",
      2,     0,       kParams,
      parse, "d",     kModelParams};
  return kind;
}

}  // namespace isolink
