#include "solver/nnls.h"

#include <algorithm>
#include <cmath>
#include <functional>
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

Eigen::VectorXd nnls_gram(const std::function<Eigen::VectorXd(int)>& column,
                          const Eigen::VectorXd& diagonal, const Eigen::VectorXd& atb) {
  const int n = static_cast<int>(atb.size());
  // Scaled to a unit diagonal, as nnls scales its columns.
  Eigen::VectorXd scale(n);
  for (int j = 0; j < n; ++j) scale[j] = diagonal[j] > 0 ? std::sqrt(diagonal[j]) : 1.0;
  const Eigen::VectorXd c = atb.cwiseQuotient(scale);
  std::vector<Eigen::VectorXd> g(n);  // the scaled columns fetched, those that were ever passive
  auto col = [&](int j) -> const Eigen::VectorXd& {
    if (g[j].size() == 0) g[j] = column(j).cwiseQuotient(scale) / scale[j];
    return g[j];
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(n, false), dropped(n, false);
  const double tol = 1e-12 * std::max(1.0, c.cwiseAbs().maxCoeff());
  auto passive_set = [&] {
    std::vector<int> idx;
    for (int j = 0; j < n; ++j)
      if (passive[j]) idx.push_back(j);
    return idx;
  };
  auto solve_passive = [&](Eigen::VectorXd& s) {
    const std::vector<int> idx = passive_set();
    const int k = static_cast<int>(idx.size());
    Eigen::MatrixXd gp(k, k);
    Eigen::VectorXd cp(k);
    for (int b = 0; b < k; ++b) {
      cp[b] = c[idx[b]];
      for (int a = 0; a < k; ++a) gp(a, b) = col(idx[b])[idx[a]];
    }
    gp.diagonal().array() += 1e-13;  // a ridge below rounding: two alike columns stay solvable
    const Eigen::VectorXd sp = Eigen::LDLT<Eigen::MatrixXd>(gp).solve(cp);
    s.setZero(n);
    for (int a = 0; a < k; ++a) s[idx[a]] = sp[a];
  };
  for (int outer = 0; outer < 3 * n; ++outer) {
    Eigen::VectorXd w = c;  // the gradient, c - G x, from the passive columns alone
    for (int j : passive_set()) w -= x[j] * col(j);
    int best = -1;
    for (int j = 0; j < n; ++j)
      if (!passive[j] && !dropped[j] && w[j] > tol && (best < 0 || w[j] > w[best])) best = j;
    if (best < 0) break;
    passive[best] = true;
    for (int inner = 0; inner < 3 * n; ++inner) {
      Eigen::VectorXd s;
      solve_passive(s);
      if (!s.allFinite()) {  // a singular passive block: the column just added adds nothing
        passive[best] = false, dropped[best] = true;
        break;
      }
      bool feasible = true;
      for (int j = 0; j < n && feasible; ++j)
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
  return x.cwiseQuotient(scale);
}

Eigen::VectorXd nnls_gram(const Eigen::MatrixXd& ata, const Eigen::VectorXd& atb) {
  return nnls_gram([&](int j) { return Eigen::VectorXd(ata.col(j)); }, ata.diagonal(), atb);
}

}  // namespace isolink
