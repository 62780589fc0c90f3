// The port model (solver/port_model.h): its AC transfer against the closed form of an RC seen
// from a diode's port, a clipper's knee against the DC equation solved by bisection, and its
// waveforms against the full-circuit Newton transient at reltol 1e-6 (a rectifier with charge
// storage, a clipper driven by a sine, seeded random LC ladders with TVS and rail clamps).
#include "solver/port_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <tuple>

#include "solver/transient.h"
#include "test_cards.h"

namespace isolink {
namespace {
using namespace isolink::testing;

constexpr double kVt = 1.38064852e-23 * 300.15 / 1.6021766208e-19;  // kT/q at 27 degC
constexpr double kGmin = 1e-12;

std::shared_ptr<const CardModel> model(std::vector<std::pair<std::string, double>> params) {
  auto m = std::make_shared<CardModel>();
  m->name = "dtest";
  m->type = "d";
  for (const auto& [k, v] : params) m->params.emplace_back(k, num(v));
  return m;
}

Card diode(std::string name, std::vector<std::string> nodes, std::shared_ptr<const CardModel> m) {
  Card c = card(std::move(name), std::move(nodes), {});
  c.model = std::move(m);
  return c;
}

std::vector<Probe> probes(const Circuit& c, const std::vector<std::string>& texts) {
  std::vector<Probe> out;
  for (const auto& t : texts) {
    StatusOr<Probe> p = parse_probe(c, t);
    EXPECT_TRUE(p.ok()) << t;
    if (p) out.push_back(*p);
  }
  return out;
}

// Max |a - b| over a's times in column k, b interpolated linearly.
double max_difference(const Waveform& a, const Waveform& b, size_t k) {
  double worst = 0;
  size_t j = 0;
  for (size_t i = 0; i < a.samples(); ++i) {
    const double t = a.time[i];
    while (j + 2 < b.samples() && b.time[j + 1] < t) ++j;
    const double t0 = b.time[j], t1 = b.time[j + 1];
    const double f = t1 > t0 ? std::clamp((t - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
    const double v = b.columns[k][j] + f * (b.columns[k][j + 1] - b.columns[k][j]);
    worst = std::max(worst, std::fabs(a.columns[k][i] - v));
  }
  return worst;
}

struct Runs {
  Waveform port, full;
  PortModelStats stats;
};

// The port model at the engine's default options and the full transient at reltol 1e-6 on the same
// cards.
Runs both(const std::vector<Card>& cards, const std::vector<std::string>& texts,
          TransientOptions opt) {
  Runs r;
  Circuit c;
  EXPECT_EQ(build(c, cards), "");
  const std::vector<Probe> ps = probes(c, texts);
  StatusOr<PortModel> m = build_port_model(cards, c, ps, opt.tstop, {});
  EXPECT_TRUE(m.ok()) << m.status().message();
  if (!m) return r;
  TransientOptions po = opt;
  // The run analysis/simulate.cpp keeps at its defaults: its self-check's second, at a tenth of
  // default_reltol, when it agrees with the first.
  po.reltol = PortModelOptions{}.default_reltol / 10;
  StatusOr<Waveform> w = run_port_model(c, *m, po, &r.stats);
  EXPECT_TRUE(w.ok()) << w.status().message();
  if (w) r.port = std::move(*w);
  Circuit full;
  EXPECT_EQ(build(full, cards), "");
  opt.reltol = 1e-6;
  StatusOr<Waveform> f = run_transient(full, opt, probes(full, texts));
  EXPECT_TRUE(f.ok()) << f.status().message();
  if (f) r.full = std::move(*f);
  return r;
}

TEST(PortModel, AcTransferIsTheRcClosedForm) {
  // V1 -> 1 kohm -> out, 10 pF to ground, a diode from out to ground: the port is out-ground and
  // the linear network is R || C || the port's shunt g_s. A unit current drawn at the port gives
  // v = -1 / Y, Y = 1/R + j w C + g_s; the source gives v = (1/R) / Y.
  const std::vector<Card> cards = {card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-6, 1})}),
                                   card("r1", {"in", "out"}, {num(1e3)}),
                                   card("c1", {"out", "0"}, {num(10e-12)}),
                                   diode("d1", {"out", "0"}, model({{"is", 1e-14}}))};
  Circuit c;
  ASSERT_EQ(build(c, cards), "");
  const PortModelOptions po;
  StatusOr<PortModel> m = build_port_model(cards, c, probes(c, {"v(out)"}), 1e-6, po);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->sources, 1);
  ASSERT_EQ(m->ports, 1);
  EXPECT_LE(m->model.stats.error, po.reduced.tol);
  for (double f : {0.0, 1e3, 1e6, 1.6e7, 1e8, 1e9, 3e9}) {
    const std::complex<double> s(0, 2 * std::numbers::pi * f);
    const std::complex<double> y = 1e-3 + s * 10e-12 + po.port_shunt;
    const std::complex<double> z = -1.0 / y, h = 1e-3 / y;
    // inputs: 0 the source, 1 the port; outputs: 0 the probe v(out), 1 the port's voltage.
    for (size_t out : {0u, 1u}) {
      EXPECT_LT(std::abs(m->model.transfer(1, out, s) - z), 1e-5 * (1.0 / (1e-3 + po.port_shunt)))
          << f << " Hz, output " << out;
      EXPECT_LT(std::abs(m->model.transfer(0, out, s) - h), 1e-5) << f << " Hz, output " << out;
    }
  }
}

