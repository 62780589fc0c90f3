#include "solver/klu_solver.h"

#include <cholmod.h>
#include <klu.h>

#include <algorithm>
#include <limits>
#include <list>
#include <utility>
#include <vector>

namespace isolink {

namespace {

// Row-oriented copy of one numeric factorization: P (R \ A) Q = L U + F with L unit lower and U
// upper inside each BTF block, F the entries above the diagonal blocks.
struct Factors {
  double key = 0;
  std::vector<int> row_perm;      // P: row k of the factored matrix is row row_perm[k] of A
  std::vector<double> row_scale;  // 1 / (KLU's scale factor of that row)
  std::vector<int> col_perm;      // Q: x[col_perm[k]] = y[k]
  std::vector<int> blocks;        // BTF block boundaries, nblocks + 1
  std::vector<int> lp, lj;        // strictly lower L, by rows
  std::vector<double> lx;
  std::vector<int> up, uj;  // strictly upper U divided by its diagonal, by rows
  std::vector<double> ux;
  std::vector<double> udiag_inv;  // 1 / U(k, k)
  std::vector<int> fp, fj;        // F by rows (empty with one block)
  std::vector<double> fx;
  long lu_nonzeros = 0;
  int chain = 0;

  long offdiagonal() const { return static_cast<long>(lx.size() + ux.size() + fx.size()); }
  double cost() const {
    return static_cast<double>(offdiagonal()) + KluSolver::kChainWeight * chain;
  }
};

// Transposes column-compressed (p, i, x) into rows (rp, rj, rx), dropping the diagonal and
// multiplying row r by row_factor[r] when given.
void to_rows(int n, const std::vector<int>& p, const std::vector<int>& i,
             const std::vector<double>& x, const std::vector<double>* row_factor,
             std::vector<int>& rp, std::vector<int>& rj, std::vector<double>& rx) {
  rp.assign(n + 1, 0);
  for (int col = 0; col < n; ++col)
    for (int k = p[col]; k < p[col + 1]; ++k)
      if (i[k] != col) ++rp[i[k] + 1];
  for (int r = 0; r < n; ++r) rp[r + 1] += rp[r];
  rj.assign(rp[n], 0);
  rx.assign(rp[n], 0.0);
  std::vector<int> next(rp.begin(), rp.end() - 1);
  for (int col = 0; col < n; ++col)
    for (int k = p[col]; k < p[col + 1]; ++k) {
      const int r = i[k];
      if (r == col) continue;
      rj[next[r]] = col;
      rx[next[r]++] = row_factor ? x[k] * (*row_factor)[r] : x[k];
    }
}

// Longest chain of dependent rows: forward through L, then backward through U.
int chain_length(const Factors& f, int n) {
  std::vector<int> depth(n, 0);
  int longest_l = 0, longest_u = 0;
  for (int r = 0; r < n; ++r) {
    int d = 0;
    for (int k = f.lp[r]; k < f.lp[r + 1]; ++k) d = std::max(d, depth[f.lj[k]]);
    depth[r] = d + 1;
    longest_l = std::max(longest_l, d + 1);
  }
  std::fill(depth.begin(), depth.end(), 0);
  for (int r = n - 1; r >= 0; --r) {
    int d = 0;
    for (int k = f.up[r]; k < f.up[r + 1]; ++k) d = std::max(d, depth[f.uj[k]]);
    depth[r] = d + 1;
    longest_u = std::max(longest_u, d + 1);
  }
  return longest_l + longest_u;
}

// Copies a KLU factorization into f; false when KLU cannot extract it.
bool extract(klu_common& common, klu_symbolic* symbolic, klu_numeric* num, int n, Factors& f) {
  const int lnz = num->lnz, unz = num->unz, nzoff = num->nzoff, nb = symbolic->nblocks;
  std::vector<int> Lp(n + 1), Li(lnz), Up(n + 1), Ui(unz), Fp(n + 1), Fi(std::max(nzoff, 1)), P(n),
      Q(n), R(nb + 1);
  std::vector<double> Lx(lnz), Ux(unz), Fx(std::max(nzoff, 1)), Rs(n);
  if (!klu_extract(num, symbolic, Lp.data(), Li.data(), Lx.data(), Up.data(), Ui.data(), Ux.data(),
                   Fp.data(), Fi.data(), Fx.data(), P.data(), Q.data(), Rs.data(), R.data(),
                   &common))
    return false;
  f.row_perm = P;
  f.col_perm = Q;
  f.blocks = R;
  f.row_scale.resize(n);
  for (int k = 0; k < n; ++k) f.row_scale[k] = 1.0 / Rs[k];  // KLU keeps Rs in pivot order
  f.udiag_inv.assign(n, 0.0);
  for (int col = 0; col < n; ++col)
    for (int k = Up[col]; k < Up[col + 1]; ++k)
      if (Ui[k] == col) f.udiag_inv[col] = 1.0 / Ux[k];
  to_rows(n, Lp, Li, Lx, nullptr, f.lp, f.lj, f.lx);
  to_rows(n, Up, Ui, Ux, &f.udiag_inv, f.up, f.uj, f.ux);
  if (nzoff > 0) {
    to_rows(n, Fp, Fi, Fx, nullptr, f.fp, f.fj, f.fx);
  } else {
    f.fp.clear(), f.fj.clear(), f.fx.clear();
  }
  f.lu_nonzeros = static_cast<long>(lnz) + unz;
  f.chain = chain_length(f, n);
  return true;
}

// METIS nested dissection of the pattern of A + A' (through CHOLMOD); empty on failure.
std::vector<int> nested_dissection(int n, const std::vector<int>& ap, const std::vector<int>& ai) {
  // Upper triangle of A + A', by columns, diagonal included.
  std::vector<std::pair<int, int>> entries;  // (col, row), row <= col
  entries.reserve(ai.size() + n);
  for (int col = 0; col < n; ++col) {
    entries.emplace_back(col, col);
    for (int k = ap[col]; k < ap[col + 1]; ++k)
      entries.emplace_back(std::max(col, ai[k]), std::min(col, ai[k]));
  }
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());

