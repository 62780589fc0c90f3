#include "solver/ac.h"

#include <amd.h>
#include <fmt/format.h>
#include <klu.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>

#include "solver/mna.h"

namespace isolink {

// KLU's complex factorization (klu_z_*) on one symbolic analysis of the pattern: the same
// library and ordering family as the transient's solves, several times faster than a general
// sparse LU on circuit matrices (the reduced model factors a few hundred frequencies).
struct AcAnalysis::Impl {
  const Circuit* circuit = nullptr;
  MnaPattern pattern{0};
  std::vector<double> g, c;
  std::vector<int> ap, ai;  // the pattern's CSC arrays, for KLU (int*)
  std::vector<double> a;    // interleaved re, im of R (G + j w C), pattern (CSC) order
  // R: each row's scale, a power of two (exact) that brings the row's largest entry (by
  // max(|re|, |im|)) into [0.5, 1), recomputed at each frequency: the scaling KLU's own
  // (common.scale = 2: a complex modulus per entry, 4 % of a sweep point) gives pivoting, cheaper.
  std::vector<double> row_scale;
  std::vector<double> g_row_max, c_row_max;  // per row: the largest |g|, |c|
  klu_common common{};
  klu_symbolic* symbolic = nullptr;
  // COLAMD's ordering, until the first factorization keeps whichever of it and `symbolic` (the
  // paired ordering, below) needs fewer flops.
  klu_symbolic* candidate = nullptr;
  klu_numeric* numeric = nullptr;
  bool paired = true;     // `symbolic` is the paired ordering (else COLAMD's)
  double frequency = -1;  // of the current factorization, -1: none
  // The current factorization failed the backward-error probe even with fresh, stricter pivots:
  // each solve refines itself (header: Accuracy).
  bool refine = false;
  ~Impl() {
    if (numeric) klu_z_free_numeric(&numeric, &common);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
    if (candidate) klu_free_symbolic(&candidate, &common);
  }
  klu_symbolic* analyze_paired();
  bool keep_cheaper_ordering(bool factored);
  double probe_backward_error();
  bool factor_fresh();
  void multiply(const std::vector<double>& x, std::vector<double>& y, bool transposed) const;
  double backward_error(const std::vector<double>& x, const std::vector<double>& rhs,
                        bool transposed, std::vector<double>& residual) const;
  void solve_scaled(std::vector<double>& x, bool transposed);
  AcAnalysis::Vector solve(const AcAnalysis::Vector& b, bool transposed);
};

namespace {

// Accuracy (header): the largest backward error a factorization's probe solve may leave (a
// stable LU leaves about n eps), KLU's pivot threshold after one that left more (its default is
// 0.001), and the refinement steps a solve takes when even that factorization is inaccurate.
constexpr double kBackwardErrorBound = 1e-11;
constexpr double kStrictPivotTolerance = 0.1;
constexpr int kRefinementSteps = 3;

// |g| + |c| of the pattern's entry (row, col) (0-based), 0 where the pattern has none.
double entry_size(const MnaPattern& pattern, const std::vector<double>& g,
                  const std::vector<double>& c, int row, int col) {
  const std::vector<int>& cp = pattern.col_start();
  const std::vector<int>& ri = pattern.row_index();
  for (int k = cp[col]; k < cp[col + 1]; ++k)
    if (ri[k] == row) return std::fabs(g[k]) + std::fabs(c[k]);
  return 0;
}

// Each branch unknown (a voltage source's or an inductor's current) paired with a node of its
// element: pair[i] is the row that stands on unknown i's diagonal (an involution; unpaired
// unknowns keep their own row). A branch row, v_a - v_b - j w L i = 0, has a zero diagonal for a
// source and a small one for an inductor below its corner (w L under the ohms around it), so
// pivoting swaps it with a node's row, and an ordering that counted on the diagonal fills in: a
// 12 m link's cable (R and L per section) took 55.7k flops a factorization under COLAMD. The
// pair's two entries (the branch's +-1 in the node's KCL row, the node's +-1 in the branch row)
// do not depend on frequency; ordered with them as the diagonal, the same link takes 16-20k.
std::vector<int> pair_branches_with_nodes(const Circuit& circuit, const MnaPattern& pattern,
                                          const std::vector<double>& g,
                                          const std::vector<double>& c) {
  const int n = pattern.size();
  std::vector<int> pair(static_cast<size_t>(n));
  std::iota(pair.begin(), pair.end(), 0);
  std::vector<char> paired(static_cast<size_t>(n), 0);
  for (const auto& e : circuit.elements())
    for (int branch : e->branches()) {
      const int b = branch - 1;  // unknowns count from 1 (0 is ground); KLU's from 0
      if (b < 0 || b >= n || paired[b]) continue;
      for (int node : e->nodes()) {
        const int v = node - 1;
        if (v < 0 || v >= n || paired[v]) continue;
        if (entry_size(pattern, g, c, v, b) == 0 || entry_size(pattern, g, c, b, v) == 0) continue;
        pair[b] = v, pair[v] = b;
        paired[b] = paired[v] = 1;
        break;
      }
    }
  return pair;
}

}  // namespace

// AMD on the pattern with each pair's rows swapped (pair_branches_with_nodes), given to KLU as
// rows P = pair(Q), columns Q. KLU still pivots (threshold partial pivoting) where a paired
// diagonal is too small: the ordering only sets the fill, never whether the LU is sound.
klu_symbolic* AcAnalysis::Impl::analyze_paired() {
  const int n = pattern.size();
  const std::vector<int> pair = pair_branches_with_nodes(*circuit, pattern, g, c);
  std::vector<int> bi(ai.size());  // the swapped pattern's rows, sorted in each column
  for (int col = 0; col < n; ++col) {
    for (int k = ap[col]; k < ap[col + 1]; ++k) bi[k] = pair[ai[k]];
    std::sort(bi.begin() + ap[col], bi.begin() + ap[col + 1]);
  }
  std::vector<int> q(static_cast<size_t>(n));
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  const int status = amd_order(n, ap.data(), bi.data(), q.data(), control, info);
  if (status != AMD_OK && status != AMD_OK_BUT_JUMBLED) return nullptr;
  std::vector<int> p(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) p[k] = pair[q[k]];
  const int btf = common.btf;
  common.btf = 0;  // the order is for the whole matrix
  klu_symbolic* s = klu_analyze_given(n, ap.data(), ai.data(), p.data(), q.data(), &common);
  common.btf = btf;
  return s;
}

// After the first factorization (with `symbolic`; `factored`: it succeeded): factors with the
// candidate too and keeps the one with fewer flops, or the one that factors. The paired order
// won on every link spec tried; COLAMD stays for netlists where pairing does not pay. True when
// `numeric` holds a factorization.
bool AcAnalysis::Impl::keep_cheaper_ordering(bool factored) {
  klu_symbolic* other = candidate;
  candidate = nullptr;
  if (!factored && numeric) klu_z_free_numeric(&numeric, &common);
  klu_numeric* num = klu_z_factor(ap.data(), ai.data(), a.data(), other, &common);
  const bool other_ok = num != nullptr && common.status == KLU_OK;
  double mine = 0;
  if (factored && other_ok && klu_z_flops(symbolic, numeric, &common)) mine = common.flops;
  if (other_ok && (!factored || (klu_z_flops(other, num, &common) && common.flops < mine))) {
    std::swap(symbolic, other);
    std::swap(numeric, num);
    paired = false;
    factored = true;
  }
  if (num) klu_z_free_numeric(&num, &common);
  klu_free_symbolic(&other, &common);
  return factored;
}

AcAnalysis::AcAnalysis() : impl_(std::make_unique<Impl>()) {}
AcAnalysis::AcAnalysis(AcAnalysis&&) noexcept = default;
AcAnalysis& AcAnalysis::operator=(AcAnalysis&&) noexcept = default;
AcAnalysis::~AcAnalysis() = default;

StatusOr<AcAnalysis> AcAnalysis::create(const Circuit& circuit, AcOrdering ordering) {
  AcAnalysis ac;
  Impl& m = *ac.impl_;
  m.circuit = &circuit;
  const int n = circuit.unknown_count();
  if (n == 0) return Status::Error("ac analysis: the circuit has no unknowns");
  MnaMatrices mna = assemble_mna(circuit);
  m.pattern = std::move(mna.pattern);
  m.g = std::move(mna.g);
  m.c = std::move(mna.c);
  // KLU's C interface takes the pattern as int*, never writing it: its own copies.
  m.ap = m.pattern.col_start();
  m.ai = m.pattern.row_index();

  klu_defaults(&m.common);
  // The candidate: COLAMD, not KLU's default AMD, which (on the unpaired pattern) left a 40 m
  // link's (2732 unknowns) pivoted LU with 230k entries, 17 ms a refactorization; COLAMD's 34k.
  m.common.ordering = 1;
  // The rows are scaled here (Impl::row_scale); the pattern is KLU's own analysis's, checked.
  m.common.scale = -1;
  m.candidate = klu_analyze(n, m.ap.data(), m.ai.data(), &m.common);
  if (m.candidate == nullptr)
    return Status::Error(
        fmt::format("ac analysis: KLU symbolic analysis failed (status {})", m.common.status));
  m.a.assign(2 * static_cast<size_t>(m.pattern.nonzeros()), 0.0);
  m.row_scale.assign(static_cast<size_t>(n), 1.0);
  m.g_row_max.assign(static_cast<size_t>(n), 0.0);
  m.c_row_max.assign(static_cast<size_t>(n), 0.0);
  for (int k = 0; k < m.pattern.nonzeros(); ++k) {
    double& gm = m.g_row_max[m.ai[k]];
    double& cm = m.c_row_max[m.ai[k]];
    gm = std::max(gm, std::fabs(m.g[k]));
    cm = std::max(cm, std::fabs(m.c[k]));
  }
  if (ordering != AcOrdering::kColamd) m.symbolic = m.analyze_paired();
  if (m.symbolic == nullptr) {  // COLAMD alone
    std::swap(m.symbolic, m.candidate);
    m.paired = false;
  }
  if (ordering == AcOrdering::kPaired && m.candidate) klu_free_symbolic(&m.candidate, &m.common);
  return ac;
}

Status AcAnalysis::add_excitation(const std::string& source, std::complex<double> amplitude,
                                  Vector& b) const {
  const Impl& m = *impl_;
  const Element* e = m.circuit->find_element(source);
  if (e == nullptr) return Status::Error(fmt::format("ac analysis: no source named '{}'", source));
  if (b.size() != static_cast<size_t>(m.pattern.size() + 1)) b.assign(m.pattern.size() + 1, 0.0);
  std::vector<DcEdge> edges;
  e->dc_edges(edges);
  const DcLink link = edges.size() == 1 ? edges[0].link : DcLink::Conductive;
  if (link == DcLink::VoltageDefining && e->branches().size() == 1 && !e->branch_is_state()) {
    b[e->branches()[0]] += amplitude;
  } else if (link == DcLink::CurrentSource && e->nodes().size() == 2) {
    if (e->nodes()[0] > 0) b[e->nodes()[0]] -= amplitude;
    if (e->nodes()[1] > 0) b[e->nodes()[1]] += amplitude;
  } else {
    return Status::Error(fmt::format("ac analysis: '{}' is not a V or I source", source));
  }
  return Status::Ok();
}

namespace {

// klu_z_rcond's estimate, min |U_kk| / max |U_kk| (0 for a zero or NaN pivot), from squared
// magnitudes: it used hypot per pivot, 1.4 ms of a 12 m link's 266 refactorizations.
double pivot_ratio(const klu_numeric* numeric, int n) {
  const double* u = static_cast<const double*>(numeric->Udiag);  // interleaved re, im
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (int k = 0; k < n; ++k) {
    const double m2 = u[2 * k] * u[2 * k] + u[2 * k + 1] * u[2 * k + 1];
    if (!(m2 > 0) || !std::isfinite(m2)) return 0;
    lo = std::min(lo, m2);
    hi = std::max(hi, m2);
  }
  return n > 0 ? std::sqrt(lo / hi) : 0;
}

// 2^-k with r 2^-k in [0.5, 1), from r's exponent bits (frexp and ldexp per row were 8 % of a
// refactorization); 1 for r = 0, subnormal, infinite, NaN or over 2^1021.
double power_of_two_below(double r) {
  const int field = static_cast<int>((std::bit_cast<uint64_t>(r) >> 52) & 0x7ff);  // r's, biased
  // r in [2^(field - 1023), 2^(field - 1022)): the scale's biased exponent is 2045 - field.
  if (field == 0 || field > 2044) return 1.0;
  return std::bit_cast<double>(static_cast<uint64_t>(2045 - field) << 52);
}

}  // namespace

Status AcAnalysis::factor(double frequency) {
  Impl& m = *impl_;
  if (!(frequency >= 0) || !std::isfinite(frequency))
    return Status::Error(fmt::format("ac analysis: frequency {:g} Hz must be >= 0", frequency));
  const double w = 2 * std::numbers::pi * frequency;
  int* ap = m.ap.data();
  int* ai = m.ai.data();
  const int nnz = m.pattern.nonzeros();
  // Row i's largest entry max_k max(|g_ik|, w |c_ik|) is max(max_k |g_ik|, w max_k |c_ik|).
  std::vector<double>& rs = m.row_scale;
  for (size_t i = 0; i < rs.size(); ++i) {
    rs[i] = power_of_two_below(std::max(m.g_row_max[i], w * m.c_row_max[i]));
  }
  for (int k = 0; k < nnz; ++k) {
    const double r = rs[ai[k]];
    m.a[2 * k] = r * m.g[k], m.a[2 * k + 1] = r * (w * m.c[k]);
  }
  m.frequency = -1;
  // Refactor on the previous pivots when there is one (fast), a full factor otherwise or when
  // the refactorization's pivots have become poor.
  bool ok = false;
  if (m.numeric) {
    ok = klu_z_refactor(ap, ai, m.a.data(), m.symbolic, m.numeric, &m.common) == 1;
    ok = ok && pivot_ratio(m.numeric, m.pattern.size()) > 1e-13;
    if (!ok) klu_z_free_numeric(&m.numeric, &m.common);
  }
  if (!ok) {
    ok = m.factor_fresh();
    if (m.candidate) ok = m.keep_cheaper_ordering(ok);
  }
  // Accuracy (header): a factorization whose probe solve leaves a residual is redone with fresh
  // pivots at KLU's strict threshold; if that is still inaccurate, every solve refines itself.
  m.refine = false;
  if (ok && m.probe_backward_error() > kBackwardErrorBound) {
    m.common.tol = kStrictPivotTolerance;  // kept for this analysis's later factorizations
    ok = m.factor_fresh();
    m.refine = ok && m.probe_backward_error() > kBackwardErrorBound;
  }
  if (!ok)
    return Status::Error(fmt::format("ac analysis at {:g} Hz: singular matrix (KLU status {})",
                                     frequency, m.common.status));
  m.frequency = frequency;
  return Status::Ok();
}

// A full factorization (new pivots) of `a` on `symbolic`, the previous one freed.
bool AcAnalysis::Impl::factor_fresh() {
  if (numeric) klu_z_free_numeric(&numeric, &common);
  numeric = klu_z_factor(ap.data(), ai.data(), a.data(), symbolic, &common);
  return numeric != nullptr && common.status == KLU_OK;
}

// y = S x or S^T x (S = R A, the scaled matrix `a`), complex vectors interleaved re, im.
void AcAnalysis::Impl::multiply(const std::vector<double>& x, std::vector<double>& y,
                                bool transposed) const {
  std::fill(y.begin(), y.end(), 0.0);
  const int n = pattern.size();
  for (int col = 0; col < n; ++col)
    for (int k = ap[col]; k < ap[col + 1]; ++k) {
      const double are = a[2 * k], aim = a[2 * k + 1];
      const size_t from = 2 * static_cast<size_t>(transposed ? ai[k] : col);
      const size_t to = 2 * static_cast<size_t>(transposed ? col : ai[k]);
      y[to] += are * x[from] - aim * x[from + 1];
      y[to + 1] += are * x[from + 1] + aim * x[from];
    }
}

// The normwise backward error of x as a solution of S x = rhs (S^T x = rhs):
// max|rhs - S x| / (max|S| max|x| + max|rhs|), max|S| at most 1 (each row's largest entry is
// scaled into [0.5, 1), and |re| + |im| bounds an entry). `residual` is left holding rhs - S x.
double AcAnalysis::Impl::backward_error(const std::vector<double>& x,
                                        const std::vector<double>& rhs, bool transposed,
                                        std::vector<double>& residual) const {
  residual.resize(x.size());
  multiply(x, residual, transposed);
  double r = 0, xm = 0, bm = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    residual[i] = rhs[i] - residual[i];
    r = std::max(r, std::fabs(residual[i]));
    xm = std::max(xm, std::fabs(x[i]));
    bm = std::max(bm, std::fabs(rhs[i]));
  }
  const double scale = 2 * xm + bm;
  if (!std::isfinite(r) || !std::isfinite(scale)) return std::numeric_limits<double>::infinity();
  return scale > 0 ? r / scale : 0;
}