TEST(PortModel, ClipperFollowsItsKneeOnASlowRamp) {
  // As tests/solver/diode_test.cpp: each row is the DC solution (vin - vd) / r = i(vd).
  const std::vector<Card> cards = {card("v1", {"in", "0"}, {call("pwl", {0, 0, 1e-3, 5})}),
                                   card("r1", {"in", "out"}, {num(1e3)}),
                                   diode("d1", {"out", "0"}, model({{"is", 1e-14}}))};
  Circuit c;
  ASSERT_EQ(build(c, cards), "");
  const std::vector<Probe> ps = probes(c, {"v(in)", "v(out)"});
  StatusOr<PortModel> m = build_port_model(cards, c, ps, 1e-3, {});
  ASSERT_TRUE(m.ok()) << m.status().message();
  // The rows at the steps' ends solve the diode; those inside a step (the march's steps grow to
  // tstop / 50 here) take its current as a straight line over the step, within the step
  // control's trtol reltol |v|: 7e-5 V at reltol 1e-3, 7e-6 V at 1e-4.
  for (const double reltol : {1e-3, 1e-4}) {
    TransientOptions opt{.tstep = 10e-6, .tstop = 1e-3, .reltol = reltol};
    StatusOr<Waveform> w = run_port_model(c, *m, opt);
    ASSERT_TRUE(w.ok()) << w.status().message();
    ASSERT_GT(w->samples(), 100u);  // at least one row each TSTEP
    double worst = 0;
    for (size_t k = 0; k < w->samples(); ++k) {
      const double vin = w->columns[0][k];
      const double vd = std::fabs(vin) < 1e-12 ? 0.0 : [&] {
        double a = -1, b = std::max(vin, 0.0) + 1e-9;
        auto f = [&](double x) {
          return (vin - x) / 1e3 - 1e-14 * (std::exp(x / kVt) - 1) - kGmin * x;
        };
        for (int i = 0; i < 200; ++i) ((f(0.5 * (a + b)) > 0) ? a : b) = 0.5 * (a + b);
        return 0.5 * (a + b);
      }();
      worst = std::max(worst, std::fabs(w->columns[1][k] - vd));
    }
    EXPECT_LT(worst, reltol / 10) << reltol;
    EXPECT_NEAR(w->columns[1].back(), 0.6929, 1e-3);
  }
}

