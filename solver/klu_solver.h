// KluSolver: SuiteSparse KLU over a fixed MNA pattern, numeric factorizations cached by key.
//
//   KluSolver klu;
//   klu.analyze(pattern);                        // symbolic analysis, once per circuit
//   if (!klu.select(key)) klu.factor(key, a);    // a: pattern.nonzeros() values of G + alpha C
//   klu.solve(x);                                // in place, x has pattern.size() entries
// The key identifies a matrix (the engines use alpha, the coefficient of C): when a step size
// comes back, its factorization is reused instead of refactored.
// Ownership: the solver copies the pattern's arrays at analyze() (the pattern need not outlive
// it) and owns every cached factorization (at most kCacheSize, least recently used dropped).
// Errors: analyze (no unknowns, KLU's symbolic analysis failed), factor (a singular matrix,
// naming the column; another KLU failure with its status), solve (no factorization selected).
//
// A transient step is one solve, so the solve is what counts, and for circuit matrices its time
// is set less by the number of entries than by the longest chain of dependent updates (each
// unknown waits for the ones it depends on). Two orderings are tried on the first matrix:
//   - KLU's default: BTF blocks, AMD inside them (least fill; on a cable ladder every unknown
//     then waits for the previous one: a chain of ~390 rows over L and U for 204 unknowns);
//   - METIS nested dissection (through CHOLMOD) of A + A', no BTF (a little more fill, a chain
//     of ~46 on the same ladder: the CPU overlaps independent rows).
// The first matrix should look like the later ones (the engines factor the DC matrix, whose
// pivots differ, with a separate Ordering::Colamd solver: at DC a voltage source's or an
// inductor's branch row has no diagonal, partial pivoting moves away from AMD's order, which
// assumed one, and COLAMD orders the columns for any row pivoting; a 64 m link's DC matrix,
// 3,009 unknowns, factored with 326k entries in 16 ms under AMD and 38k in 0.5 ms under COLAMD).
// The one with the lower modelled solve cost (off-diagonal entries + kChainWeight x chain length of
// L and U) is kept for the whole run. KLU factors (partial pivoting, row scaling); each
// factorization is then copied out (klu_extract) into row-oriented arrays: row permutation with the
// scaling folded in, strictly lower L, strictly upper U pre-divided by its diagonal, the
// off-diagonal BTF blocks, and the column permutation. solve() runs on those: no division and no
// per-column unpacking.
#pragma once

#include <memory>
#include <string>

#include "base/status.h"
#include "solver/mna.h"

namespace isolink {

class KluSolver {
 public:
  static constexpr size_t kCacheSize = 24;
  // Cost of one link of the dependency chain, in off-diagonal entries (latency of a load, a
  // multiply and a subtract against the throughput of independent ones; measured on x86-64).
  static constexpr double kChainWeight = 5.0;

  enum class Ordering { Auto, Amd, Colamd, NestedDissection };

  KluSolver();
  ~KluSolver();
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  // Auto picks on the first factorization (see above); Colamd is for matrices that pivot off
  // their diagonal (DC); the others force one (tests, benches).
  Status analyze(const MnaPattern& pattern, Ordering ordering = Ordering::Auto);
  // Makes the factorization stored under key current; false when none is cached.
  bool select(double key);
  // Factors values (over the pattern) and stores it under key. On a singular matrix the error
  // names the column, and singular_column() gives it (0-based matrix index, unknown - 1).
  Status factor(double key, const double* values);
  // Factors values into a slot of its own, outside the cache, and makes it current: for
  // matrices that do not come back (a Newton iteration's). Errors as factor().
  Status factor_once(const double* values);
  // Solves A x = b in place with the current factorization.
  Status solve(double* x);
  int singular_column() const { return singular_col_; }

  int factorizations() const { return factorizations_; }  // numeric factorizations done
  int reuses() const { return reuses_; }                  // times select() found one cached

  // About the current factorization, for benches and tests.
  struct Info {
    std::string ordering;  // "amd" or "nested dissection"
    long lu_nonzeros = 0;  // entries of L and U, diagonals included (as KLU counts them)
    long offdiagonal = 0;  // entries the solve multiplies (L, U and F off their diagonals)
    int chain = 0;         // longest chain of dependent rows, L and U together
    int blocks = 0;        // BTF blocks
  };
  Info info() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int singular_col_ = -1;
  int factorizations_ = 0;
  int reuses_ = 0;
};

}  // namespace isolink
