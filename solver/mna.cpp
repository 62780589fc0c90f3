#include "solver/mna.h"

#include <algorithm>

namespace isolink {

Slot MnaPattern::slot(int row, int col) {
  if (!finalized_) {
    if (row > 0 && col > 0) entries_.emplace_back(col - 1, row - 1);
    return 0;
  }
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

}  // namespace isolink