// Method step 5, the rows inside the steps: a series RLC rung by a 1 ns ramp, beside a diode
// held at a constant forward bias by a DC source of its own. The port's voltage never moves, so
// the steps grow to tstop / 50 (40 ns, a fifth of the ringing's period) and nearly every row is
// one the modes were marched to inside a step. Against the closed form of the ramp response
// (R(t) the step response's integral): every row exact to the model's check, the rows at most
// TSTEP apart, and the straight line between rows within a few times trtol reltol |v|peak.
TEST(PortModel, RowsInsideStepsFollowARingingRlcClosedForm) {
  const double r = 10, l = 1e-6, cap = 1e-9, t0 = 10e-9, tr = 1e-9;
  const std::vector<Card> cards = {
      card("v1", {"in", "0"}, {call("pwl", {0, 0, t0, 0, t0 + tr, 1})}),
      card("r1", {"in", "a"}, {num(r)}),
      card("l1", {"a", "out"}, {num(l)}),
      card("c1", {"out", "0"}, {num(cap)}),
      card("v2", {"b", "0"}, {num(1)}),
      card("r2", {"b", "k"}, {num(1e3)}),
      diode("d1", {"k", "0"}, model({{"is", 1e-14}}))};
  Circuit c;
  ASSERT_EQ(build(c, cards), "");
  const TransientOptions opt{.tstep = 10e-9, .tstop = 2e-6, .reltol = 1e-3};
  StatusOr<PortModel> m = build_port_model(cards, c, probes(c, {"v(out)"}), opt.tstop, {});
  ASSERT_TRUE(m.ok()) << m.status().message();
  PortModelStats stats;
  StatusOr<Waveform> w = run_port_model(c, *m, opt, &stats);
  ASSERT_TRUE(w.ok()) << w.status().message();
  const double alpha = r / (2 * l), w0 = 1 / std::sqrt(l * cap);
  const double wd = std::sqrt(w0 * w0 - alpha * alpha), n2 = alpha * alpha + wd * wd;
  auto integral = [&](double t) {  // of the unit step response 1 - e^-at (cos + a/wd sin)
    if (t <= 0) return 0.0;
    const double e = std::exp(-alpha * t), co = std::cos(wd * t), si = std::sin(wd * t);
    const double ic = (alpha - e * (alpha * co - wd * si)) / n2;
    const double is = (wd - e * (alpha * si + wd * co)) / n2;
    return t - ic - alpha / wd * is;
  };
  auto exact = [&](double t) { return (integral(t - t0) - integral(t - t0 - tr)) / tr; };
  const std::vector<double>& v = w->columns[0];
  double peak = 0, worst_row = 0, worst_line = 0, widest = 0;
  for (size_t k = 0; k < w->samples(); ++k) {
    peak = std::max(peak, std::fabs(v[k]));
    worst_row = std::max(worst_row, std::fabs(v[k] - exact(w->time[k])));
    if (k == 0) continue;
    const double dt = w->time[k] - w->time[k - 1], mid = w->time[k - 1] + dt / 2;
    widest = std::max(widest, dt);
    worst_line = std::max(worst_line, std::fabs(0.5 * (v[k - 1] + v[k]) - exact(mid)));
  }
  EXPECT_GT(peak, 1.5);  // it rings: 1.6 V overshoot of a 1 V step
  EXPECT_LT(stats.accepted * 5, static_cast<long>(w->samples()));  // rows inside the steps
  EXPECT_LE(widest, opt.tstep * (1 + 1e-9));                       // TSTEP's rows at least
  EXPECT_LT(worst_row, 2e-5 * peak);                 // the model's check: 2e-6 of the pair's peak
  const double tol = opt.trtol * opt.reltol * peak;  // the rows' interpolation allowance
  EXPECT_LT(worst_line, 3 * tol) << tol;
}

// A rectifier diode with series resistance, junction capacitance and transit time (charge
// storage), shared by the rectifier and the series-ammeter tests.
std::shared_ptr<const CardModel> rectifier_diode() {
  return model({{"is", 1e-8},
                {"n", 1.05},
                {"rs", 0.3},
                {"cjo", 30e-12},
                {"vj", 0.5},
                {"m", 0.45},
                {"tt", 5e-9}});
}

