// C: a linear capacitor between two nodes (open at DC).
#include <cmath>
#include <optional>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"c", NAN, "F", "capacitance, positive"},
    {"ic", NAN, "V", "initial voltage, used with .tran ... UIC only (as ngspice)", true},
    {"m", 1.0, "", "parallel multiplier"},
};

class Capacitor final : public Element {
 public:
  Capacitor(const Card& card, double c, std::optional<double> ic)
      : Element(card.name, card.loc), c_(c), ic_(ic) {}
  void uic_charge(const double* x0, double* dq) const override {
    if (!ic_) return;
    const double d = c_ * (*ic_ - (x0[nodes_[0]] - x0[nodes_[1]]));
    dq[nodes_[0]] += d, dq[nodes_[1]] -= d;
  }
  void stamp(MnaStamp& m) const override {
    const int a = nodes_[0], b = nodes_[1];
    m.c(a, a, c_), m.c(b, b, c_), m.c(a, b, -c_), m.c(b, a, -c_);
  }

 private:
  double c_;
  std::optional<double> ic_;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> c = card_value(card, kParams, "c", 0);
  if (!c) return c.status();
  if (Status s = require_positive(card, "c", 0, *c, "capacitance"); !s.ok()) return s;
  StatusOr<double> m = card_value(card, kParams, "m", -1);
  if (!m) return m.status();
  if (Status s = require_positive(card, "m", -1, *m, "multiplier"); !s.ok()) return s;
  std::optional<double> ic;
  if (card.param("ic")) {
    StatusOr<double> v = card_value(card, kParams, "ic", -1);
    if (!v) return v.status();
    ic = *v;
  }
  return std::unique_ptr<Element>(std::make_unique<Capacitor>(card, *c * *m, ic));
}

}  // namespace

const ElementKind& capacitor_kind() {
  static const ElementKind kind{'c',     "capacitor", "Cname n+ n- value [ic=V] [m=N]", 2, 0,
                                kParams, parse};
  return kind;
}

}  // namespace isolink