  std::vector<int> perm(n);
  cholmod_common cc;
  cholmod_start(&cc);
  cc.print = 0;
  cholmod_sparse* s = cholmod_allocate_sparse(n, n, entries.size(), /*sorted=*/1, /*packed=*/1,
                                              /*stype=*/1, CHOLMOD_PATTERN, &cc);
  bool ok = s != nullptr;
  if (ok) {
    int* sp = static_cast<int*>(s->p);
    int* si = static_cast<int*>(s->i);
    std::fill(sp, sp + n + 1, 0);
    for (size_t k = 0; k < entries.size(); ++k) {
      ++sp[entries[k].first + 1];
      si[k] = entries[k].second;
    }
    for (int col = 0; col < n; ++col) sp[col + 1] += sp[col];
    ok = cholmod_metis(s, nullptr, 0, /*postorder=*/1, perm.data(), &cc) != 0;
    cholmod_free_sparse(&s, &cc);
  }
  cholmod_finish(&cc);
  if (!ok) return {};
  return perm;
}

}  // namespace

struct KluSolver::Impl {
  klu_common common;
  std::vector<int> ap, ai;
  int n = 0;
  klu_symbolic* symbolic = nullptr;   // the ordering in use
  klu_symbolic* candidate = nullptr;  // nested dissection, until the first factorization decides
  const char* ordering = "amd";
  std::list<Factors> cache;  // most recently used first
  Factors scratch;           // factor_once's: outside the cache
  const Factors* current = nullptr;
  std::vector<double> y;   // solve workspace
  std::vector<double> ax;  // the values being factored: KLU's C interface takes double*

  ~Impl() {
    if (symbolic) klu_free_symbolic(&symbolic, &common);
    if (candidate) klu_free_symbolic(&candidate, &common);
  }

