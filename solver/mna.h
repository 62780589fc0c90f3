// MNA assembly: a sparse pattern declared once, constant G and C value arrays over it.
//
// Lifecycle:
//   MnaPattern pattern(unknowns);            // unknowns excludes ground (index 0)
//   for each element: element.declare(pattern)   // collecting pass: records entries
//   pattern.finalize();                            // builds the CSC structure
//   for each element: element.declare(pattern)   // binding pass: same calls, real slots
//   values: g and c arrays of pattern.value_count() doubles; element.stamp(g, c)
// Matrix rows and columns are unknown indices minus one; any entry in the ground row or column
// maps to the trash slot (the last value), which the solver never reads.
#pragma once

#include <utility>
#include <vector>

#include "solver/elements/element.h"

namespace isolink {

class MnaPattern {
 public:
  explicit MnaPattern(int unknowns) : n_(unknowns) {}

  // The slot of entry (row, col), both unknown indices (0 = ground).
  Slot slot(int row, int col);
  void finalize();
  bool finalized() const { return finalized_; }

  int size() const { return n_; }
  int nonzeros() const { return static_cast<int>(row_index_.size()); }
  int value_count() const { return nonzeros() + 1; }  // + trash
  Slot trash() const { return nonzeros(); }
  const std::vector<int>& col_start() const { return col_start_; }  // CSC, n + 1 entries
  const std::vector<int>& row_index() const { return row_index_; }  // CSC, nonzeros entries

 private:
  int n_;
  bool finalized_ = false;
  std::vector<std::pair<int, int>> entries_;  // collecting pass (col, row), 0-based
  std::vector<int> col_start_, row_index_;
};

}  // namespace isolink
