// KluSolver: the flattened solve against the residual, for each ordering and for BTF blocks.
#include "solver/klu_solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "solver/mna_system.h"
#include "test_cards.h"

namespace isolink {
namespace {

// A matrix over an MnaPattern: entries by (row, col) as unknown indices (1..n), values summed.
struct TestMatrix {
  int n;
  MnaPattern pattern;
  std::vector<double> values;

  TestMatrix(int size, const std::vector<std::pair<std::pair<int, int>, double>>& entries)
      : n(size), pattern(size) {
    for (const auto& [rc, v] : entries) pattern.declare(rc.first, rc.second);
    pattern.finalize();
    values.assign(pattern.value_count(), 0.0);
    for (const auto& [rc, v] : entries) values[pattern.slot(rc.first, rc.second)] += v;
  }
  // max |A x - b| / max |b|
  double residual(const std::vector<double>& x, const std::vector<double>& b) const {
    std::vector<double> r(n, 0.0);
    const auto& cp = pattern.col_start();
    const auto& ri = pattern.row_index();
    for (int col = 0; col < n; ++col)
      for (int k = cp[col]; k < cp[col + 1]; ++k) r[ri[k]] += values[k] * x[col];
    double worst = 0, scale = 0;
    for (int i = 0; i < n; ++i) worst = std::max(worst, std::fabs(r[i] - b[i]));
    for (double v : b) scale = std::max(scale, std::fabs(v));
    return worst / scale;
  }
};

// Two coupled lines of `cells` cells, like the cable ladder: a long chain for AMD.
TestMatrix ladder(int cells, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  const int n = 2 * cells;
  std::vector<std::pair<std::pair<int, int>, double>> e;
  auto conductance = [&](int a, int b, double g) {  // a, b unknowns, 0 = ground
    if (a) e.push_back({{a, a}, g});
    if (b) e.push_back({{b, b}, g});
    if (a && b) e.push_back({{a, b}, -g}), e.push_back({{b, a}, -g});
  };
  for (int k = 0; k < cells; ++k) {
    const int p = 2 * k + 1, q = 2 * k + 2;
    conductance(p, q, u(rng));
    conductance(p, 0, 0.1 * u(rng));
    conductance(q, 0, 0.1 * u(rng));
    if (k + 1 < cells) {
      conductance(p, p + 2, 3 * u(rng));
      conductance(q, q + 2, 3 * u(rng));
      e.push_back({{p, q + 2}, 0.2 * u(rng)});  // an unsymmetric coupling
    }
  }
  return TestMatrix(n, e);
}

std::vector<double> some_rhs(int n) {
  std::vector<double> b(n);
  for (int i = 0; i < n; ++i) b[i] = std::sin(1.0 + i) + 0.1 * i;
  return b;
}

TEST(KluSolver, EveryOrderingSolvesTheLadder) {
  const TestMatrix m = ladder(60, 1);
  for (auto ordering : {KluSolver::Ordering::Auto, KluSolver::Ordering::Amd,
                        KluSolver::Ordering::NestedDissection}) {
    KluSolver klu;
    ASSERT_TRUE(klu.analyze(m.pattern, ordering).ok());
    ASSERT_TRUE(klu.factor(1.0, m.values.data()).ok());
    const std::vector<double> b = some_rhs(m.n);
    std::vector<double> x = b;
    ASSERT_TRUE(klu.solve(x.data()).ok());
    EXPECT_LT(m.residual(x, b), 1e-13) << klu.info().ordering;
  }
}

TEST(KluSolver, AutoPicksTheShorterChainOnALadder) {
  const TestMatrix m = ladder(100, 2);
  KluSolver amd, automatic;
  ASSERT_TRUE(amd.analyze(m.pattern, KluSolver::Ordering::Amd).ok());
  ASSERT_TRUE(amd.factor(1.0, m.values.data()).ok());
  ASSERT_TRUE(automatic.analyze(m.pattern).ok());
  ASSERT_TRUE(automatic.factor(1.0, m.values.data()).ok());
  const KluSolver::Info a = amd.info(), b = automatic.info();
  EXPECT_EQ(a.ordering, "amd");
  EXPECT_EQ(b.ordering, "nested dissection");
  // AMD eliminates the ladder from one end: every row waits for the one before it.
  EXPECT_GT(a.chain, 150);
  EXPECT_LT(b.chain, a.chain / 3);
  EXPECT_GT(b.lu_nonzeros, 0);
  EXPECT_LT(b.lu_nonzeros, 2 * a.lu_nonzeros);  // a little more fill at most
}

// The DC matrix of a link as the engines build it (MnaSystem::dc_values): a source through an
// isolation capacitor per line into a twisted pair of 150 sections (R, then L with the pair's
// mutual coupling and its neighbours', as the cable library couples them, capacitance between
// the lines and to ground), an isolation capacitor per line
// and a termination at the far end. At DC an inductor's branch row, v_a - v_b = 0, has no
// diagonal and the capacitors' nodes float (gmin), so KLU pivots away from AMD's symmetric order
// (908 unknowns: 96.8k LU entries under AMD, 9.2k under COLAMD).
TEST(KluSolver, ColamdKeepsTheDcMatrixOfACableSparse) {
  using testing::card, testing::num, testing::word;
  std::vector<Card> cards = {card("vp", {"sp", "0"}, {num(5)}), card("vn", {"sn", "0"}, {num(0)}),
                             card("cip", {"sp", "p0"}, {num(2.2e-9)}),
                             card("cin", {"sn", "q0"}, {num(2.2e-9)})};
  const int sections = 150;
  for (int k = 0; k < sections; ++k) {
    const std::string i = std::to_string(k), j = std::to_string(k + 1);
    cards.push_back(card("rp" + i, {"p" + i, "pm" + i}, {num(0.02)}));
    cards.push_back(card("rq" + i, {"q" + i, "qm" + i}, {num(0.02)}));
    cards.push_back(card("lp" + i, {"pm" + i, "p" + j}, {num(40e-9)}));
    cards.push_back(card("lq" + i, {"qm" + i, "q" + j}, {num(40e-9)}));
    cards.push_back(card("k" + i, {}, {num(0.6)}, {"lp" + i, "lq" + i}));
    if (k + 1 < sections) {  // the neighbouring sections' coupling (the library's cable model)
      cards.push_back(card("kpp" + i, {}, {num(0.1)}, {"lp" + i, "lp" + j}));
      cards.push_back(card("kqq" + i, {}, {num(0.1)}, {"lq" + i, "lq" + j}));
      cards.push_back(card("kpq" + i, {}, {num(0.07)}, {"lp" + i, "lq" + j}));
      cards.push_back(card("kqp" + i, {}, {num(0.07)}, {"lq" + i, "lp" + j}));
    }
    cards.push_back(card("cpq" + i, {"p" + j, "q" + j}, {num(4e-12)}));
    cards.push_back(card("cp" + i, {"p" + j, "0"}, {num(2e-12)}));
    cards.push_back(card("cq" + i, {"q" + j, "0"}, {num(2e-12)}));
  }
  const std::string end = std::to_string(sections);
  cards.push_back(card("cop", {"p" + end, "rp"}, {num(2.2e-9)}));
  cards.push_back(card("con", {"q" + end, "rq"}, {num(2.2e-9)}));
  cards.push_back(card("rterm", {"rp", "rq"}, {num(120)}));
  Circuit circuit;
  ASSERT_EQ(testing::build(circuit, cards), "");
  MnaSystem sys;
  ASSERT_TRUE(sys.build(circuit).ok());
  const std::vector<double> values = sys.dc_values(circuit, {}, nullptr);
  long entries[2] = {0, 0};
  int k = 0;
  for (auto ordering : {KluSolver::Ordering::Amd, KluSolver::Ordering::Colamd}) {
    KluSolver klu;
    ASSERT_TRUE(klu.analyze(sys.pattern, ordering).ok());
    ASSERT_TRUE(klu.factor(0.0, values.data()).ok()) << klu.info().ordering;
    entries[k++] = klu.info().lu_nonzeros;
  }
  // A ladder's LU needs a few entries per unknown in a good order.
  EXPECT_LT(entries[1], 12L * sys.n) << "colamd";
  EXPECT_LT(3 * entries[1], entries[0]) << "amd " << entries[0] << ", colamd " << entries[1];
}

TEST(KluSolver, SmallCircuitsKeepAmd) {
  const TestMatrix m = ladder(5, 3);
  KluSolver klu;
  ASSERT_TRUE(klu.analyze(m.pattern).ok());
  ASSERT_TRUE(klu.factor(1.0, m.values.data()).ok());
  EXPECT_EQ(klu.info().ordering, "amd");
}

// A block upper triangular matrix (a chain feeding a cycle feeding a cycle): BTF splits it, and the
// solve goes through the off-diagonal blocks.
TEST(KluSolver, SolvesThroughBtfOffDiagonalBlocks) {
  std::vector<std::pair<std::pair<int, int>, double>> e;
  const int n = 9;
  for (int i = 1; i <= n; ++i) e.push_back({{i, i}, 4.0 + i});
  // cycles 1-2-3, 4-5-6, 7-8-9; coupling only from later groups into earlier rows
  for (int g = 0; g < 3; ++g) {
    const int a = 3 * g + 1;
    e.push_back({{a, a + 1}, 1.0}), e.push_back({{a + 1, a + 2}, -1.5}),
        e.push_back({{a + 2, a}, 0.7});
  }
  e.push_back({{1, 5}, 2.0}), e.push_back({{2, 9}, -1.0}), e.push_back({{4, 8}, 0.5});
  TestMatrix m(n, e);
  KluSolver klu;
  ASSERT_TRUE(klu.analyze(m.pattern, KluSolver::Ordering::Amd).ok());
  ASSERT_TRUE(klu.factor(1.0, m.values.data()).ok());
  EXPECT_GT(klu.info().blocks, 1);
  EXPECT_GT(klu.info().offdiagonal, 0);
  const std::vector<double> b = some_rhs(n);
  std::vector<double> x = b;
  ASSERT_TRUE(klu.solve(x.data()).ok());
  EXPECT_LT(m.residual(x, b), 1e-14);
}

TEST(KluSolver, FactorizationsAreCachedByKey) {
  const TestMatrix m = ladder(40, 4);
  KluSolver klu;
  ASSERT_TRUE(klu.analyze(m.pattern).ok());
  EXPECT_FALSE(klu.select(1.0));
  ASSERT_TRUE(klu.factor(1.0, m.values.data()).ok());
  std::vector<double> doubled = m.values;
  for (double& v : doubled) v *= 2;
  ASSERT_TRUE(klu.factor(2.0, doubled.data()).ok());
  const std::vector<double> b = some_rhs(m.n);
  std::vector<double> x1 = b, x2 = b;
  ASSERT_TRUE(klu.select(1.0));
  ASSERT_TRUE(klu.solve(x1.data()).ok());
  ASSERT_TRUE(klu.select(2.0));
  ASSERT_TRUE(klu.solve(x2.data()).ok());
  for (int i = 0; i < m.n; ++i) EXPECT_NEAR(x2[i], x1[i] / 2, 1e-12 * std::fabs(x1[i]) + 1e-300);
  EXPECT_EQ(klu.factorizations(), 2);
  EXPECT_EQ(klu.reuses(), 2);
}

TEST(KluSolver, SingularMatrixNamesItsColumn) {
  // Unknown 3 appears in no equation with a nonzero value: column 2 (0-based) is singular.
  TestMatrix m(3, {{{1, 1}, 1.0}, {{2, 2}, 1.0}, {{1, 2}, 0.5}, {{3, 3}, 0.0}});
  KluSolver klu;
  ASSERT_TRUE(klu.analyze(m.pattern).ok());
  Status s = klu.factor(1.0, m.values.data());
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(klu.singular_column(), 2);
  std::vector<double> x(3, 1.0);
  EXPECT_FALSE(klu.solve(x.data()).ok());  // no factorization selected
}

}  // namespace
}  // namespace isolink