  klu_symbolic* analyze_nested_dissection() {
    std::vector<int> perm = nested_dissection(n, ap, ai);
    if (perm.empty()) return nullptr;
    const int btf = common.btf;
    common.btf = 0;  // the dissection already orders the whole matrix
    klu_symbolic* s = klu_analyze_given(n, ap.data(), ai.data(), perm.data(), perm.data(), &common);
    common.btf = btf;
    return s;
  }

  // Factors with sym and copies the result into f. False when KLU fails (status in common).
  bool factor_into(klu_symbolic* sym, const double* values, Factors& f) {
    ax.assign(values, values + ap[n]);
    klu_numeric* num = klu_factor(ap.data(), ai.data(), ax.data(), sym, &common);
    if (!num) return false;
    if (common.status == KLU_SINGULAR) {
      klu_free_numeric(&num, &common);
      return false;
    }
    const bool ok = extract(common, sym, num, n, f);
    klu_free_numeric(&num, &common);
    return ok;
  }

  // Factors with the ordering in use into f; on the first factorization also with the candidate
  // ordering, keeping whichever solves faster (modelled), for good.
  Status factor_choosing(Factors& f, const double* values, int* singular_col) {
    *singular_col = -1;
    if (!factor_into(symbolic, values, f)) {
      if (common.status == KLU_SINGULAR) {
        *singular_col = common.singular_col;
        return Status::Error("singular matrix at column " + std::to_string(*singular_col));
      }
      return Status::Error("KLU factorization failed (status " + std::to_string(common.status) +
                           ")");
    }
    if (candidate) {
      Factors g;
      if (factor_into(candidate, values, g) && g.cost() < f.cost()) {
        std::swap(symbolic, candidate);
        ordering = "nested dissection";
        f = std::move(g);
      }
      klu_free_symbolic(&candidate, &common);
      candidate = nullptr;
    }
    return Status::Ok();
  }
};

KluSolver::KluSolver() : impl_(std::make_unique<Impl>()) {
  klu_defaults(&impl_->common);
}
KluSolver::~KluSolver() = default;

Status KluSolver::analyze(const MnaPattern& pattern, Ordering ordering) {
  Impl& m = *impl_;
  m.n = pattern.size();
  m.ap = pattern.col_start();
  m.ai = pattern.row_index();
  if (m.n == 0) return Status::Error("circuit has no unknowns");
  m.y.assign(m.n, 0.0);
  if (ordering == Ordering::NestedDissection) {
    m.symbolic = m.analyze_nested_dissection();
    m.ordering = "nested dissection";
    if (!m.symbolic) return Status::Error("KLU symbolic analysis (nested dissection) failed");
    return Status::Ok();
  }
  if (ordering == Ordering::Colamd) {
    const int kept = m.common.ordering;
    m.common.ordering = 1;  // COLAMD
    m.symbolic = klu_analyze(m.n, m.ap.data(), m.ai.data(), &m.common);
    m.common.ordering = kept;
    m.ordering = "colamd";
    if (!m.symbolic) return Status::Error("KLU symbolic analysis (COLAMD) failed");
    return Status::Ok();
  }
  m.symbolic = klu_analyze(m.n, m.ap.data(), m.ai.data(), &m.common);
  m.ordering = "amd";
  if (!m.symbolic) return Status::Error("KLU symbolic analysis failed");
  // A dissection cannot shorten a chain of a few rows: only worth trying on larger circuits.
  if (ordering == Ordering::Auto && m.n >= 32) m.candidate = m.analyze_nested_dissection();
  return Status::Ok();
}

bool KluSolver::select(double key) {
  Impl& m = *impl_;
  if (m.current && m.current->key == key) {
    ++reuses_;
    return true;
  }
  for (auto it = m.cache.begin(); it != m.cache.end(); ++it) {
    if (it->key == key) {
      m.cache.splice(m.cache.begin(), m.cache, it);
      m.current = &m.cache.front();
      ++reuses_;
      return true;
    }
  }
  return false;
}