TEST(PortModel, RectifierWithChargeStorageMatchesTheFullTransient) {
  const auto d = rectifier_diode();
  const std::vector<Card> cards = {card("v1", {"in", "0"}, {call("sin", {0, 5, 1e6})}),
                                   card("rs", {"in", "a"}, {num(10)}), diode("d1", {"a", "out"}, d),
                                   card("rl", {"out", "0"}, {num(2e3)}),
                                   card("cl", {"out", "0"}, {num(1e-9)})};
  Runs r = both(cards, {"v(out)", "v(a)"}, {.tstep = 1e-9, .tstop = 5e-6});
  ASSERT_GT(r.port.samples(), 100u);
  for (size_t k = 0; k < 2; ++k) EXPECT_LT(max_difference(r.port, r.full, k), 3e-3) << k;
}

TEST(PortModel, SeriesAmmetersReadTheirDiodesCurrentWithTheSign) {
  // 0 V ammeters in series with diodes (as isolink stress puts one before every clamp): vam1
  // from a into d1's anode (i(vam1) = +i(d1)), vam2 from ground into d2's cathode node (the
  // diode's current enters vam2 at its n- node: i(vam2) = -i(d2)). Both are read from the
  // ports, not through the model; against the full transient's branch currents at 1e-6.
  const auto d = rectifier_diode();
  const std::vector<Card> cards = {card("v1", {"in", "0"}, {call("sin", {0, 5, 1e6})}),
                                   card("rs", {"in", "a"}, {num(10)}),
                                   card("vam1", {"a", "da"}, {num(0)}),
                                   diode("d1", {"da", "out"}, d),
                                   card("rl", {"out", "0"}, {num(2e3)}),
                                   card("cl", {"out", "0"}, {num(1e-9)}),
                                   diode("d2", {"out", "kb"}, d),
                                   card("vam2", {"0", "kb"}, {num(0)})};
  const std::vector<std::string> texts = {"i(vam1)", "v(out)", "i(vam2)"};
  Circuit c;
  ASSERT_EQ(build(c, cards), "");
  StatusOr<PortModel> m = build_port_model(cards, c, probes(c, texts), 5e-6, {});
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->port_current_probes.size(), 2u);
  EXPECT_EQ(m->port_current_probes[0].column, 0);
  EXPECT_EQ(m->port_current_probes[0].sign, 1.0);
  EXPECT_EQ(m->port_current_probes[1].column, 2);
  EXPECT_EQ(m->port_current_probes[1].sign, -1.0);
  EXPECT_EQ(m->probes, 1);  // v(out) alone through the model
  Runs r = both(cards, texts, {.tstep = 1e-9, .tstop = 5e-6});
  ASSERT_GT(r.port.samples(), 100u);
  double peak1 = 0, peak2 = 0;
  for (size_t i = 0; i < r.full.samples(); ++i) {
    peak1 = std::max(peak1, std::fabs(r.full.columns[0][i]));
    peak2 = std::max(peak2, std::fabs(r.full.columns[2][i]));
  }
  ASSERT_GT(peak1, 1e-3);  // mA through the rectifier: the comparison is not of zeros
  ASSERT_GT(peak2, 1e-3);
  EXPECT_LT(max_difference(r.port, r.full, 0), 0.01 * peak1);
  EXPECT_LT(max_difference(r.port, r.full, 1), 3e-3);
  EXPECT_LT(max_difference(r.port, r.full, 2), 0.01 * peak2);
}

