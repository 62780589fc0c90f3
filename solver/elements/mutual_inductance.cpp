// K: magnetic coupling between two inductors, M = k sqrt(L1 L2), dots on the first nodes.
// Several K's may share inductors (a multi-winding transformer); the first K's check() tests
// every group.
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "solver/circuit.h"
#include "solver/elements/card_values.h"
#include "solver/elements/inductor.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"k", NAN, "",
     "coupling coefficient, |k| <= 1 (k = 0: no coupling; |k| = 1: ideal coupling, "
     "the transformer idiom); the inductance matrix of every coupled group must be "
     "positive semi-definite"},
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
  // The inductance matrix of the group of inductors this K couples (directly or through other
  // K's) must be positive semi-definite, or the magnetic energy i'Li / 2 could be negative and
  // the transient grows without bound (NaN). Reported at the group's first K.
  Status check(const Circuit& circuit) const override {
    // The circuit's first K checks every group at once (union-find over the inductors), so that
    // a cable ladder's thousands of K's cost O(K), not O(K^2) (each K scanning all the others).
    // Every other K returns at the first K it meets (the scan for all of them, one per K, made
    // a 12 m cable's finalize cost 3 ms).
    for (const auto& e : circuit.elements()) {
      if (e.get() == this) break;
      if (dynamic_cast<const MutualInductance*>(e.get()) != nullptr) return Status::Ok();
    }
    std::vector<const MutualInductance*> ks;
    for (const auto& e : circuit.elements())
      if (auto* k = dynamic_cast<const MutualInductance*>(e.get())) ks.push_back(k);
    std::unordered_map<const Inductor*, int> id;
    std::vector<const Inductor*> inductors;
    std::vector<int> parent;
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (const MutualInductance* k : ks) {
      for (const Inductor* l : k->l_)
        if (id.emplace(l, static_cast<int>(inductors.size())).second) {
          parent.push_back(static_cast<int>(inductors.size()));
          inductors.push_back(l);
        }
      parent[find(id[k->l_[0]])] = find(id[k->l_[1]]);
    }
    // Groups in the order of their first K; members in the order they are first named.
    std::unordered_map<int, std::vector<const MutualInductance*>> group_ks;
    std::vector<int> roots;
    for (const MutualInductance* k : ks) {
      const int r = find(id[k->l_[0]]);
      auto [it, fresh] = group_ks.try_emplace(r);
      if (fresh) roots.push_back(r);
      it->second.push_back(k);
    }
    for (int r : roots) {
      const auto& gk = group_ks[r];
      std::vector<const Inductor*> group;
      auto index = [&](const Inductor* l) {
        auto at = std::find(group.begin(), group.end(), l);
        if (at != group.end()) return static_cast<int>(at - group.begin());
        group.push_back(l);
        return static_cast<int>(group.size()) - 1;
      };
      std::vector<std::pair<int, int>> pairs;
      for (const MutualInductance* k : gk) {
        const int a = index(k->l_[0]);  // in this order: the inductors as first named
        pairs.emplace_back(a, index(k->l_[1]));
      }
      const int n = static_cast<int>(group.size());
      Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
      for (int i = 0; i < n; ++i) l(i, i) = group[i]->inductance();
      std::string names;
      for (size_t q = 0; q < gk.size(); ++q) {
        names += (names.empty() ? "" : ", ") + gk[q]->name();
        l(pairs[q].first, pairs[q].second) += gk[q]->m_;
        l(pairs[q].second, pairs[q].first) += gk[q]->m_;
      }
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(l, Eigen::EigenvaluesOnly);
      const double lo = eig.eigenvalues().minCoeff(), hi = eig.eigenvalues().maxCoeff();
      if (lo >= -1e-9 * hi) continue;
      std::string list;
      for (const Inductor* x : group) list += (list.empty() ? "" : ", ") + x->name();
      return error_at(gk[0]->loc(), fmt::format("the couplings {} make the inductance matrix of {} "
                                                "not positive semi-definite (smallest eigenvalue "
                                                "{:.4g} H): these k values cannot all hold at "
                                                "once, and the transient would grow without bound",
                                                names, list, lo));
    }
    return Status::Ok();
  }
  void stamp(MnaStamp& m) const override {
    m.c(l_[0]->branch(), l_[1]->branch(), -m_), m.c(l_[1]->branch(), l_[0]->branch(), -m_);
  }

 private:
  double k_, m_ = 0.0;
  std::vector<std::string> refs_;
  std::vector<SourceLoc> ref_locs_;
  const Inductor* l_[2] = {nullptr, nullptr};
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<double> k = card_value(card, kParams, "k", 0);
  if (!k) return k.status();
  if (!(std::fabs(*k) <= 1))
    return error_at(value_loc(card, "k", 0),
                    fmt::format("coupling of {} must satisfy |k| <= 1, got {:g}", card.name, *k));
  return std::unique_ptr<Element>(std::make_unique<MutualInductance>(card, *k));
}

}  // namespace

const ElementKind& mutual_inductance_kind() {
  static const ElementKind kind{'k',  "mutual inductance", "Kname Lname1 Lname2 k", 0, 2, kParams,
                                parse};
  return kind;
}

}  // namespace isolink
