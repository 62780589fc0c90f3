// The transfer of a small dense descriptor system, H(s) = L (G + s C)^-1 B, at many frequencies
// without its eigen-decomposition: the reduced model's search (solver/reduced_model.cpp) measures
// each intermediate projection this way and diagonalises only the one it accepts.
//
// Method (Laub, "Efficient multivariable frequency response computations", IEEE TAC 1981): with
// A = G + sigma C regular (sigma real), M = A^-1 C and H(s) = L (I + (s - sigma) M)^-1 A^-1 B.
// M = Q T Q' with T upper Hessenberg and Q orthogonal (one O(q^3) reduction, about a tenth of a
// real eigen-decomposition's work), so H(s) = (L Q) (I + (s - sigma) T)^-1 (Q' A^-1 B): one
// O(q^2) Hessenberg solve (Gaussian elimination, partial pivoting between neighbouring rows:
// backward stable) per source and frequency.
//
//   HessenbergTransfer h;
//   Status s = h.set(gr, cr, br, lr, sigma);   // q x q, q x q, q x nk, np x q
//   Eigen::MatrixXcd x = h.at({0, w});          // nk x np: H_kp(j w)
#pragma once

#include <Eigen/Dense>
#include <complex>
#include <vector>

#include "base/status.h"
#include "solver/dense_lapack.h"

namespace isolink {

// The shift-and-invert form both the Hessenberg transfer and the reduced model's modal form
// start from: M = (G + sigma C)^-1 C and AB = (G + sigma C)^-1 B. Error: G + sigma C singular (a
// non-finite result).
struct ShiftInvert {
  Eigen::MatrixXd m, ab;
};
StatusOr<ShiftInvert> shift_invert(const Eigen::MatrixXd& g, const Eigen::MatrixXd& c,
                                   const Eigen::MatrixXd& b, double sigma);

class HessenbergTransfer {
 public:
  // Takes the system (copies what it needs; the arguments need not outlive it). Errors: G +
  // sigma C singular or the system not finite. q = 0 is allowed: H = 0.
  Status set(const Eigen::MatrixXd& g, const Eigen::MatrixXd& c, const Eigen::MatrixXd& b,
             const Eigen::MatrixXd& l, double sigma);
  // H(s) as an nk x np matrix (element (k, p): source k to probe p). Thread-safe: the work
  // arrays are each thread's own (kept between calls, so that repeated calls allocate nothing).
  Eigen::MatrixXcd at(std::complex<double> s) const;
  // The system's modes from its Hessenberg form (modal_split of T, Q'A^-1B and LQ: the same
  // split as of M, A^-1 B and L, without reducing M again): their values are the eigenvalues of
  // M, poles sigma - 1 / lambda.
  StatusOr<ModalSplit> modes(double relative, double absolute) const;

 private:
  // The two ways through (I + z T), z = s - sigma: one solve per probe with the transposed
  // matrix, or one per source; at() takes the one with fewer right-hand sides.
  Eigen::MatrixXcd at_by_probes(double zr, double zi) const;
  Eigen::MatrixXcd at_by_sources(double zr, double zi) const;

  int q_ = 0;
  double sigma_ = 0;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> t_;  // q x q, Hessenberg
  Eigen::MatrixXd lq_;                                                        // np x q: L Q
  Eigen::MatrixXd qab_;                                                       // q x nk: Q' A^-1 B
};

}  // namespace isolink
