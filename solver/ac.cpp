#include "solver/ac.h"

#include <fmt/format.h>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <cmath>
#include <numbers>

#include "solver/mna.h"

namespace isolink {

struct AcAnalysis::Impl {
  const Circuit* circuit = nullptr;
  MnaPattern pattern{0};
  std::vector<double> g, c;
  Eigen::SparseMatrix<std::complex<double>> a;
  mutable Eigen::SparseLU<Eigen::SparseMatrix<std::complex<double>>>
      lu;                 // transpose() is non-const
  double frequency = -1;  // of the current factorization, -1: none
};

AcAnalysis::AcAnalysis() : impl_(std::make_unique<Impl>()) {}
AcAnalysis::AcAnalysis(AcAnalysis&&) noexcept = default;
AcAnalysis& AcAnalysis::operator=(AcAnalysis&&) noexcept = default;
AcAnalysis::~AcAnalysis() = default;

StatusOr<AcAnalysis> AcAnalysis::create(const Circuit& circuit) {
  AcAnalysis ac;
  Impl& m = *ac.impl_;
  m.circuit = &circuit;
  const int n = circuit.unknown_count();
  if (n == 0) return Status::Error("ac analysis: the circuit has no unknowns");
  m.pattern = MnaPattern(n);
  auto& elements = const_cast<Circuit&>(circuit).elements();
  for (auto& e : elements) e->declare(m.pattern);
  m.pattern.finalize();
  for (auto& e : elements) e->declare(m.pattern);
  m.g.assign(m.pattern.value_count(), 0.0);
  m.c.assign(m.pattern.value_count(), 0.0);
  for (auto& e : elements) e->stamp(m.g.data(), m.c.data());
  for (int node : circuit.floating_nodes())
    m.g[m.pattern.slot(node, node)] += Circuit::kFloatingTie;

  std::vector<Eigen::Triplet<std::complex<double>>> triplets;
  const auto& cp = m.pattern.col_start();
  const auto& ri = m.pattern.row_index();
  for (int col = 0; col < n; ++col)
    for (int k = cp[col]; k < cp[col + 1]; ++k) triplets.emplace_back(ri[k], col, 1.0);
  m.a.resize(n, n);
  m.a.setFromTriplets(triplets.begin(), triplets.end());
  m.a.makeCompressed();
  m.lu.analyzePattern(m.a);
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

Status AcAnalysis::factor(double frequency) {
  Impl& m = *impl_;
  if (!(frequency >= 0) || !std::isfinite(frequency))
    return Status::Error(fmt::format("ac analysis: frequency {:g} Hz must be >= 0", frequency));
  // The matrix's value order is the pattern's CSC order (same structure, compressed).
  const double w = 2 * std::numbers::pi * frequency;
  std::complex<double>* values = m.a.valuePtr();
  for (int k = 0; k < m.pattern.nonzeros(); ++k) values[k] = {m.g[k], w * m.c[k]};
  m.lu.factorize(m.a);
  m.frequency = -1;
  if (m.lu.info() != Eigen::Success)
    return Status::Error(fmt::format("ac analysis at {:g} Hz: singular matrix ({})", frequency,
                                     m.lu.lastErrorMessage()));
  m.frequency = frequency;
  return Status::Ok();
}

double AcAnalysis::factored_frequency() const {
  return impl_->frequency;
}

AcAnalysis::Vector AcAnalysis::solve_factored(const Vector& b) const {
  const Impl& m = *impl_;
  const int n = m.pattern.size();
  Eigen::VectorXcd rhs(n);
  for (int i = 0; i < n; ++i) rhs[i] = b[i + 1];
  Eigen::VectorXcd x = m.lu.solve(rhs);
  Vector out(n + 1, 0.0);
  for (int i = 0; i < n; ++i) out[i + 1] = x[i];
  return out;
}

AcAnalysis::Vector AcAnalysis::solve_transposed(const Vector& c) const {
  const Impl& m = *impl_;
  const int n = m.pattern.size();
  Eigen::VectorXcd rhs(n);
  for (int i = 0; i < n; ++i) rhs[i] = c[i + 1];
  Eigen::VectorXcd z = m.lu.transpose().solve(rhs);
  Vector out(n + 1, 0.0);
  for (int i = 0; i < n; ++i) out[i + 1] = z[i];
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
