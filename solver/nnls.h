// Non-negative least squares, for fits whose terms must stay passive (a ladder's R, L and C):
//
//   Eigen::VectorXd x = nnls(a, b);   // min |a x - b| subject to x >= 0
//   Eigen::VectorXd x = nnls_gram(a.transpose() * a, a.transpose() * b);   // the same
//
// Lawson and Hanson's active-set method (Solving Least Squares Problems, 1974, ch. 23), with the
// columns scaled to unit norm for conditioning. Used by the cable's skin and dielectric ladders
// (netlists/link/cable.cpp) and a measured line's (netlists/link/measured_line.cpp).
#pragma once

#include <Eigen/Dense>
#include <functional>

namespace isolink {

Eigen::VectorXd nnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);

// The same problem given by its normal equations, ata = A^T A and atb = A^T b (Bro and De Jong's
// fast NNLS, 1997): each active-set solve is a Cholesky factorisation of the passive columns'
// k x k Gram block, not a QR of the tall m x k matrix. For problems with many more rows than
// passive columns (the passivity enforcement's least-distance problem: thousands of rows, a few
// hundred active constraints); the condition number is the square of nnls'.
Eigen::VectorXd nnls_gram(const Eigen::MatrixXd& ata, const Eigen::VectorXd& atb);
// The same with A^T A given by its diagonal and its columns on demand (column(j) = A^T a_j): only
// the columns that enter the passive set are formed, for problems whose Gram matrix is too large
// to hold or form whole.
Eigen::VectorXd nnls_gram(const std::function<Eigen::VectorXd(int)>& column,
                          const Eigen::VectorXd& diagonal, const Eigen::VectorXd& atb);

}  // namespace isolink