TEST(PortModel, ZenerClipperInSeriesMatchesTheFullTransient) {
  // A diode in series with a zener: their junction node is reached by the diodes only.
  const auto sig = model({{"is", 2.52e-9},
                          {"n", 1.752},
                          {"rs", 0.568},
                          {"cjo", 4e-12},
                          {"m", 0.4},
                          {"tt", 20e-9},
                          {"bv", 100},
                          {"ibv", 100e-6}});
  const auto zen = model({{"is", 1e-14},
                          {"rs", 2},
                          {"cjo", 50e-12},
                          {"vj", 0.75},
                          {"m", 0.33},
                          {"bv", 5.1},
                          {"ibv", 5e-3}});
  const std::vector<Card> cards = {card("v1", {"in", "0"}, {call("sin", {0, 10, 100e3})}),
                                   card("r1", {"in", "out"}, {num(1e3)}),
                                   diode("d1", {"out", "mid"}, sig),
                                   diode("dz", {"0", "mid"}, zen),
                                   diode("d3", {"0", "out"}, sig),
                                   card("c1", {"out", "0"}, {num(10e-12)})};
  Runs r = both(cards, {"v(out)"}, {.tstep = 10e-9, .tstop = 20e-6});
  ASSERT_GT(r.port.samples(), 100u);
  EXPECT_LT(max_difference(r.port, r.full, 0), 3e-3);
}

// A seeded random single-ended link: a pulse source through 50 ohm into an LC ladder (a cable of
// N sections with some loss), terminated, with TVS to ground and clamps to a 3.3 V rail placed
// at random nodes; the drive overshoots the rail so the clamps conduct.
std::vector<Card> random_link(unsigned seed) {
  std::mt19937 rng(seed);
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const int sections = std::uniform_int_distribution<int>(4, 10)(rng);
  const double amp = uni(4, 8), tr = uni(2e-9, 10e-9);
  std::vector<Card> cards = {
      card("v1", {"src", "0"}, {call("pulse", {0, amp, 20e-9, tr, tr, 200e-9, 500e-9})}),
      card("rsrc", {"src", "n0"}, {num(uni(20, 60))}), card("vdd", {"rail", "0"}, {num(3.3)})};
  const auto tvs = model({{"is", 1e-12},
                          {"n", 1.1},
                          {"rs", 0.5},
                          {"cjo", 12e-12},
                          {"vj", 0.8},
                          {"m", 0.35},
                          {"bv", uni(5, 7)},
                          {"ibv", 1e-3}});
  const auto pin = model({{"is", 1e-15},
                          {"n", 1.05},
                          {"rs", 5},
                          {"cjo", 1e-12},
                          {"vj", 0.7},
                          {"m", 0.4},
                          {"tt", 1e-9}});
  for (int k = 0; k < sections; ++k) {
    const std::string a = "n" + std::to_string(k), m = "m" + std::to_string(k),
                      b = "n" + std::to_string(k + 1);
    cards.push_back(card("l" + std::to_string(k), {a, m}, {num(uni(0.2e-6, 0.5e-6))}));
    cards.push_back(card("r" + std::to_string(k), {m, b}, {num(uni(0.05, 0.5))}));
    cards.push_back(card("c" + std::to_string(k), {b, "0"}, {num(uni(15e-12, 40e-12))}));
  }
  const std::string end = "n" + std::to_string(sections);
  cards.push_back(card("rterm", {end, "0"}, {num(uni(80, 200))}));
  cards.push_back(diode("dtvs0", {"0", "n0"}, tvs));
  const int mid = std::uniform_int_distribution<int>(1, sections - 1)(rng);
  cards.push_back(diode("dtvs1", {"0", "n" + std::to_string(mid)}, tvs));
  cards.push_back(diode("dclp", {end, "rail"}, pin));
  cards.push_back(diode("dcln", {"0", end}, pin));
  return cards;
}

TEST(PortModel, RandomLinksWithDiodesMatchTheFullTransient) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const std::vector<Card> cards = random_link(seed);
    const int sections = static_cast<int>((cards.size() - 3 - 5) / 3);
    const std::string end = "v(n" + std::to_string(sections) + ")";
    Runs r = both(cards, {end, "v(n0)"}, {.tstep = 1e-9, .tstop = 1e-6});
    ASSERT_GT(r.port.samples(), 100u) << seed;
    for (size_t k = 0; k < 2; ++k)
      EXPECT_LT(max_difference(r.port, r.full, k), 3e-3) << "seed " << seed << " probe " << k;
    std::printf("seed %u: %d sections, %d ports, %d modes, %ld steps; %.3f / %.3f mV\n", seed,
                sections, r.stats.ports, r.stats.modes, r.stats.accepted,
                1e3 * max_difference(r.port, r.full, 0), 1e3 * max_difference(r.port, r.full, 1));
  }
}

