#include "solver/circuit.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

namespace isolink {

namespace {
struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  bool unite(int a, int b) {  // false when already joined
    a = find(a), b = find(b);
    if (a == b) return false;
    parent[a] = b;
    return true;
  }
};
}  // namespace

Status Circuit::add(const Card& card) {
  const ElementKind* kind = find_element_kind(card.letter);
  if (!kind) return error_at(card.loc, fmt::format("unknown element kind '{}'", card.letter));
  if (static_cast<int>(card.nodes.size()) != kind->node_count ||
      static_cast<int>(card.refs.size()) != kind->ref_count)
    return error_at(
        card.loc, fmt::format("{} needs {} nodes ({})", card.name, kind->node_count, kind->usage));
  StatusOr<std::unique_ptr<Element>> e = kind->parse(card);
  if (!e) return e.status();
  std::vector<std::string> names = card.nodes;
  for (std::string& internal : (*e)->internal_node_names()) names.push_back(std::move(internal));
  (*e)->set_node_names(std::move(names));
  return add(std::move(*e));
}

Status Circuit::add(std::unique_ptr<Element> element) {
  if (finalized_) return Status::Error("circuit already finalized; cannot add " + element->name());
  if (element_index_.count(element->name()))
    return error_at(element->loc(), "duplicate element name '" + element->name() + "' (first at " +
                                        elements_[element_index_[element->name()]]->loc().str() +
                                        ")");
  element_index_[element->name()] = elements_.size();
  elements_.push_back(std::move(element));
  return Status::Ok();
}

int Circuit::intern_node(const std::string& name) {
  auto [it, inserted] = node_index_.emplace(name, static_cast<int>(node_names_.size()));
  if (inserted) node_names_.push_back(name);
  return it->second;
}

int Circuit::find_node(std::string_view name) const {
  auto it = node_index_.find(std::string(name));
  return it == node_index_.end() ? -1 : it->second;
}

const Element* Circuit::find_element(std::string_view name) const {
  auto it = element_index_.find(std::string(name));
  return it == element_index_.end() ? nullptr : elements_[it->second].get();
}

std::string Circuit::unknown_name(int u) const {
  if (u < node_count()) return "node " + node_names_[u];
  return "current of " + branch_names_[u - node_count()];
}

Status Circuit::finalize() {
  if (finalized_) return Status::Ok();
  for (auto& e : elements_) {
    std::vector<int> nodes;
    for (const auto& n : e->node_names()) nodes.push_back(intern_node(n));
    e->set_nodes(std::move(nodes));
  }
  int next = node_count();
  for (auto& e : elements_) {
    std::vector<int> branches;
    for (int i = 0; i < e->branch_count(); ++i) {
      branches.push_back(next++);
      branch_names_.push_back(e->name());
    }
    e->set_branches(std::move(branches));
  }
  unknowns_ = next - 1;
  is_state_.assign(next, false);
  for (auto& e : elements_)
    for (int b : e->branches()) is_state_[b] = e->branch_is_state();
  for (auto& e : elements_)
    if (Status s = e->link(*this); !s.ok()) return s;
  for (auto& e : elements_)
    if (Status s = e->check(*this); !s.ok()) return s;

  // DC topology: voltage-defining loops are singular; components without a path to ground float.
  std::vector<DcEdge> edges;
  std::vector<const Element*> owner;
  for (auto& e : elements_) {
    size_t before = edges.size();
    e->dc_edges(edges);
    owner.resize(edges.size(), e.get());
    (void)before;
  }
  const int n = node_count();
  UnionFind vloop(n), conn(n);
  // Voltage sources first, then inductors: an inductor that closes a loop of voltage sources and
  // inductors is opened at DC (its current starts at 0), so only a loop of sources is an error.
  std::vector<size_t> order(edges.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_partition(order.begin(), order.end(),
                        [&](size_t i) { return edges[i].link != DcLink::Inductive; });
  std::string opened;
  for (size_t i : order) {
    const DcEdge& d = edges[i];
    if (d.link == DcLink::Inductive) {
      if (!vloop.unite(d.a, d.b) && !owner[i]->branches().empty()) {
        dc_open_.push_back(owner[i]->branches()[0]);
        if (dc_open_.size() <= 8) opened += (opened.empty() ? "" : ", ") + owner[i]->name();
      }
      conn.unite(d.a, d.b);
      continue;
    }
    if (d.link == DcLink::VoltageDefining && !vloop.unite(d.a, d.b)) {
      // Name the loop: every voltage-defining element between the two joined sets.
      std::vector<std::string> names;
      for (size_t j = 0; j <= i; ++j)
        if (edges[j].link == DcLink::VoltageDefining && vloop.find(edges[j].a) == vloop.find(d.a))
          names.push_back(owner[j]->name());
      std::string list;
      for (const auto& s : names) list += (list.empty() ? "" : ", ") + s;
      return error_at(owner[i]->loc(),
                      fmt::format("singular circuit: voltage sources / inductors form a loop "
                                  "({}) through nodes {} and {}",
                                  list, node_names_[d.a], node_names_[d.b]));
    }
    if (d.link != DcLink::CurrentSource) conn.unite(d.a, d.b);
  }
  if (!dc_open_.empty())
    warnings_.push_back(fmt::format(
        "warning: {} inductor(s) close a loop with voltage sources or other inductors, where the "
        "DC current is not determined; they start at 0 A (as in ngspice): {}{}",
        dc_open_.size(), opened,
        dc_open_.size() > 8 ? fmt::format(" and {} more", dc_open_.size() - 8) : ""));
  std::vector<bool> grounded(n, false);
  for (int i = 0; i < n; ++i) grounded[i] = conn.find(i) == conn.find(0);
  for (size_t i = 0; i < edges.size(); ++i) {
    const DcEdge& d = edges[i];
    if (d.link != DcLink::CurrentSource) continue;
    for (int node : {d.a, d.b})
      if (!grounded[node])
        return error_at(owner[i]->loc(),
                        fmt::format("singular circuit: current source {} drives node {}, which "
                                    "has no DC path to ground",
                                    owner[i]->name(), node_names_[node]));
  }
  std::string list;
  for (int i = 1; i < n; ++i) {
    if (grounded[i]) continue;
    floating_.push_back(i);
    if (floating_.size() <= 8) list += (list.empty() ? "" : ", ") + node_names_[i];
  }
  if (!floating_.empty()) {
    if (floating_.size() > 8) list += fmt::format(" and {} more", floating_.size() - 8);
    warnings_.push_back(fmt::format(
        "warning: {} node(s) have no DC path to ground and are tied to it with {:g} S: {}",
        floating_.size(), kFloatingTie, list));
  }
  finalized_ = true;
  return Status::Ok();
}

}  // namespace isolink
