#include "solver/klu_solver.h"

#include <klu.h>

#include <vector>

namespace isolink {

struct KluSolver::Impl {
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  std::vector<int> ap, ai;
  int n = 0;
  struct Entry {
    double key;
    klu_numeric* numeric;
  };
  std::list<Entry> cache;  // most recently used first
  klu_numeric* current = nullptr;

  void free_numeric(klu_numeric* num) { klu_free_numeric(&num, &common); }
  ~Impl() {
    for (auto& e : cache) free_numeric(e.numeric);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
};

KluSolver::KluSolver() : impl_(std::make_unique<Impl>()) { klu_defaults(&impl_->common); }
KluSolver::~KluSolver() = default;

Status KluSolver::analyze(const MnaPattern& pattern) {
  impl_->n = pattern.size();
  impl_->ap = pattern.col_start();
  impl_->ai = pattern.row_index();
  if (impl_->n == 0) return Status::Error("circuit has no unknowns");
  impl_->symbolic = klu_analyze(impl_->n, impl_->ap.data(), impl_->ai.data(), &impl_->common);
  if (!impl_->symbolic) return Status::Error("KLU symbolic analysis failed");
  return Status::Ok();
}

bool KluSolver::select(double key) {
  auto& cache = impl_->cache;
  for (auto it = cache.begin(); it != cache.end(); ++it) {
    if (it->key == key) {
      cache.splice(cache.begin(), cache, it);
      impl_->current = it->numeric;
      ++reuses_;
      return true;
    }
  }
  return false;
}

Status KluSolver::factor(double key, const double* values) {
  singular_col_ = -1;
  klu_numeric* num = klu_factor(impl_->ap.data(), impl_->ai.data(), const_cast<double*>(values),
                                impl_->symbolic, &impl_->common);
  if (!num || impl_->common.status == KLU_SINGULAR) {
    singular_col_ = impl_->common.singular_col;
    if (num) impl_->free_numeric(num);
    impl_->current = nullptr;
    return Status::Error("singular matrix at column " + std::to_string(singular_col_));
  }
  ++factorizations_;
  auto& cache = impl_->cache;
  cache.push_front({key, num});
  if (cache.size() > kCacheSize) {
    impl_->free_numeric(cache.back().numeric);
    cache.pop_back();
  }
  impl_->current = num;
  return Status::Ok();
}

Status KluSolver::solve(double* x) {
  if (!impl_->current) return Status::Error("no factorization selected");
  if (!klu_solve(impl_->symbolic, impl_->current, impl_->n, 1, x, &impl_->common))
    return Status::Error("KLU solve failed");
  return Status::Ok();
}

}  // namespace isolink