// A module 30 V above the chassis, its line floating at its own potential (bleed, clamp diodes to
// its 5 V rail and ground), plugged onto a grounded LC ladder by a switch (ngspice's SW) whose
// control is a PWL source of its own: the port model reads the control from the source.
std::vector<Card> hot_plug(double vplug) {
  auto sw = std::make_shared<CardModel>();
  sw->name = "contact";
  sw->type = "sw";
  sw->params = {{"vt", num(0.5)}, {"ron", num(0.02)}, {"roff", num(1e12)}};
  const auto pin = model({{"is", 1e-14}, {"n", 1.0}, {"rs", 2}, {"cjo", 2e-12}});
  std::vector<Card> cards = {
      card("vplug", {"g", "0"}, {num(vplug)}),
      card("vrail", {"rail", "g"}, {num(5)}),
      card("rbleed", {"mod", "g"}, {num(1e7)}),
      card("cmod", {"mod", "g"}, {num(100e-12)}),
      card("cgnd", {"g", "0"}, {num(1e-9)}),
      diode("dhi", {"mod", "rail"}, pin),
      diode("dlo", {"g", "mod"}, pin),
      card("vctl", {"ctl", "0"}, {call("pwl", {0, 0, 100e-9, 0, 101e-9, 1})}),
      card("rterm", {"n6", "0"}, {num(120)})};
  Card s1 = card("s1", {"n0", "mod", "ctl", "0"}, {});
  s1.model = sw;
  cards.push_back(s1);
  for (int k = 0; k < 6; ++k) {
    const std::string a = "n" + std::to_string(k), m = "m" + std::to_string(k),
                      b = "n" + std::to_string(k + 1);
    cards.push_back(card("l" + std::to_string(k), {a, m}, {num(0.3e-6)}));
    cards.push_back(card("r" + std::to_string(k), {m, b}, {num(0.2)}));
    cards.push_back(card("c" + std::to_string(k), {b, "0"}, {num(30e-12)}));
  }
  return cards;
}

