// R: a linear resistor between two nodes.
#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"r", NAN, "ohm", "resistance, positive"},
};

class Resistor final : public Element {
 public:
  Resistor(const Card& card, double r) : Element(card.name, card.loc), g_(1.0 / r) {}
  void declare(MnaPattern& p) override {
    const int a = nodes_[0], b = nodes_[1];
    aa_ = p.slot(a, a), ab_ = p.slot(a, b), ba_ = p.slot(b, a), bb_ = p.slot(b, b);
  }
  void stamp(double* g, double*) const override {
    g[aa_] += g_, g[bb_] += g_, g[ab_] -= g_, g[ba_] -= g_;
  }
  void dc_edges(std::vector<DcEdge>& out) const override {
    out.push_back({nodes_[0], nodes_[1], DcLink::Conductive});
  }

 private:
  double g_;
  Slot aa_ = 0, ab_ = 0, ba_ = 0, bb_ = 0;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> r = card_value(card, kParams, "r", 0);
  if (!r) return r.status();
  if (Status s = require_positive(card, "r", 0, *r, "resistance"); !s.ok()) return s;
  return std::unique_ptr<Element>(std::make_unique<Resistor>(card, *r));
}

}  // namespace

const ElementKind& resistor_kind() {
  static const ElementKind kind{'r', "resistor", "Rname n+ n- value", 2, 0, kParams, parse};
  return kind;
}

}  // namespace isolink
