// Branch equation: V(a) - V(b) - L di/dt = 0; KCL: +i leaves a, enters b.
#include "solver/elements/inductor.h"

#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"l", NAN, "H", "inductance, positive"},
    {"ic", NAN, "A", "initial current, used with .tran ... UIC only (as ngspice)", true},
    {"m", 1.0, "", "parallel multiplier: the inductance is l / m"},
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> l = card_value(card, kParams, "l", 0);
  if (!l) return l.status();
  if (Status s = require_positive(card, "l", 0, *l, "inductance"); !s.ok()) return s;
  StatusOr<double> m = card_value(card, kParams, "m", -1);
  if (!m) return m.status();
  if (Status s = require_positive(card, "m", -1, *m, "multiplier"); !s.ok()) return s;
  std::optional<double> ic;
  if (card.param("ic")) {
    StatusOr<double> v = card_value(card, kParams, "ic", -1);
    if (!v) return v.status();
    ic = *v;
  }
  return std::unique_ptr<Element>(std::make_unique<Inductor>(card, *l / *m, ic));
}

}  // namespace

void Inductor::stamp(MnaStamp& m) const {
  const int a = nodes_[0], b = nodes_[1], br = branches_[0];
  m.g(a, br, 1), m.g(b, br, -1), m.g(br, a, 1), m.g(br, b, -1);
  m.c(br, br, -l_);
}

void Inductor::dc_edges(std::vector<DcEdge>& out) const {
  out.push_back({nodes_[0], nodes_[1], DcLink::Inductive});
}

void Inductor::uic_state(double* x0) const {
  if (ic_) x0[branches_[0]] = *ic_;
}

const ElementKind& inductor_kind() {
  static const ElementKind kind{'l',     "inductor", "Lname n+ n- value [ic=A] [m=N]", 2, 0,
                                kParams, parse};
  return kind;
}

}  // namespace isolink
