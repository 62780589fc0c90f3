// isolink compare's model and fit: the simulation at arbitrary times from the edge response, the
// spec with keys replaced (sweep's key-path setter), and the bounded least-squares fit (Ceres).
#include <ceres/ceres.h>
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <tuple>

#include "analysis/compare_model.h"
#include "analysis/sweep_spec.h"
#include "netlists/link/cards.h"

namespace isolink::analysis {
namespace compare_detail {

namespace {

// The edges from k on that sit a whole number of E's grid steps after edge k (the half bits of
// one frame do): their offsets in steps, and the index past the group.
size_t edge_group(const EdgeList& edges, size_t k, double dt, std::vector<long>& steps) {
  steps.assign(1, 0);
  size_t end = k + 1;
  for (; end < edges.t.size(); ++end) {
    const double x = (edges.t[end] - edges.t[k]) / dt, r = std::round(x);
    if (r < static_cast<double>(steps.back()) || std::abs(x - r) > 1e-6) break;
    steps.push_back(static_cast<long>(r));
  }
  return end;
}

}  // namespace

void synth_at(const EdgeResponse& e, const EdgeList& edges, double offset,
              std::span<const double> t, std::span<double> out) {
  std::fill(out.begin(), out.end(), e.v_idle);
  if (t.empty() || e.e.empty()) return;
  // Edges on one grid share E's interpolation weights, so each group is first summed on E's grid
  // (g, E taken as 0 before its record and e.back() after it), then g is interpolated at the
  // samples: one interpolation per sample and group instead of one per sample and edge.
  const double dt = e.dt;
  const double first = -static_cast<double>(e.pre) * dt;  // E's first sample, from the edge
  const long ne = static_cast<long>(e.e.size());
  std::vector<double> after(t.size() + 1, 0.0);  // g's last value from an index on
  std::vector<double> g, tail;
  std::vector<long> steps;
  for (size_t k = 0; k < edges.t.size();) {
    const size_t end = edge_group(edges, k, dt, steps);
    const long span = steps.back() + ne;
    g.assign(static_cast<size_t>(span), 0.0);
    tail.assign(static_cast<size_t>(span) + 1, 0.0);
    for (size_t q = k; q < end; ++q) {
      const double dl = edges.dl[q];
      double* gq = g.data() + steps[q - k];
      for (long j = 0; j < ne; ++j) gq[j] += dl * e.e[static_cast<size_t>(j)];
      tail[static_cast<size_t>(steps[q - k] + ne)] += dl * e.e.back();
    }
    double run = 0;
    for (size_t j = 0; j < g.size(); ++j) g[j] += (run += tail[j]);
    const double t0 = edges.t[k] + offset + first;
    auto lo = std::lower_bound(t.begin(), t.end(), t0);
    auto hi = std::upper_bound(t.begin(), t.end(), t0 + static_cast<double>(span - 1) * dt);
    for (auto it = lo; it < hi; ++it) {
      const double x = (*it - t0) / dt;
      const size_t i = static_cast<size_t>(x);
      const double f = x - static_cast<double>(i);
      const double y = i + 1 < g.size() ? g[i] + f * (g[i + 1] - g[i]) : g.back();
      out[static_cast<size_t>(it - t.begin())] += y;
    }
    after[static_cast<size_t>(hi - t.begin())] += g.back();
    k = end;
  }
  double run = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    run += after[i];
    out[i] += run;
  }
}

std::vector<std::string> key_paths(const std::string& key) {
  if (key.rfind("ends.", 0) == 0) return {"tx." + key.substr(5), "rx." + key.substr(5)};
  return {key};
}

LinkModel::LinkModel(std::string spec_text, std::string spec_path, const link::PartLibrary& parts,
                     link::Direction d, const link::ExpandOptions& expand)
    : text_(std::move(spec_text)), path_(std::move(spec_path)), parts_(parts), dir_(d) {
  wopt_.expand = expand;
}

StatusOr<std::shared_ptr<const EdgeResponse>> LinkModel::response(
    const std::vector<std::string>& keys, const std::vector<double>& values) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [k, v, e] : kept_)
      if (v == values && k == keys) return e;
  }
  std::vector<sweep::Assignment> assign;
  for (size_t i = 0; i < keys.size(); ++i)
    for (const std::string& path : key_paths(keys[i]))
      assign.push_back({path, fmt::format("{:.12g}", values[i]), true});
  StatusOr<link::LinkSpec> spec = sweep::spec_with(text_, path_, assign);
  if (!spec) return spec.status();
  WorstOptions wopt = wopt_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    wopt.reduced_start_points = start_points_;
  }
  StatusOr<EdgeResponse> e = edge_response(*spec, parts_, dir_, wopt);
  if (!e) return e.status();
  for (double x : e->e)
    if (!std::isfinite(x)) return Status::Error("the simulated edge response is not finite");
  ++evaluations_;
  auto kept = std::make_shared<const EdgeResponse>(std::move(*e));
  std::lock_guard<std::mutex> lock(mutex_);
  if (start_points_.empty()) start_points_ = kept->expansion_points;  // the design's, normally
  if (kept_.size() >= kKept) kept_.pop_front();
  kept_.push_back({keys, values, kept});
  return kept;
}

