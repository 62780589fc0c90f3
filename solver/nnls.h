// Non-negative least squares, for fits whose terms must stay passive (a ladder's R, L and C):
//
//   Eigen::VectorXd x = nnls(a, b);   // min |a x - b| subject to x >= 0
//
// Lawson and Hanson's active-set method (Solving Least Squares Problems, 1974, ch. 23), with the
// columns scaled to unit norm for conditioning. Used by the cable's skin and dielectric ladders
// (netlists/link/cable.cpp) and a measured line's (netlists/link/measured_line.cpp).
#pragma once

#include <Eigen/Dense>

namespace isolink {

Eigen::VectorXd nnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b);

}  // namespace isolink
