// KluSolver: SuiteSparse KLU over a fixed MNA pattern, numeric factorizations cached by key.
//
//   KluSolver klu;
//   klu.analyze(pattern);                        // symbolic analysis, once per circuit
//   if (!klu.select(key)) klu.factor(key, a);    // a: pattern.nonzeros() values of G + alpha C
//   klu.solve(x);                                // in place, x has pattern.size() entries
// The key identifies a matrix (the engines use alpha, the coefficient of C): when a step size
// comes back, its factorization is reused instead of refactored.
#pragma once

#include <list>
#include <memory>

#include "solver/mna.h"
#include "solver/status.h"

namespace isolink {

class KluSolver {
 public:
  static constexpr size_t kCacheSize = 24;

  KluSolver();
  ~KluSolver();
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  Status analyze(const MnaPattern& pattern);
  // Makes the factorization stored under key current; false when none is cached.
  bool select(double key);
  // Factors values (over the pattern) and stores it under key. On a singular matrix the error
  // names the column, and singular_column() gives it (0-based matrix index, unknown - 1).
  Status factor(double key, const double* values);
  // Solves A x = b in place with the current factorization.
  Status solve(double* x);
  int singular_column() const { return singular_col_; }

  int factorizations() const { return factorizations_; }  // numeric factorizations done
  int reuses() const { return reuses_; }                  // times select() found one cached

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int singular_col_ = -1;
  int factorizations_ = 0;
  int reuses_ = 0;
};

}  // namespace isolink