namespace {

// Residuals and their Jacobian by differences of each parameter's own step. The point and its
// neighbours are evaluated in parallel (oneTBB, `threads` at most; 0: all cores): a
// link fit's evaluation is a new edge response, and the columns are independent.
class CentralCost : public ceres::CostFunction {
 public:
  CentralCost(const ResidualFn& f, size_t m, const std::vector<LsqParam>& p, int threads)
      : f_(f), p_(p), arena_(threads > 0 ? threads : tbb::task_arena::automatic) {
    set_num_residuals(static_cast<int>(m));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(p.size()));
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const size_t n = p_.size(), m = static_cast<size_t>(num_residuals());
    const std::vector<double> xv(x[0], x[0] + n);
    const bool jac = jacobians && jacobians[0];
    // Point 0 is x; with the Jacobian, j + 1 is x + step_j e_j (forward), or 2j + 1 and 2j + 2
    // are x +/- step_j e_j (central).
    const size_t per = central_ ? 2 : 1;
    std::vector<std::vector<double>> xs(jac ? per * n + 1 : 1, xv), rs(xs.size());
    for (size_t j = 0; jac && j < n; ++j) {
      xs[per * j + 1][j] += p_[j].step;
      if (central_) xs[2 * j + 2][j] -= p_[j].step;
    }
    std::atomic<bool> ok{true};
    arena_.execute([&] {
      tbb::parallel_for(size_t{0}, xs.size(), [&](size_t k) {
        if (!call(xs[k], rs[k])) ok = false;
      });
    });
    if (!ok) return false;
    std::copy(rs[0].begin(), rs[0].end(), residuals);
    for (size_t j = 0; jac && j < n; ++j) {
      const std::vector<double>&rp = rs[per * j + 1], &rm = rs[central_ ? 2 * j + 2 : 0];
      const double h = static_cast<double>(per) * p_[j].step;
      for (size_t i = 0; i < m; ++i) jacobians[0][i * n + j] = (rp[i] - rm[i]) / h;
    }
    return true;
  }
  // Forward differences while the fit iterates (n new points per Jacobian: they steer the
  // search, whose residuals are exact, so the minimum found is the same to well under the
  // standard errors), central ones for the standard errors at the solution.
  void set_central(bool central) { central_ = central; }
  int evaluations() const { return evals_.load(); }
  Status last_error() const {
    std::lock_guard<std::mutex> lock(error_mutex_);
    return last_error_;
  }

 private:
  bool call(const std::vector<double>& x, std::vector<double>& r) const {
    ++evals_;
    r.clear();
    Status s = f_(x, r);
    if (!s.ok()) {
      std::lock_guard<std::mutex> lock(error_mutex_);
      last_error_ = s;
      return false;
    }
    return r.size() == static_cast<size_t>(num_residuals());
  }
  const ResidualFn& f_;
  const std::vector<LsqParam>& p_;
  bool central_ = false;
  mutable tbb::task_arena arena_;
  mutable std::atomic<int> evals_{0};
  mutable std::mutex error_mutex_;
  mutable Status last_error_;
};

