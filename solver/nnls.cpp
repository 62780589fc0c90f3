#include "solver/nnls.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace isolink {
namespace {

// Lawson and Hanson's active-set loop over n unknowns, shared by both forms: `gradient(x,
// passive)` is A^T (b - A x) (of the scaled problem), `solve(idx)` the unconstrained least
// squares on the passive columns idx. A passive solve that is not finite (a singular block) drops
// the column just added for good.
using Gradient = std::function<Eigen::VectorXd(const Eigen::VectorXd&, const std::vector<int>&)>;
using PassiveSolve = std::function<Eigen::VectorXd(const std::vector<int>&)>;

Eigen::VectorXd lawson_hanson(int n, double tol, const Gradient& gradient,
                              const PassiveSolve& solve) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(n, false), dropped(n, false);
  auto passive_set = [&] {
    std::vector<int> idx;
    for (int j = 0; j < n; ++j)
      if (passive[j]) idx.push_back(j);
    return idx;
  };
  for (int outer = 0; outer < 3 * n; ++outer) {
    const Eigen::VectorXd w = gradient(x, passive_set());
    int best = -1;
    for (int j = 0; j < n; ++j)
      if (!passive[j] && !dropped[j] && w[j] > tol && (best < 0 || w[j] > w[best])) best = j;
    if (best < 0) break;
    passive[best] = true;
    for (int inner = 0; inner < 3 * n; ++inner) {
      const std::vector<int> idx = passive_set();
      const Eigen::VectorXd sp = solve(idx);
      if (!sp.allFinite()) {
        passive[best] = false, dropped[best] = true;
        break;
      }
      Eigen::VectorXd s = Eigen::VectorXd::Zero(n);
      for (size_t k = 0; k < idx.size(); ++k) s[idx[k]] = sp[static_cast<Eigen::Index>(k)];
      bool feasible = true;
      for (int j : idx)
        if (s[j] <= 0) feasible = false;
      if (feasible) {
        x = s;
        break;
      }
      double alpha = 1.0;
      for (int j : idx)
        if (s[j] <= 0) alpha = std::min(alpha, x[j] / (x[j] - s[j]));
      x += alpha * (s - x);
      for (int j : idx)
        if (x[j] <= 1e-15) passive[j] = false, x[j] = 0;
    }
  }
  return x;
}

}  // namespace

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
  const Eigen::VectorXd x = lawson_hanson(
      n, 1e-12 * std::max(1.0, b.norm()),
      [&](const Eigen::VectorXd& at, const std::vector<int>&) -> Eigen::VectorXd {
        return a.transpose() * (b - a * at);
      },
      [&](const std::vector<int>& idx) -> Eigen::VectorXd {
        Eigen::MatrixXd ap(a.rows(), static_cast<Eigen::Index>(idx.size()));
        for (size_t k = 0; k < idx.size(); ++k)
          ap.col(static_cast<Eigen::Index>(k)) = a.col(idx[k]);
        return ap.colPivHouseholderQr().solve(b);
      });
  return x.cwiseQuotient(scale);
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
  const Eigen::VectorXd x = lawson_hanson(
      n, 1e-12 * std::max(1.0, c.cwiseAbs().maxCoeff()),
      // c - G x, from the passive columns alone
      [&](const Eigen::VectorXd& at, const std::vector<int>& idx) -> Eigen::VectorXd {
        Eigen::VectorXd w = c;
        for (int j : idx) w -= at[j] * col(j);
        return w;
      },
      [&](const std::vector<int>& idx) -> Eigen::VectorXd {
        const int k = static_cast<int>(idx.size());
        Eigen::MatrixXd gp(k, k);
        Eigen::VectorXd cp(k);
        for (int b = 0; b < k; ++b) {
          cp[b] = c[idx[b]];
          for (int a = 0; a < k; ++a) gp(a, b) = col(idx[b])[idx[a]];
        }
        gp.diagonal().array() += 1e-13;  // a ridge below rounding: two alike columns stay solvable
        return Eigen::LDLT<Eigen::MatrixXd>(gp).solve(cp);
      });
  return x.cwiseQuotient(scale);
}

Eigen::VectorXd nnls_gram(const Eigen::MatrixXd& ata, const Eigen::VectorXd& atb) {
  return nnls_gram([&](int j) { return Eigen::VectorXd(ata.col(j)); }, ata.diagonal(), atb);
}

}  // namespace isolink
