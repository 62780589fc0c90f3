// L: a linear inductor; its branch current is an MNA unknown (and a state for step control).
// Exposed so that mutual inductance (K) can couple two of them.
#pragma once

#include <optional>

#include "solver/elements/element.h"

namespace isolink {

class Inductor final : public Element {
 public:
  Inductor(const Card& card, double l, std::optional<double> ic = std::nullopt)
      : Element(card.name, card.loc), l_(l), ic_(ic) {}
  double inductance() const { return l_; }
  int branch() const { return branches_[0]; }

  int branch_count() const override { return 1; }
  bool branch_is_state() const override { return true; }
  void stamp(MnaStamp& m) const override;
  void dc_edges(std::vector<DcEdge>& out) const override;
  void uic_state(double* x0) const override;

 private:
  double l_;
  std::optional<double> ic_;  // ic=, used with UIC
};

}  // namespace isolink
