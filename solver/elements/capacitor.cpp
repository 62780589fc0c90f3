// C: a linear capacitor between two nodes (open at DC).
#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"c", NAN, "F", "capacitance, positive"},
    {"ic", 0.0, "V", "initial voltage: accepted for ngspice compatibility, ignored (the DC point sets the state)"},
    {"m", 1.0, "", "parallel multiplier"},
};

class Capacitor final : public Element {
 public:
  Capacitor(const Card& card, double c) : Element(card.name, card.loc), c_(c) {}
  void declare(MnaPattern& p) override {
    const int a = nodes_[0], b = nodes_[1];
    aa_ = p.slot(a, a), ab_ = p.slot(a, b), ba_ = p.slot(b, a), bb_ = p.slot(b, b);
  }
  void stamp(double*, double* c) const override {
    c[aa_] += c_, c[bb_] += c_, c[ab_] -= c_, c[ba_] -= c_;
  }

 private:
  double c_;
  Slot aa_ = 0, ab_ = 0, ba_ = 0, bb_ = 0;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> c = card_value(card, kParams, "c", 0);
  if (!c) return c.status();
  if (Status s = require_positive(card, "c", 0, *c, "capacitance"); !s.ok()) return s;
  StatusOr<double> m = card_value(card, kParams, "m", -1);
  if (!m) return m.status();
  if (Status s = require_positive(card, "m", -1, *m, "multiplier"); !s.ok()) return s;
  return std::unique_ptr<Element>(std::make_unique<Capacitor>(card, *c * *m));
}

}  // namespace

const ElementKind& capacitor_kind() {
  static const ElementKind kind{'c', "capacitor", "Cname n+ n- value [ic=V] [m=N]", 2, 0, kParams,
                                parse};
  return kind;
}

}  // namespace isolink
