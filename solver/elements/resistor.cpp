// R: a linear resistor between two nodes (with ngspice's m=, tc1=, tc2=, temp=, tnom=).
#include <fmt/format.h>

#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"r", NAN, "ohm", "resistance at tnom, positive"},
    {"m", 1.0, "", "parallel multiplier: the resistance is r / m"},
    {"tc1", 0.0, "1/degC", "first-order temperature coefficient"},
    {"tc2", 0.0, "1/degC^2",
     "second-order temperature coefficient: r (1 + tc1 dT + tc2 dT^2), "
     "dT = temp - tnom"},
    {"temp", 27.0, "degC", "temperature (the netlist's .temp or .options temp= when not given)"},
    {"tnom", 27.0, "degC", "temperature at which r is given (.options tnom=)"},
};

class Resistor final : public Element {
 public:
  Resistor(const Card& card, double r) : Element(card.name, card.loc), g_(1.0 / r) {}
  void stamp(MnaStamp& m) const override {
    const int a = nodes_[0], b = nodes_[1];
    m.g(a, a, g_), m.g(b, b, g_), m.g(a, b, -g_), m.g(b, a, -g_);
  }
  void dc_edges(std::vector<DcEdge>& out) const override {
    out.push_back({nodes_[0], nodes_[1], DcLink::Conductive});
  }

 private:
  double g_;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  double v[6];
  for (int k = 0; k < 6; ++k) {
    StatusOr<double> x = card_value(card, kParams, kParams[k].name, k == 0 ? 0 : -1);
    if (!x) return x.status();
    v[k] = *x;
  }
  const double r = v[0], m = v[1], tc1 = v[2], tc2 = v[3], dt = v[4] - v[5];
  if (Status s = require_positive(card, "r", 0, r, "resistance"); !s.ok()) return s;
  if (Status s = require_positive(card, "m", -1, m, "multiplier"); !s.ok()) return s;
  const double factor = 1.0 + tc1 * dt + tc2 * dt * dt;
  if (!(factor > 0))
    return error_at(value_loc(card, "tc1", -1),
                    fmt::format("resistance of {} at {:g} degC is not positive (tc1={:g}, "
                                "tc2={:g}, tnom={:g} degC)",
                                card.name, v[4], tc1, tc2, v[5]));
  return std::unique_ptr<Element>(std::make_unique<Resistor>(card, r * factor / m));
}

}  // namespace

const ElementKind& resistor_kind() {
  static const ElementKind kind{
      'r', "resistor", "Rname n+ n- value [m=N] [tc1=A] [tc2=B] [temp=T]", 2, 0, kParams, parse};
  return kind;
}

}  // namespace isolink
