// MNA assembly: a sparse pattern declared once, constant G and C value arrays over it.
//
//   MnaMatrices m = assemble_mna(circuit);   // what the engines do, in two passes:
//     MnaPattern pattern(unknowns);            // unknowns excludes ground (index 0)
//     MnaStamp collect(pattern);               // collecting pass: records the entries
//     for each element: element.stamp(collect)
//     pattern.finalize();                      // builds the CSC structure
//     MnaStamp values(pattern, g, c);          // value pass: adds into g and c
//     for each element: element.stamp(values)
// Matrix rows and columns are unknown indices minus one. Entries in the ground row or column
// (index 0) are dropped, so stamps never test for ground. The elements keep no slots: the pattern
// maps an entry to its slot, so a Circuit is read, never written, by the engines.
#pragma once

#include <utility>
#include <vector>

namespace isolink {

class Circuit;

using Slot = int;  // index into a matrix value array; MnaPattern::trash() for ground entries

class MnaPattern {
 public:
  explicit MnaPattern(int unknowns) : n_(unknowns) {}

  // Collecting pass (before finalize): records entry (row, col), unknown indices, 0 = ground
  // (not recorded). Repeats are fine.
  void declare(int row, int col);
  void finalize();
  bool finalized() const { return finalized_; }
  // After finalize: the slot of a declared entry (row, col); trash() for ground. An entry that was
  // not declared has no slot: undefined (the elements declare what they stamp, by construction).
  Slot slot(int row, int col) const;

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

// Where Element::stamp writes G (conductance, S) and C (the d/dt terms: F, H) entries by unknown
// indices: on a collecting pattern it records them, on a finalized one it adds the values into g
// and c (value arrays of pattern.value_count() doubles, which it does not own).
class MnaStamp {
 public:
  explicit MnaStamp(MnaPattern& collecting) : collecting_(&collecting), pattern_(&collecting) {}
  MnaStamp(const MnaPattern& finalized, double* g, double* c)
      : pattern_(&finalized), g_(g), c_(c) {}

  void g(int row, int col, double value) { add(g_, row, col, value); }
  void c(int row, int col, double value) { add(c_, row, col, value); }

 private:
  void add(double* values, int row, int col, double value) {
    if (collecting_)
      collecting_->declare(row, col);
    else if (row > 0 && col > 0)
      values[pattern_->slot(row, col)] += value;
  }
  MnaPattern* collecting_ = nullptr;
  const MnaPattern* pattern_;
  double* g_ = nullptr;
  double* c_ = nullptr;
};

// A finalized circuit's pattern and its constant G and C over it (the floating-node ties,
// Circuit::kFloatingTie, included in G): what both engines and the AC analysis start from.
struct MnaMatrices {
  MnaPattern pattern{0};
  std::vector<double> g, c;  // pattern.value_count() values each
};
MnaMatrices assemble_mna(const Circuit& circuit);

}  // namespace isolink
