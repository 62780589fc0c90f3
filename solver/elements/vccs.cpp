// G: a linear voltage-controlled current source, gm V(nc+, nc-) flowing from n+ through the
// source to n- (ngspice's G). The fitted N-port of a measured cable (netlists/link/
// touchstone_cable.h) is built from these, resistors and capacitors, so that ngspice replays it.
#include <fmt/format.h>

#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"gm", NAN, "S", "transconductance, any finite value (negative allowed)"},
    {"m", 1.0, "", "parallel multiplier: the transconductance is gm m"},
};

class Vccs final : public Element {
 public:
  Vccs(const Card& card, double gm) : Element(card.name, card.loc), gm_(gm) {}
  void stamp(MnaStamp& m) const override {
    const int a = nodes_[0], b = nodes_[1], c = nodes_[2], d = nodes_[3];
    m.g(a, c, gm_), m.g(a, d, -gm_), m.g(b, c, -gm_), m.g(b, d, gm_);
  }
  // Controlled by its own terminals with gm > 0 it is a conductance; any other G joins no nodes
  // at DC for the topology checks (a floating node is tied and named, never solved singular).
  void dc_edges(std::vector<DcEdge>& out) const override {
    if (gm_ > 0 && nodes_[0] == nodes_[2] && nodes_[1] == nodes_[3])
      out.push_back({nodes_[0], nodes_[1], DcLink::Conductive});
  }

 private:
  double gm_;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> gm = card_value(card, kParams, "gm", 0);
  if (!gm) return gm.status();
  StatusOr<double> m = card_value(card, kParams, "m", -1);
  if (!m) return m.status();
  if (Status s = require_positive(card, "m", -1, *m, "multiplier"); !s.ok()) return s;
  if (!std::isfinite(*gm * *m))
    return error_at(value_loc(card, "gm", 0),
                    fmt::format("transconductance of {} is not finite", card.name));
  return std::unique_ptr<Element>(std::make_unique<Vccs>(card, *gm * *m));
}

}  // namespace

const ElementKind& vccs_kind() {
  static const ElementKind kind{'g', "vccs", "Gname n+ n- nc+ nc- gm [m=N]", 4, 0, kParams, parse};
  return kind;
}

}  // namespace isolink
