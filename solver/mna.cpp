#include "solver/mna.h"

#include <algorithm>

#include "solver/circuit.h"

namespace isolink {

void MnaPattern::declare(int row, int col) {
  if (row > 0 && col > 0) entries_.emplace_back(col - 1, row - 1);
}

Slot MnaPattern::slot(int row, int col) const {
  if (row <= 0 || col <= 0) return trash();
  const int c = col - 1, r = row - 1;
  auto begin = row_index_.begin() + col_start_[c];
  auto end = row_index_.begin() + col_start_[c + 1];
  auto it = std::lower_bound(begin, end, r);
  return static_cast<Slot>(it - row_index_.begin());  // declared, so present
}

void MnaPattern::finalize() {
  // The diagonal is always present: KLU and the gmin ties may need it.
  for (int i = 0; i < n_; ++i) entries_.emplace_back(i, i);
  std::sort(entries_.begin(), entries_.end());
  entries_.erase(std::unique(entries_.begin(), entries_.end()), entries_.end());
  col_start_.assign(n_ + 1, 0);
  row_index_.clear();
  row_index_.reserve(entries_.size());
  for (const auto& [c, r] : entries_) {
    ++col_start_[c + 1];
    row_index_.push_back(r);
  }
  for (int c = 0; c < n_; ++c) col_start_[c + 1] += col_start_[c];
  entries_.clear();
  entries_.shrink_to_fit();
  finalized_ = true;
}

MnaMatrices assemble_mna(const Circuit& circuit) {
  MnaMatrices m;
  m.pattern = MnaPattern(circuit.unknown_count());
  MnaStamp collect(m.pattern);
  for (const auto& e : circuit.elements()) e->stamp(collect);
  m.pattern.finalize();
  m.g.assign(m.pattern.value_count(), 0.0);
  m.c.assign(m.pattern.value_count(), 0.0);
  MnaStamp values(m.pattern, m.g.data(), m.c.data());
  for (const auto& e : circuit.elements()) e->stamp(values);
  for (int node : circuit.floating_nodes())
    m.g[m.pattern.slot(node, node)] += Circuit::kFloatingTie;
  return m;
}

}  // namespace isolink