Status KluSolver::factor(double key, const double* values) {
  Impl& m = *impl_;
  m.current = nullptr;
  // Storage: a new entry, or the least recently used one once the cache is full.
  if (m.cache.size() >= kCacheSize)
    m.cache.splice(m.cache.begin(), m.cache, std::prev(m.cache.end()));
  else
    m.cache.emplace_front();
  Factors& f = m.cache.front();
  if (Status s = m.factor_choosing(f, values, &singular_col_); !s.ok()) {
    m.cache.pop_front();
    return s;
  }
  f.key = key;
  ++factorizations_;
  m.current = &f;
  return Status::Ok();
}

Status KluSolver::factor_once(const double* values) {
  Impl& m = *impl_;
  m.current = nullptr;
  if (Status s = m.factor_choosing(m.scratch, values, &singular_col_); !s.ok()) return s;
  m.scratch.key = std::numeric_limits<double>::quiet_NaN();  // select() never finds it
  ++factorizations_;
  m.current = &m.scratch;
  return Status::Ok();
}

Status KluSolver::solve(double* x) {
  const Factors* f = impl_->current;
  if (!f) return Status::Error("no factorization selected");
  const int n = impl_->n;
  double* __restrict y = impl_->y.data();
  const int* __restrict rp = f->row_perm.data();
  const double* __restrict rs = f->row_scale.data();
  const int* __restrict cp = f->col_perm.data();
  const int* __restrict lp = f->lp.data();
  const int* __restrict lj = f->lj.data();
  const double* __restrict lx = f->lx.data();
  const int* __restrict up = f->up.data();
  const int* __restrict uj = f->uj.data();
  const double* __restrict ux = f->ux.data();
  const double* __restrict dinv = f->udiag_inv.data();

  if (f->blocks.size() == 2) {
    // One block (no F): the permutations fold into the two sweeps (x is read by the first
    // sweep only, written by the second only).
    for (int r = 0; r < n; ++r) {
      double s = x[rp[r]] * rs[r];
      for (int k = lp[r]; k < lp[r + 1]; ++k) s -= lx[k] * y[lj[k]];
      y[r] = s;
    }
    for (int r = n - 1; r >= 0; --r) {
      double s = y[r] * dinv[r];
      for (int k = up[r]; k < up[r + 1]; ++k) s -= ux[k] * y[uj[k]];
      y[r] = s;
      x[cp[r]] = s;
    }
    return Status::Ok();
  }

  for (int k = 0; k < n; ++k) y[k] = x[rp[k]] * rs[k];
  const bool offdiag = !f->fp.empty();
  // Blocks last to first: F couples a block to the blocks after it, already solved.
  for (int b = static_cast<int>(f->blocks.size()) - 2; b >= 0; --b) {
    const int k1 = f->blocks[b], k2 = f->blocks[b + 1];
    if (offdiag) {
      for (int r = k1; r < k2; ++r) {
        double s = y[r];
        for (int k = f->fp[r]; k < f->fp[r + 1]; ++k) s -= f->fx[k] * y[f->fj[k]];
        y[r] = s;
      }
    }
    for (int r = k1; r < k2; ++r) {
      double s = y[r];
      for (int k = lp[r]; k < lp[r + 1]; ++k) s -= lx[k] * y[lj[k]];
      y[r] = s;
    }
    for (int r = k2 - 1; r >= k1; --r) {
      double s = y[r] * dinv[r];
      for (int k = up[r]; k < up[r + 1]; ++k) s -= ux[k] * y[uj[k]];
      y[r] = s;
    }
  }
  for (int k = 0; k < n; ++k) x[cp[k]] = y[k];
  return Status::Ok();
}

KluSolver::Info KluSolver::info() const {
  Info out;
  out.ordering = impl_->ordering;
  if (const Factors* f = impl_->current) {
    out.lu_nonzeros = f->lu_nonzeros;
    out.offdiagonal = f->offdiagonal();
    out.chain = f->chain;
    out.blocks = static_cast<int>(f->blocks.size()) - 1;
  }
  return out;
}

}  // namespace isolink
