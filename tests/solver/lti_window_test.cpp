// The reduced model's output grid refined window by window (GridOptions::window, threads,
// on_rows) against the same grid in one window, and its rows against the closed form (values()),
// on seeded random links: an RLC ladder driven by a random differential pulse train.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <utility>

#include "solver/lti.h"
#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

struct Link {
  Circuit circuit;
  std::vector<Probe> probes;
  double tstop = 0;
};

// Seeded: 3-8 LC sections (R in series, C to ground, random values around a 100 ohm line) from a
// differential driver (two PWL sources, n = -p) with its series resistance, terminated; bursts of
// random-width pulses with 5-30 ns edges over 20 us. Probes: the far end's difference and one
// pin.
std::unique_ptr<Link> random_link(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto link = std::make_unique<Link>();
  link->tstop = 20e-6;
  std::vector<double> pwl_p{0, 0}, pwl_n{0, 0};  // (t, v) pairs; the n line is -p
  auto point = [&](double at, double v) {
    pwl_p.push_back(at), pwl_p.push_back(v);
    pwl_n.push_back(at), pwl_n.push_back(-v);
  };
  for (double t = 0.3e-6; t < 18e-6;) {
    const double edge = 5e-9 + 25e-9 * u(rng), width = 100e-9 + 400e-9 * u(rng);
    const double v = u(rng) < 0.5 ? 2.5 : -2.5;
    point(t, 0), point(t + edge, v), point(t + edge + width, v), point(t + 2 * edge + width, 0);
    t += 2 * edge + width + (u(rng) < 0.3 ? 50e-9 + 2e-6 * u(rng) : 50e-9);
  }
  std::vector<Card> cards{card("vp", {"dp", "0"}, {call("pwl", pwl_p)}),
                          card("vn", {"dn", "0"}, {call("pwl", pwl_n)}),
                          card("rsp", {"dp", "p0"}, {num(20 + 40 * u(rng))}),
                          card("rsn", {"dn", "n0"}, {num(20 + 40 * u(rng))})};
  const int sections = 3 + static_cast<int>(6 * u(rng));
  for (int s = 0; s < sections; ++s) {
    const double l = 0.2e-6 * (0.5 + u(rng)), c = 20e-12 * (0.5 + u(rng)), r = 0.5 * u(rng);
    for (const char* side : {"p", "n"}) {
      const std::string a = side + std::to_string(s),
                        m = side + std::string("m") + std::to_string(s),
                        b = side + std::to_string(s + 1);
      cards.push_back(card(std::string("r") + m, {a, m}, {num(r + 0.01)}));
      cards.push_back(card(std::string("l") + m, {m, b}, {num(l)}));
      cards.push_back(card(std::string("c") + m, {b, "0"}, {num(c)}));
    }
  }
  const std::string p_end = "p" + std::to_string(sections), n_end = "n" + std::to_string(sections);
  cards.push_back(card("rt", {p_end, n_end}, {num(80 + 60 * u(rng))}));
  cards.push_back(card("cc", {p_end, "0"}, {num(10e-12)}));
  cards.push_back(card("cd", {n_end, "0"}, {num(10e-12)}));
  EXPECT_EQ(build(link->circuit, cards), "");
  for (const std::string& p : {"v(" + p_end + "," + n_end + ")", "v(" + p_end + ")"}) {
    auto probe = parse_probe(link->circuit, p);
    EXPECT_TRUE(probe.ok()) << probe.status().message();
    if (probe) link->probes.push_back(*probe);
  }
  return link;
}

TEST(LtiWindows, WindowedGridIsTheOneWindowGridOnSeededRandomLinks) {
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::unique_ptr<Link> link = random_link(seed);
    LtiOptions opt;
    opt.horizon = link->tstop;
    opt.method = LtiOptions::Method::Reduced;
    opt.tie_sources = true;
    StatusOr<LtiResponses> lti = LtiResponses::compute(link->circuit, link->probes, opt);
    ASSERT_TRUE(lti.ok()) << lti.status().message();
    const std::vector<SourceInput> inputs = lti->netlist_inputs(link->tstop);
    LtiResponses::GridOptions one{.tstop = link->tstop};
    one.window = 0;
    LtiResponses::GridInfo one_info;
    const Waveform whole = lti->waveform(inputs, one, &one_info);
    EXPECT_EQ(one_info.warning, "");
    ASSERT_GT(whole.time.size(), 2000u);  // a grid refined after the corners

    // Windows of 1 and 37 first-level cells (20 ns each), on one and on three threads, and
    // handed on window by window: every row the same, at the same time.
    for (auto [window, threads, handed] :
         {std::tuple{20e-9, 1, false}, {740e-9, 3, false}, {740e-9, 2, true}}) {
      SCOPED_TRACE("window " + std::to_string(window) + " s, threads " + std::to_string(threads) +
                   (handed ? ", handed on" : ""));
      LtiResponses::GridOptions grid = one;
      grid.window = window;
      grid.threads = threads;
      Waveform got;
      got.columns.resize(link->probes.size());
      if (handed)
        grid.on_rows = [&](const std::vector<double>& t,
                           const std::vector<std::vector<double>>& v) {
          got.time.insert(got.time.end(), t.begin(), t.end());
          for (size_t p = 0; p < v.size(); ++p)
            got.columns[p].insert(got.columns[p].end(), v[p].begin(), v[p].end());
        };
      LtiResponses::GridInfo info;
      Waveform w = lti->waveform(inputs, grid, &info);
      if (handed) {
        EXPECT_TRUE(w.time.empty());
        w.time = std::move(got.time);
        w.columns = std::move(got.columns);
      }
      EXPECT_EQ(info.rows, one_info.rows);
      ASSERT_EQ(w.time.size(), whole.time.size());
      double dt = 0, dv = 0;
      for (size_t i = 0; i < w.time.size(); ++i) {
        dt = std::max(dt, std::fabs(w.time[i] - whole.time[i]));
        for (size_t p = 0; p < w.columns.size(); ++p)
          dv = std::max(dv, std::fabs(w.columns[p][i] - whole.columns[p][i]));
      }
      EXPECT_EQ(dt, 0.0);
      EXPECT_LT(dv, 1e-6);  // V
    }

    // The rows against the closed form, evaluated apart from the grid (values() steps the modes
    // through these times in one pass of its own): the state carried across windows is exact.
    std::vector<double> every;
    for (size_t i = 0; i < whole.time.size(); i += 7) every.push_back(whole.time[i]);
    const std::vector<std::vector<double>> exact = lti->values(inputs, every);
    double worst = 0;
    for (size_t j = 0; j < every.size(); ++j)
      for (size_t p = 0; p < exact.size(); ++p)
        worst = std::max(worst, std::fabs(exact[p][j] - whole.columns[p][7 * j]));
    EXPECT_LT(worst, 1e-6);
  }
}

}  // namespace
}  // namespace isolink