// Standard errors and identifiability from the Jacobian at the solution.
void covariance(const Eigen::MatrixXd& J, double sse, LsqResult& out) {
  const Eigen::Index m = J.rows(), n = J.cols();
  Eigen::VectorXd norms = J.colwise().norm();
  Eigen::MatrixXd Js = J;
  for (Eigen::Index j = 0; j < n; ++j)
    if (norms(j) > 0) Js.col(j) /= norms(j);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  out.singular.assign(s.data(), s.data() + s.size());
  out.identifiable.assign(static_cast<size_t>(n), true);
  const double smax = s.size() ? s(0) : 0.0;
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    if (s(k) > 1e-3 * smax) continue;  // a direction the capture barely sees
    for (Eigen::Index j = 0; j < n; ++j)
      if (std::abs(svd.matrixV()(j, k)) > 0.2 || norms(j) == 0)
        out.identifiable[static_cast<size_t>(j)] = false;
  }
  for (Eigen::Index j = 0; j < n; ++j)
    if (norms(j) == 0) out.identifiable[static_cast<size_t>(j)] = false;
  const double sigma2 = m > n ? sse / static_cast<double>(m - n) : 0.0;
  // (J^T J)^+ in the scaled columns: V diag(1/s^2) V^T, small singular values dropped.
  Eigen::MatrixXd inv = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index k = 0; k < s.size(); ++k)
    if (s(k) > 1e-12 * smax)
      inv += svd.matrixV().col(k) * svd.matrixV().col(k).transpose() / (s(k) * s(k));
  out.stderr_x.assign(static_cast<size_t>(n), 0.0);
  for (Eigen::Index j = 0; j < n; ++j)
    if (norms(j) > 0)
      out.stderr_x[static_cast<size_t>(j)] = std::sqrt(sigma2 * inv(j, j)) / norms(j);
  // Correlation: the column scaling cancels, inv(i, j) / sqrt(inv(i, i) inv(j, j)).
  out.correlation.assign(static_cast<size_t>(n * n), 0.0);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const double d = inv(i, i) * inv(j, j);
      const double c = i == j ? 1.0 : d > 0 ? inv(i, j) / std::sqrt(d) : 0.0;
      out.correlation[static_cast<size_t>(i * n + j)] =
          std::isfinite(c) ? std::clamp(c, -1.0, 1.0) : 0.0;
    }
}

}  // namespace

}  // namespace compare_detail

StatusOr<LsqResult> fit_least_squares(const ResidualFn& f, size_t residuals,
                                      const std::vector<LsqParam>& params, int max_iterations,
                                      int threads) {
  namespace cd = compare_detail;
  LsqResult out;
  const size_t n = params.size();
  if (n == 0 || residuals < n) return Status::Error("a fit needs more residuals than parameters");
  for (const LsqParam& p : params)
    if (!(p.low <= p.initial && p.initial <= p.high && p.step > 0))
      return Status::Error(fmt::format("a fit parameter starts at {:g} outside [{:g}, {:g}]",
                                       p.initial, p.low, p.high));
  std::vector<double> x;
  for (const LsqParam& p : params) x.push_back(p.initial);
  auto* cost = new cd::CentralCost(f, residuals, params, threads);
  ceres::Problem problem;
  problem.AddResidualBlock(cost, nullptr, x.data());
  for (size_t j = 0; j < n; ++j) {
    problem.SetParameterLowerBound(x.data(), static_cast<int>(j), params[j].low);
    problem.SetParameterUpperBound(x.data(), static_cast<int>(j), params[j].high);
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.function_tolerance = 1e-6;
  so.parameter_tolerance = 1e-6;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!cost->last_error().ok() && summary.termination_type == ceres::FAILURE)
    return cost->last_error();
  if (summary.termination_type == ceres::FAILURE)
    return Status::Error("the fit failed: " + summary.message);
  out.x = x;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.report = summary.BriefReport();
  // The Jacobian at the solution, for the standard errors.
  std::vector<double> r(residuals), jac(residuals * n);
  double* jp = jac.data();
  const double* xp = x.data();
  cost->set_central(true);
  if (!cost->Evaluate(&xp, r.data(), &jp))
    return cost->last_error().ok() ? Status::Error("the fit's model failed at its solution")
                                   : cost->last_error();
  out.evaluations = cost->evaluations();
  out.sse = 0;
  out.max_abs_residual = 0;
  for (double v : r) {
    out.sse += v * v;
    out.max_abs_residual = std::max(out.max_abs_residual, std::abs(v));
  }
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
      jac.data(), static_cast<Eigen::Index>(residuals), static_cast<Eigen::Index>(n));
  cd::covariance(J, out.sse, out);
  return out;
}

}  // namespace isolink::analysis