// The backward error of the factorization's solve for a fixed right-hand side, b = S x0.
double AcAnalysis::Impl::probe_backward_error() {
  const size_t n = static_cast<size_t>(pattern.size());
  std::vector<double> x0(2 * n), b(2 * n), x, residual;
  for (size_t i = 0; i < n; ++i) x0[2 * i] = 1.0 + 0.1 * (i % 7), x0[2 * i + 1] = 0.2 * (i % 5);
  multiply(x0, b, false);
  x = b;
  solve_scaled(x, false);  // as the solves will (refine is off while the factorization is probed)
  return backward_error(x, b, false, residual);
}

// x := S^-1 x (S^-T x), with up to kRefinementSteps of iterative refinement when `refine`.
void AcAnalysis::Impl::solve_scaled(std::vector<double>& x, bool transposed) {
  const int n = pattern.size();
  const auto klu = [&](std::vector<double>& v) {
    if (transposed)
      klu_z_tsolve(symbolic, numeric, n, 1, v.data(), 0, &common);  // S^T, not conjugated
    else
      klu_z_solve(symbolic, numeric, n, 1, v.data(), &common);
  };
  const std::vector<double> rhs = refine ? x : std::vector<double>{};
  klu(x);
  std::vector<double> residual;
  for (int step = 0; refine && step < kRefinementSteps; ++step) {
    if (backward_error(x, rhs, transposed, residual) <= kBackwardErrorBound) break;
    klu(residual);
    for (size_t i = 0; i < x.size(); ++i) x[i] += residual[i];
  }
}

