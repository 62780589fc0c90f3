// AC small-signal analysis: the phasor response of a linear circuit to one source driven with a
// unit amplitude, every other source set to zero (V sources short, I sources open).
//
//   Circuit c;  ...add cards...;  c.finalize();
//   StatusOr<AcAnalysis> ac = AcAnalysis::create(c);              // pattern and LU analysis once
//   StatusOr<AcSolution> x = ac->solve("vin", 1e6);               // 1 V (or 1 A) at 1 MHz
//   std::complex<double> v = x->voltage(probe);                   // a Probe from parse_probe
// Solves (G + j 2 pi f C) x = b with KLU's complex LU; the G and C stamps are the ones the
// transient engine uses, floating nodes tied as there. Used for impedances, attenuation and
// filter responses (cable and part-library checks), not for time-domain results.
//
// Ordering: MNA's branch unknowns (voltage sources, inductors) have a zero or, below an
// inductor's corner, a small diagonal, and pivoting trades it for a node's row. Each is paired
// with a node of its element up front (the +-1s of KCL and of the branch equation as the
// diagonal) and the swapped pattern ordered by AMD; COLAMD on the unswapped one is the
// alternative, and the first factorization keeps whichever needs fewer flops. A 12 m link's LU
// took 55.7k flops under COLAMD, 16-20k paired (bench/README.md).
// Accuracy: each factor() solves a probe right-hand side and measures its normwise backward
// error. Over 1e-11 (a stable LU leaves about n eps), the matrix is factored again with fresh
// pivots at KLU's strict threshold (0.1, kept for the analysis's later factorizations); if even
// that leaves more, every solve of that factorization takes up to three steps of iterative
// refinement. Reusing the previous frequency's pivots left a residual of 0.61 of the right-hand
// side on a common-mode choke's coupled windings at 614-719 MHz (bench/README.md, "Stress").
// Units: frequencies in Hz; solutions in V (nodes) and A (branches) per unit source amplitude.
// Lifetime: the analysis keeps a pointer to the circuit (names, sources): the circuit must
// outlive it. It owns its pattern, stamps and KLU factorization; moving it is cheap.
// Errors: create (no unknowns, KLU's symbolic analysis failed), factor (a negative or non-finite
// frequency, a singular matrix with KLU's status), solve / add_excitation (no such source, or not
// a V or I source). solve_factored and solve_transposed need a successful factor() first.
#pragma once

#include <complex>
#include <memory>
#include <string>
#include <vector>

#include "base/status.h"
#include "solver/circuit.h"
#include "solver/probe.h"

namespace isolink {

struct AcSolution {
  double frequency = 0;                 // Hz
  std::vector<std::complex<double>> x;  // per unknown; x[0] is ground (0)
  std::complex<double> voltage(const Probe& p) const { return x[p.a] - x[p.b]; }
};

// The LU's fill-reducing ordering (header: Ordering). kCheaper: both, the first factorization
// keeps the one with fewer flops; the others force one (tests, bench).
enum class AcOrdering { kCheaper, kPaired, kColamd };

class AcAnalysis {
 public:
  // The circuit must be finalized and outlive the analysis.
  static StatusOr<AcAnalysis> create(const Circuit& circuit,
                                     AcOrdering ordering = AcOrdering::kCheaper);
  AcAnalysis(AcAnalysis&&) noexcept;
  AcAnalysis& operator=(AcAnalysis&&) noexcept;
  ~AcAnalysis();

  // Drives the named V or I source (lower case) with amplitude 1 at frequency f (Hz, >= 0).
  StatusOr<AcSolution> solve(const std::string& source, double frequency);

  // Several right-hand sides on one factorization (noise analysis: sources driven together,
  // adjoint sensitivities). Vectors are indexed by unknown, [0] being ground (ignored in b, 0 in
  // the result).
  using Vector = std::vector<std::complex<double>>;
  // Factors G + j 2 pi f C at f (Hz, >= 0); the solves below reuse it until the next factor().
  Status factor(double frequency);
  double factored_frequency() const;
  // KLU's flop count of the current factorization (0 before the first), and the ordering in use
  // (header: "paired AMD" or "COLAMD"; under kCheaper, decided by the first factor()).
  double factor_flops() const;
  const char* ordering_name() const;
  // x with A x = b.
  Vector solve_factored(const Vector& b) const;
  // z with A^T z = c: for an output c.x, a change dA of the matrix moves it by -z^T dA x.
  Vector solve_transposed(const Vector& c) const;
  // Adds amplitude times the named V or I source's unit excitation into b (size unknowns + 1).
  Status add_excitation(const std::string& source, std::complex<double> amplitude, Vector& b) const;
  // The stamps: A = G + j w C, values in the pattern's CSC order (col_start, row_index, both
  // over unknowns - 1, i.e. without ground).
  const std::vector<double>& g_values() const;
  const std::vector<double>& c_values() const;
  const std::vector<int>& col_start() const;
  const std::vector<int>& row_index() const;

 private:
  AcAnalysis();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace isolink
