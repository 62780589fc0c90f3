#include "solver/nnls.h"

#include <algorithm>
#include <vector>

namespace isolink {

Eigen::VectorXd nnls(const Eigen::MatrixXd& a_in, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(a_in.cols());
  // Column scaling for conditioning.
  Eigen::VectorXd scale(n);
  Eigen::MatrixXd a = a_in;
  for (int j = 0; j < n; ++j) {
    const double s = a.col(j).norm();
    scale[j] = s > 0 ? s : 1.0;
    a.col(j) /= scale[j];
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(n, false);
  const double tol = 1e-12 * std::max(1.0, b.norm());
  auto solve_passive = [&](Eigen::VectorXd& s) {
    std::vector<int> idx;
    for (int j = 0; j < n; ++j)
      if (passive[j]) idx.push_back(j);
    Eigen::MatrixXd ap(a.rows(), static_cast<Eigen::Index>(idx.size()));
    for (size_t k = 0; k < idx.size(); ++k) ap.col(static_cast<Eigen::Index>(k)) = a.col(idx[k]);
    Eigen::VectorXd sp = ap.colPivHouseholderQr().solve(b);
    s.setZero(n);
    for (size_t k = 0; k < idx.size(); ++k) s[idx[k]] = sp[static_cast<Eigen::Index>(k)];
  };
  for (int outer = 0; outer < 3 * n; ++outer) {
    Eigen::VectorXd w = a.transpose() * (b - a * x);
    int best = -1;
    for (int j = 0; j < n; ++j)
      if (!passive[j] && w[j] > tol && (best < 0 || w[j] > w[best])) best = j;
    if (best < 0) break;
    passive[best] = true;
    for (int inner = 0; inner < 3 * n; ++inner) {
      Eigen::VectorXd s;
      solve_passive(s);
      bool feasible = true;
      for (int j = 0; j < n; ++j)
        if (passive[j] && s[j] <= 0) feasible = false;
      if (feasible) {
        x = s;
        break;
      }
      double alpha = 1.0;
      for (int j = 0; j < n; ++j)
        if (passive[j] && s[j] <= 0) alpha = std::min(alpha, x[j] / (x[j] - s[j]));
      x += alpha * (s - x);
      for (int j = 0; j < n; ++j)
        if (passive[j] && x[j] <= 1e-15) passive[j] = false, x[j] = 0;
    }
  }
  for (int j = 0; j < n; ++j) x[j] /= scale[j];
  return x;
}

}  // namespace isolink