double AcAnalysis::factored_frequency() const {
  return impl_->frequency;
}

double AcAnalysis::factor_flops() const {
  Impl& m = *impl_;
  if (!m.numeric || !klu_z_flops(m.symbolic, m.numeric, &m.common)) return 0;
  return m.common.flops;
}

const char* AcAnalysis::ordering_name() const {
  return impl_->paired ? "paired AMD" : "COLAMD";
}

// A x = b as (R A) x = R b; A^T x = b as (R A)^T y = b, x = R y (R: Impl::row_scale).
AcAnalysis::Vector AcAnalysis::solve_factored(const Vector& b) const {
  return impl_->solve(b, false);
}

AcAnalysis::Vector AcAnalysis::solve_transposed(const Vector& c) const {
  return impl_->solve(c, true);
}

AcAnalysis::Vector AcAnalysis::Impl::solve(const Vector& b, bool transposed) {
  const int n = pattern.size();
  std::vector<double> x(2 * static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double r = transposed ? 1.0 : row_scale[i];
    x[2 * i] = r * b[i + 1].real(), x[2 * i + 1] = r * b[i + 1].imag();
  }
  solve_scaled(x, transposed);
  Vector out(n + 1, 0.0);
  for (int i = 0; i < n; ++i) {
    const double r = transposed ? row_scale[i] : 1.0;
    out[i + 1] = {r * x[2 * i], r * x[2 * i + 1]};
  }
  return out;
}

const std::vector<double>& AcAnalysis::g_values() const {
  return impl_->g;
}
const std::vector<double>& AcAnalysis::c_values() const {
  return impl_->c;
}
const std::vector<int>& AcAnalysis::col_start() const {
  return impl_->pattern.col_start();
}
const std::vector<int>& AcAnalysis::row_index() const {
  return impl_->pattern.row_index();
}

StatusOr<AcSolution> AcAnalysis::solve(const std::string& source, double frequency) {
  Vector b(impl_->pattern.size() + 1, 0.0);
  if (Status s = add_excitation(source, 1.0, b); !s.ok()) return s;
  if (Status s = factor(frequency); !s.ok()) return s;
  AcSolution out;
  out.frequency = frequency;
  out.x = solve_factored(b);
  return out;
}

}  // namespace isolink