TEST(PortModel, SwitchedHotPlugMatchesTheFullTransient) {
  Runs r = both(hot_plug(30), {"v(n0)", "v(mod,g)"}, {.tstep = 1e-9, .tstop = 1e-6});
  ASSERT_GT(r.port.samples(), 100u);
  ASSERT_GT(r.full.samples(), 100u);
  EXPECT_EQ(r.stats.ports, 3);  // two diodes and the switch
  // The contact closes at 100.5 ns, where each engine takes the step that crosses the control's
  // threshold as a corner: the edges can sit a fraction of a step apart, so the peaks and the
  // settled values are compared, not the samples on the edge. The port model runs at its
  // reltol 1e-4: a 30 V peak within 3 mV + 2e-4 of it (the full transient at 1e-6).
  for (size_t k = 0; k < 2; ++k) {
    double pmax = -1e9, pmin = 1e9, fmax = -1e9, fmin = 1e9;
    for (double v : r.port.columns[k]) pmax = std::max(pmax, v), pmin = std::min(pmin, v);
    for (double v : r.full.columns[k]) fmax = std::max(fmax, v), fmin = std::min(fmin, v);
    EXPECT_NEAR(pmax, fmax, 3e-3 + 2e-4 * std::fabs(fmax)) << k;
    EXPECT_NEAR(pmin, fmin, 3e-3 + 2e-4 * std::fabs(fmin)) << k;
    EXPECT_NEAR(r.port.columns[k].back(), r.full.columns[k].back(), 3e-3) << k;
  }
  // A probe on the control's own node: the source is then an input too, so the probe reads it.
  Runs c = both(hot_plug(30), {"v(ctl)"}, {.tstep = 1e-9, .tstop = 1e-6});
  ASSERT_GT(c.port.samples(), 10u);
  EXPECT_NEAR(c.port.columns[0].front(), 0.0, 1e-9);
  EXPECT_NEAR(c.port.columns[0].back(), 1.0, 1e-6);
  // The switch did close: the line swings by volts (the module's 30 V through its clamps).
  double swing = 0;
  for (double v : r.port.columns[0]) swing = std::max(swing, std::fabs(v));
  EXPECT_GT(swing, 1.0);
  // A 0 V ammeter between the cable and the contact (as isolink stress measures the inrush):
  // read from the switch's port, positive from the cable into the module.
  std::vector<Card> metered = hot_plug(30);
  for (Card& k : metered)
    if (k.name == "s1") k.nodes[0] = "smid";
  metered.push_back(card("vam", {"n0", "smid"}, {num(0)}));
  Circuit mc;
  ASSERT_EQ(build(mc, metered), "");
  StatusOr<PortModel> pm = build_port_model(metered, mc, probes(mc, {"i(vam)"}), 1e-6, {});
  ASSERT_TRUE(pm.ok()) << pm.status().message();
  ASSERT_EQ(pm->port_current_probes.size(), 1u);
  EXPECT_EQ(pm->port_current_probes[0].sign, 1.0);
  Runs a = both(metered, {"i(vam)"}, {.tstep = 1e-9, .tstop = 1e-6});
  double pmax = 0, fmax = 0, pq = 0, fq = 0;
  for (const auto& [w, peak, charge] : {std::tie(a.port, pmax, pq), std::tie(a.full, fmax, fq)})
    for (size_t j = 1; j < w.samples(); ++j) {
      peak = std::max(peak, std::fabs(w.columns[0][j]));
      charge += 0.5 * (w.columns[0][j] + w.columns[0][j - 1]) * (w.time[j] - w.time[j - 1]);
    }
  ASSERT_GT(fmax, 0.1);  // amperes of inrush: the comparison is not of zeros
  EXPECT_NEAR(pmax, fmax, 0.01 * fmax);
  EXPECT_NEAR(pq, fq, 0.01 * std::fabs(fq));
  EXPECT_LT(fq, 0.0);  // the module at 30 V pushes charge out into the cable
}

TEST(PortModel, RefusesASwitchWhoseControlIsNotASourceOfItsOwn) {
  std::vector<Card> cards = hot_plug(30);
  cards.push_back(card("rload", {"ctl", "0"}, {num(1e3)}));  // the control node is shared now
  Circuit c;
  ASSERT_EQ(build(c, cards), "");
  StatusOr<PortModel> m = build_port_model(cards, c, probes(c, {"v(n0)"}), 1e-6, {});
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("control is not a voltage source of its own"),
            std::string::npos)
      << m.status().message();
}

TEST(PortModel, RefusesUicAndCircuitsWithoutDiodes) {
  const std::vector<Card> linear = {card("v1", {"in", "0"}, {num(1)}),
                                    card("r1", {"in", "out"}, {num(1e3)}),
                                    card("c1", {"out", "0"}, {num(1e-9)})};
  Circuit c;
  ASSERT_EQ(build(c, linear), "");
  EXPECT_FALSE(build_port_model(linear, c, probes(c, {"v(out)"}), 1e-6, {}).ok());
  std::vector<Card> cards = linear;
  cards.push_back(diode("d1", {"out", "0"}, model({{"is", 1e-14}})));
  Circuit d;
  ASSERT_EQ(build(d, cards), "");
  StatusOr<PortModel> m = build_port_model(cards, d, probes(d, {"v(out)"}), 1e-6, {});
  ASSERT_TRUE(m.ok()) << m.status().message();
  TransientOptions opt{.tstep = 1e-9, .tstop = 1e-6, .uic = true};
  StatusOr<Waveform> w = run_port_model(d, *m, opt);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("uic"), std::string::npos) << w.status().message();
}

}  // namespace
}  // namespace isolink
