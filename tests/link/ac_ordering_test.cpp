// The AC analysis's LU ordering on the circuits the link expander builds (solver/ac.h, Ordering):
// pairing each inductor's and source's branch with a node keeps a long cable's LU cheap, and the
// analysis picks it by itself. Both orderings factor the same matrix exactly, so their solutions
// agree to rounding: the paired one moves no result.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "netlists/link/cards.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "solver/ac.h"

namespace isolink::link {
namespace {

const std::string kExamples = ISOLINK_EXAMPLES_DIR;

struct Case {
  const char* spec;
  double max_flops_ratio;  // paired over COLAMD, at most (measured in the comment)
};

class AcOrdering : public ::testing::TestWithParam<Case> {};

// An example spec's link expanded down and up (empty, with the test failed, if it does not read).
std::vector<std::pair<Direction, ExpandedLink>> expand_both(const std::string& file) {
  std::vector<std::pair<Direction, ExpandedLink>> out;
  StatusOr<LinkSpec> spec = read_link_spec_file(kExamples + "/" + file);
  StatusOr<PartLibrary> parts = PartLibrary::load({});
  EXPECT_TRUE(spec.ok() && parts.ok()) << file;
  if (!spec.ok() || !parts.ok()) return out;
  for (Direction d : {Direction::kDown, Direction::kUp}) {
    StatusOr<ExpandedLink> link = expand_link(*spec, *parts, d);
    EXPECT_TRUE(link.ok()) << file << ": " << link.status().message();
    if (link.ok()) out.emplace_back(d, std::move(*link));
  }
  return out;
}

// At the reduced model's first frequency (the band's log middle, 1.73 MHz), where it picks the
// pivots its later refactorizations reuse. Measured paired / COLAMD flops: 2 m cap link
// 8.7k / 15.1k, 10 m cap + dual choke 16.9k / 47.7k, 15 m transformer 24.9k / 72.0k, 12 m
// hybrid 19.7k / 55.6k.
TEST_P(AcOrdering, PairedIsCheaperPickedAndAgreesWithColamd) {
  for (const auto& [d, link] : expand_both(GetParam().spec)) {
    Circuit c;
    ASSERT_TRUE(add_cards(c, link.netlist.cards).ok());
    ASSERT_TRUE(c.finalize().ok());
    auto probe = parse_probe(c, "v(rxp,rxn)");
    ASSERT_TRUE(probe.ok());
    auto paired = AcAnalysis::create(c, isolink::AcOrdering::kPaired);
    auto colamd = AcAnalysis::create(c, isolink::AcOrdering::kColamd);
    auto cheaper = AcAnalysis::create(c);
    ASSERT_TRUE(paired.ok() && colamd.ok() && cheaper.ok());
    const double f0 = std::sqrt(1e3 * 3e9);
    ASSERT_TRUE(paired->factor(f0).ok() && colamd->factor(f0).ok() && cheaper->factor(f0).ok());
    EXPECT_STREQ(paired->ordering_name(), "paired AMD");
    EXPECT_STREQ(colamd->ordering_name(), "COLAMD");
    EXPECT_STREQ(cheaper->ordering_name(), "paired AMD") << GetParam().spec;
    EXPECT_LE(paired->factor_flops(), GetParam().max_flops_ratio * colamd->factor_flops())
        << GetParam().spec << " " << direction_name(d);
    EXPECT_EQ(cheaper->factor_flops(), paired->factor_flops());
    // The transfer from the driver's p line to the receiver over the band, each refactorization
    // on the first one's pivots. Both are rounding away from the truth (1 kHz is the worst
    // conditioned: 10 Mohm bleeds against nF caps), by up to 7.5e-9 of the peak |H| (10 m cap +
    // dual choke link at 1 kHz); the reduced model's check allows 2e-5 of it.
    std::vector<std::complex<double>> hp, hc;
    double peak = 0;
    for (double f : {1e3, 1e4, 1e5, 1e6, 1e7, 3e7, 1e8, 3e8, 1e9, 3e9}) {
      auto xp = paired->solve("vtxp", f);
      auto xc = colamd->solve("vtxp", f);
      ASSERT_TRUE(xp.ok() && xc.ok());
      hp.push_back(xp->voltage(*probe));
      hc.push_back(xc->voltage(*probe));
      peak = std::max(peak, std::abs(hc.back()));
    }
    for (size_t i = 0; i < hp.size(); ++i)
      EXPECT_NEAR(std::abs(hp[i] - hc[i]), 0.0, 2e-8 * peak)
          << GetParam().spec << " " << direction_name(d) << " frequency #" << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Links, AcOrdering,
                         ::testing::Values(Case{"cap_2m.yaml", 0.7},
                                           Case{"capdualchoke_10m.yaml", 0.5},
                                           Case{"transformer_15m.yaml", 0.5},
                                           Case{"hybrid_xfmr_cap_12m.yaml", 0.5}));

// The normwise backward error of x as a solution of (G + j w C) x = b, from the analysis's own
// stamps: max|b - A x| / (max row sum |A| max|x| + max|b|).
double backward_error(const AcAnalysis& ac, double f, const AcAnalysis::Vector& b,
                      const AcAnalysis::Vector& x) {
  const double w = 2 * std::numbers::pi * f;
  const std::vector<int>& cp = ac.col_start();
  const std::vector<int>& ri = ac.row_index();
  AcAnalysis::Vector ax(b.size(), 0.0);
  std::vector<double> row_sum(b.size(), 0.0);
  for (size_t col = 0; col + 1 < cp.size(); ++col)
    for (int k = cp[col]; k < cp[col + 1]; ++k) {
      const std::complex<double> a(ac.g_values()[k], w * ac.c_values()[k]);
      ax[ri[k] + 1] += a * x[col + 1];
      row_sum[ri[k] + 1] += std::abs(a);
    }
  double r = 0, bm = 0, xm = 0;
  for (size_t i = 1; i < b.size(); ++i) {
    r = std::max(r, std::abs(ax[i] - b[i]));
    bm = std::max(bm, std::abs(b[i]));
    xm = std::max(xm, std::abs(x[i]));
  }
  return r / (*std::max_element(row_sum.begin(), row_sum.end()) * xm + bm);
}

// solver/ac.h, Accuracy: a 5 m cap + choke link's windings (k = 0.9985, 1 pF across each) make
// G + j w C nearly singular at 600-750 MHz, and the pivots of the sweep's first frequency,
// reused there, left a backward error of 1.1e-4 at 736 MHz (measured with the check disabled;
// the stress port model's reference was 0.61 of the right-hand side off at 719 MHz). A sweep
// from 1 kHz to 1 GHz in ascending order, every source driven, must solve to rounding.
TEST(AcAccuracy, ChokeResonancesSolveToRounding) {
  for (const auto& [d, link] : expand_both("capchoke_5m.yaml")) {
    Circuit c;
    ASSERT_TRUE(add_cards(c, link.netlist.cards).ok());
    ASSERT_TRUE(c.finalize().ok());
    auto ac = AcAnalysis::create(c);
    ASSERT_TRUE(ac.ok());
    std::vector<std::string> sources;
    for (const Card& card : link.netlist.cards)
      if (card.name[0] == 'v') sources.push_back(card.name);
    ASSERT_GE(sources.size(), 2u);
    double worst = 0, worst_f = 0;
    for (int i = 0; i <= 90; ++i) {
      const double f = std::pow(10.0, 3 + 6.0 * i / 90);
      ASSERT_TRUE(ac->factor(f).ok());
      for (const std::string& v : sources) {
        AcAnalysis::Vector b(c.unknown_count() + 1, 0.0);
        ASSERT_TRUE(ac->add_excitation(v, 1.0, b).ok());
        const double e = backward_error(*ac, f, b, ac->solve_factored(b));
        if (e > worst) worst = e, worst_f = f;
      }
    }
    EXPECT_LT(worst, 1e-13) << direction_name(d) << " at " << worst_f << " Hz";
    std::printf("%s: worst backward error %.3g at %.4g Hz\n", direction_name(d), worst, worst_f);
  }
}

}  // namespace
}  // namespace isolink::link
