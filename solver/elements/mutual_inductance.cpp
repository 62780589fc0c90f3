// K: magnetic coupling between two inductors, M = k sqrt(L1 L2), dots on the first nodes.
#include <cmath>

#include <fmt/format.h>

#include "solver/circuit.h"
#include "solver/elements/card_values.h"
#include "solver/elements/inductor.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"k", NAN, "", "coupling coefficient, 0 < |k| < 1"},
};

class MutualInductance final : public Element {
 public:
  MutualInductance(const Card& card, double k)
      : Element(card.name, card.loc), k_(k), refs_(card.refs), ref_locs_(card.ref_locs) {}

  Status link(const Circuit& circuit) override {
    for (int i = 0; i < 2; ++i) {
      const Element* e = circuit.find_element(refs_[i]);
      if (!e) return error_at(ref_locs_[i], "'" + refs_[i] + "' named by " + name_ + " not found");
      l_[i] = dynamic_cast<const Inductor*>(e);
      if (!l_[i])
        return error_at(ref_locs_[i], fmt::format("{} couples inductors, but '{}' is not an "
                                                  "inductor",
                                                  name_, refs_[i]));
    }
    if (l_[0] == l_[1]) return error_at(ref_locs_[1], name_ + " couples an inductor with itself");
    m_ = k_ * std::sqrt(l_[0]->inductance() * l_[1]->inductance());
    return Status::Ok();
  }
  void declare(MnaPattern& p) override {
    s12_ = p.slot(l_[0]->branch(), l_[1]->branch());
    s21_ = p.slot(l_[1]->branch(), l_[0]->branch());
  }
  void stamp(double*, double* c) const override { c[s12_] -= m_, c[s21_] -= m_; }

 private:
  double k_, m_ = 0.0;
  std::vector<std::string> refs_;
  std::vector<SourceLoc> ref_locs_;
  const Inductor* l_[2] = {nullptr, nullptr};
  Slot s12_ = 0, s21_ = 0;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> k = card_value(card, kParams, "k", 0);
  if (!k) return k.status();
  if (!(std::fabs(*k) > 0 && std::fabs(*k) < 1))
    return error_at(value_loc(card, "k", 0),
                    fmt::format("coupling of {} must satisfy 0 < |k| < 1, got {:g}", card.name, *k));
  return std::unique_ptr<Element>(std::make_unique<MutualInductance>(card, *k));
}

}  // namespace

const ElementKind& mutual_inductance_kind() {
  static const ElementKind kind{'k', "mutual inductance", "Kname Lname1 Lname2 k", 0, 2, kParams,
                                parse};
  return kind;
}

}  // namespace isolink
