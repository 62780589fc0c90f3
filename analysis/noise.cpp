#include "analysis/noise.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "netlists/link/cards.h"
#include "netlists/spice_writer.h"
#include "solver/ac.h"
#include "solver/circuit.h"

namespace isolink::analysis {

namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;
// Conversion below this (V per unit of injection) counts as none: keeps immunity finite.
constexpr double kFloor = 1e-30;

struct SlotDelta {
  int row = 0, col = 0;  // unknown indices (ground = 0)
  double dg = 0, dc = 0;
};

bool starts_with(const std::string& s, const std::string& p) {
  return s.rfind(p, 0) == 0;
}

}  // namespace

std::vector<ToleranceGroup> tolerance_groups(const std::vector<Card>& cards,
                                             const link::NoiseTolerances& t) {
  using TolGroup = ToleranceGroup;
  std::vector<TolGroup> groups;
  TolGroup cable_p{"cable chassis C, P", "cable_chassis_c", {}, t.cable_chassis_c};
  TolGroup cable_n{"cable chassis C, N", "cable_chassis_c", {}, t.cable_chassis_c};
  for (size_t i = 0; i < cards.size(); ++i) {
    const Card& c = cards[i];
    const std::string& n = c.name;
    if (c.args.empty() || c.args[0].kind != CardArg::Kind::Number) continue;
    if (starts_with(n, "ccab_gp")) {
      cable_p.cards.push_back(i);
      continue;
    }
    if (starts_with(n, "ccab_gn")) {
      cable_n.cards.push_back(i);
      continue;
    }
    const char* kind = nullptr;
    double tol = 0;
    for (const std::string side : {"tx", "rx"}) {
      auto is = [&](const std::string& stem) { return n == stem + "p" || n == stem + "n"; };
      if (is("c" + side + "iso")) kind = "isolation_cap", tol = t.isolation_cap;
      if (is("r" + side + "bser") || is("r" + side + "bpin")) kind = "series_r", tol = t.series_r;
      if (is("c" + side + "bbyp")) kind = "bypass_c", tol = t.bypass_c;
      if (is("c" + side + "y") || is("c" + side + "cab")) kind = "y_cap", tol = t.y_cap;
      if (is("c" + side + "esd")) kind = "esd", tol = t.esd;
      if (is("t" + side + ".ci")) kind = "winding_c", tol = t.winding_c;
      if (starts_with(n, "l" + side) && n.find('.') != std::string::npos) {
        const std::string leaf = n.substr(n.find('.') + 1);
        if (leaf == "lp" || leaf == "ln") kind = "choke_imbalance", tol = t.choke_imbalance;
        if (leaf == "cwp" || leaf == "cwn") kind = "winding_c", tol = t.winding_c;
      }
    }
    if (n == "rrxinp" || n == "rrxinn" || n == "crxinp" || n == "crxinn")
      kind = "rx_pin", tol = t.rx_pin;
    if (kind != nullptr && tol > 0) groups.push_back(TolGroup{n, kind, {i}, tol});
  }
  for (TolGroup* g : {&cable_p, &cable_n})
    if (!g->cards.empty() && g->tol > 0) groups.push_back(*g);
  return groups;
}

namespace {

StatusOr<Circuit*> build_circuit(const std::vector<Card>& cards, Circuit& c) {
  if (Status s = link::add_cards(c, cards); !s.ok()) return s;
  if (Status s = c.finalize(); !s.ok()) return s;
  return &c;
}

double db(double ratio) {
  return 20 * std::log10(std::max(ratio, 1e-20));
}

// Per pulse: the largest sine amplitude a with vend - a >= vend_min and
// vstart - a >= vstart_required(vend - a) (bisection; the rule is a step in vend).
double amplitude_budget(const eye::PulseMetrics& p, const eye::Rules& r) {
  if (!p.vstart.measured() || !p.vend.measured()) return std::numeric_limits<double>::infinity();
  auto ok = [&](double a) {
    return p.vend.value - a >= r.vend_min &&
           p.vstart.value - a >= r.vstart_required(p.vend.value - a);
  };
  if (!ok(0)) return 0;
  double lo = 0, hi = std::max(p.vstart.value, p.vend.value) + 1;
  for (int i = 0; i < 60; ++i) {
    const double mid = (lo + hi) / 2;
    (ok(mid) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

// The function is smooth between the corners' switching angles: a 0.5 degree scan, then a
// golden-section search around its best (the scan alone is under 4e-5 short).
WorstCorner worst_corner(Complex h0, const std::vector<Complex>& s) {
  auto value = [&](double theta) {
    const Complex u = std::polar(1.0, -theta);
    double v = (h0 * u).real();
    for (const Complex& si : s) v += std::abs((si * u).real());
    return v;
  };
  WorstCorner best{value(std::arg(h0)), std::arg(h0)};
  const double step = kPi / 360.0;
  for (int k = 0; k < 720; ++k)
    if (const double v = value(step * k); v > best.value) best = {v, step * k};
  const double g = (std::sqrt(5.0) - 1) / 2;
  double a = best.theta - step, b = best.theta + step;
  double c = b - g * (b - a), d = a + g * (b - a), fc = value(c), fd = value(d);
  for (int i = 0; i < 60; ++i) {
    if (fc > fd) {
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = value(c);
    } else {
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = value(d);
    }
  }
  if (fc > best.value) best = {fc, c};
  if (fd > best.value) best = {fd, d};
  return best;
}

std::vector<Contributor> contributors_at(const std::vector<ToleranceGroup>& groups,
                                         const std::vector<Complex>& s_dm, double theta) {
  std::vector<Contributor> out;
  const Complex u = std::polar(1.0, -theta);
  double sum = 0;
  for (size_t i = 0; i < groups.size() && i < s_dm.size(); ++i) {
    const double c = std::abs((s_dm[i] * u).real());
    sum += c;
    out.push_back({groups[i].name, groups[i].kind, c});
  }
  if (!(sum > 0) || !std::isfinite(sum)) return {};
  for (Contributor& c : out) c.share /= sum;
  std::stable_sort(out.begin(), out.end(),
                   [](const Contributor& a, const Contributor& b) { return a.share > b.share; });
  return out;
}

NoiseBudget noise_budget(const eye::CheckResult& check, const eye::Rules& rules,
                         double pin_signal) {
  NoiseBudget b;
  const double inf = std::numeric_limits<double>::infinity();
  double slowest = 0;
  for (const eye::PulseMetrics& p : check.pulses)
    if (p.edge.measured()) slowest = std::max(slowest, p.edge.value);
  if (!(slowest > 0)) slowest = rules.edge_max;  // no edge measured: the rule's limit
  b.slope = 2 * rules.vth / slowest;
  b.amplitude = b.width = b.edge = inf;
  for (const eye::PulseMetrics& p : check.pulses) {
    if (p.truncated) continue;
    b.amplitude = std::min(b.amplitude, amplitude_budget(p, rules));
    if (p.width.judged()) b.width = std::min(b.width, std::max(0.0, p.width.margin) * b.slope / 2);
    if (p.edge.judged()) b.edge = std::min(b.edge, std::max(0.0, p.edge.margin) * b.slope / 2);
  }
  b.idle = rules.vth;
  b.dm_amplitude = b.idle;
  b.limited_by = "idle";
  for (auto [v, name] : {std::pair{b.amplitude, "vstart/vend"}, std::pair{b.width, "width"},
                         std::pair{b.edge, "edge"}})
    if (v < b.dm_amplitude) b.dm_amplitude = v, b.limited_by = name;
  // A link that fails on its own has no budget.
  if (!check.pass) b.dm_amplitude = 0, b.limited_by = "the link fails without noise";
  for (double* v : {&b.amplitude, &b.width, &b.edge})
    if (std::isinf(*v)) *v = b.idle;
  b.pin_signal = pin_signal;
  return b;
}

double noise_peak_factor(const link::NoiseSpec& n) {
  return std::sqrt(2.0) * (n.modulation == "am" ? 1.8 : 1.0);
}

std::vector<double> noise_frequencies(const link::NoiseSpec& n) {
  const double decades = std::log10(n.f_stop / n.f_start);
  const int steps = std::max(1, static_cast<int>(std::ceil(decades * n.points_per_decade - 1e-9)));
  std::vector<double> f;
  for (int i = 0; i <= steps; ++i) f.push_back(n.f_start * std::pow(10.0, decades * i / steps));
  f.back() = n.f_stop;
  return f;
}

namespace {

// The volts per ampere of calibrated clamp current a clamp induces in each wire, by wire p or n:
// the jig's loop (calibration_r) plus the clamp's own impedance; bci both the same, dm half each,
// opposite.
double clamp_volts(const link::NoiseSpec& ns, char side) {
  const double v = ns.calibration_r + ns.clamp_r;
  if (ns.injection != "dm") return v;
  return side == 'n' ? -v / 2 : v / 2;
}

// Adds the clamp's source and impedance in series in each wire between node `a_side` (toward
// the link's transmitting end) and `b_side`, as sources vnoisep / vnoisen.
void add_clamp(const link::NoiseSpec& ns, char side, const std::string& a_side,
               const std::string& b_side, NoiseCircuit& out) {
  std::vector<Card>& cards = out.link.netlist.cards;
  const std::string name = fmt::format("vnoise{}", side), mid = fmt::format("noise_{}_r", side);
  cards.push_back(link::make_card('v', name, {b_side, mid}, {link::number_arg(0)}));
  cards.push_back(link::make_card('r', fmt::format("rnoise{}", side), {mid, a_side},
                                  {link::number_arg(2 * ns.clamp_r)}));
  out.sources.push_back({name, clamp_volts(ns, side)});
}

}  // namespace

Status measured_cable_injection(const link::LinkSpec& spec) {
  const link::NoiseSpec& ns = spec.noise;
  if (spec.cable.touchstone.empty() || ns.injection == "ground_shift" || ns.position == 0.0 ||
      ns.position == 1.0)
    return Status::Ok();
  return Status::Error(fmt::format(
      "noise: {} injection at position {:g} needs a node inside the cable, and a measured cable "
      "(cable.touchstone: {}) has only its two ends: set noise.position to 0 (the clamp at the "
      "tx end's connector) or 1 (at the rx end's), or use injection: ground_shift",
      ns.injection, ns.position, spec.cable.touchstone));
}

namespace {

// bci / dm on a measured cable (measured_cable_injection: position 0 or 1): the clamp between the
// module's connector and the cable's port at that end. The cable's cards (named g/c/r + "cab_")
// attach to a node of their own there, and the clamp joins it to the module's.
Status inject_at_measured_cable_end(const link::LinkSpec& spec, link::Direction d,
                                    NoiseCircuit& out) {
  if (Status s = measured_cable_injection(spec); !s.ok()) return s;
  const link::NoiseSpec& ns = spec.noise;
  const double x = d == link::Direction::kDown ? ns.position : 1 - ns.position;
  const bool at_from_end = x < 0.5;  // the link's transmitting end (0) or receiving end (1)
  for (int w = 0; w < 2; ++w) {
    const char side = w == 0 ? 'p' : 'n';
    const std::string& module = out.link.cable_ends[at_from_end ? w : 2 + w];
    const std::string port = fmt::format("noise_cab_{}", side);
    bool moved = false;
    for (Card& c : out.link.netlist.cards) {
      if (!(starts_with(c.name, "gcab_") || starts_with(c.name, "ccab_") ||
            starts_with(c.name, "rcab_")))
        continue;
      for (std::string& node : c.nodes)
        if (node == module) node = port, moved = true;
    }
    if (!moved)
      return Status::Error(fmt::format("noise: no card of the measured cable at {}", module));
    if (at_from_end)
      add_clamp(ns, side, module, port, out);
    else
      add_clamp(ns, side, port, module, out);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<NoiseCircuit> build_noise_circuit(const link::LinkSpec& spec,
                                           const link::PartLibrary& parts, link::Direction d,
                                           const NoiseOptions& opt) {
  NoiseCircuit out;
  link::ExpandOptions eo = opt.expand;
  eo.tx_ground = out.tx_ground;
  eo.rx_ground = out.rx_ground;
  StatusOr<link::ExpandedLink> ex = link::expand_link(spec, parts, d, eo);
  if (!ex) return ex.status();
  out.link = std::move(*ex);
  out.link.netlist.tran.reset();
  out.link.netlist.title = fmt::format("isolink noise '{}', {}, {} injection", spec.name,
                                       out.link.description, spec.noise.injection);
  std::vector<Card>& cards = out.link.netlist.cards;
  const link::NoiseSpec& ns = spec.noise;
  if (ns.injection == "ground_shift") {
    cards.push_back(
        link::make_card('v', "vnoise", {out.rx_ground, out.tx_ground}, {link::number_arg(0)}));
    out.sources = {{"vnoise", 1.0}};
    return out;
  }
  if (!spec.cable.touchstone.empty()) {
    if (Status s = inject_at_measured_cable_end(spec, d, out); !s.ok()) return s;
    return out;
  }
  // bci / dm: at the cable node nearest the position (from the spec's tx end).
  const int n = out.link.cable_segments;
  if (n < 2)
    return Status::Error(fmt::format(
        "noise: {} injection needs a cable node inside the cable; the cable has {} segment "
        "(set cable.segments >= 2)",
        ns.injection, n));
  const double x = d == link::Direction::kDown ? ns.position : 1 - ns.position;
  const int k = std::clamp(static_cast<int>(std::lround(x * n)), 1, n - 1);
  // The clamp induces the same series voltage in both wires: a source in each conductor between
  // segment k and segment k + 1 (whose first series element is re-attached to the source).
  for (char side : {'p', 'n'}) {
    const std::string node = fmt::format("cab_{}{}", side, k);
    const std::string inner = fmt::format("noise_{}", side);
    bool moved = false;
    for (const char* letter : {"r", "l"}) {
      const std::string first = fmt::format("{}cab_{}{}", letter, side, k + 1);
      for (Card& c : cards)
        if (!moved && c.name == first && !c.nodes.empty() && c.nodes[0] == node)
          c.nodes[0] = inner, moved = true;
    }
    if (!moved)
      return Status::Error(
          fmt::format("noise: no series element of cable segment {} at {}", k + 1, node));
    // The clamp's source impedance (common mode: both wires' resistors in parallel).
    add_clamp(ns, side, node, inner, out);
  }
  return out;
}

std::string noise_spice(const NoiseCircuit& c, const link::NoiseSpec& n) {
  std::string text = write_spice(c.link.netlist);
  std::string out;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line == ".end") continue;
    for (const auto& [name, amp] : c.sources)
      if (starts_with(line, name + " ")) line += fmt::format(" ac {:.12g}", amp);
    out += line + "\n";
  }
  out += fmt::format(".options rshunt=1e12\n.ac dec {} {:.12g} {:.12g}\n.end\n",
                     n.points_per_decade, n.f_start, n.f_stop);
  return out;
}

StatusOr<std::vector<ConversionPoint>> conversion_sweep(const std::vector<Card>& cards,
                                                        const ConversionRequest& req,
                                                        int* factorizations, int* unknowns) {
  Circuit circuit;
  if (StatusOr<Circuit*> c = build_circuit(cards, circuit); !c) return c.status();
  if (unknowns) *unknowns = circuit.unknown_count();
  StatusOr<AcAnalysis> ac = AcAnalysis::create(circuit);
  if (!ac) return ac.status();

  // Each group moved by +tol: the matrix entries that change.
  std::vector<std::vector<SlotDelta>> deltas;
  const std::vector<int>& cs = ac->col_start();
  const std::vector<int>& ri = ac->row_index();
  for (const ToleranceGroup& g : req.groups) {
    std::vector<Card> moved = cards;
    for (size_t i : g.cards) {
      if (i >= moved.size() || moved[i].args.empty() ||
          moved[i].args[0].kind != CardArg::Kind::Number)
        return Status::Error(
            fmt::format("noise: tolerance group '{}' names a card without a value", g.name));
      moved[i].args[0].number *= 1 + g.tol;
    }
    Circuit pc;
    if (StatusOr<Circuit*> c = build_circuit(moved, pc); !c) return c.status();
    StatusOr<AcAnalysis> pa = AcAnalysis::create(pc);
    if (!pa) return pa.status();
    std::vector<SlotDelta> d;
    for (int col = 0; col + 1 < static_cast<int>(cs.size()); ++col)
      for (int k = cs[col]; k < cs[col + 1]; ++k) {
        const double dg = pa->g_values()[k] - ac->g_values()[k];
        const double dc = pa->c_values()[k] - ac->c_values()[k];
        if (dg != 0 || dc != 0) d.push_back(SlotDelta{ri[k] + 1, col + 1, dg, dc});
      }
    deltas.push_back(std::move(d));
  }

  const int p = circuit.find_node(req.p), n = circuit.find_node(req.n);
  const int ref = circuit.find_node(req.ref);
  if (p < 0 || n < 0 || ref < 0)
    return Status::Error(fmt::format("noise: the circuit has no node '{}'", p < 0   ? req.p
                                                                            : n < 0 ? req.n
                                                                                    : req.ref));
  const size_t size = circuit.unknown_count() + 1;
  AcAnalysis::Vector b(size, 0.0), cp(size, 0.0), cn(size, 0.0);
  for (const auto& [name, amp] : req.sources)
    if (Status s = ac->add_excitation(name, amp, b); !s.ok()) return s;
  cp[p] += 1, cp[ref] -= 1;
  cn[n] += 1, cn[ref] -= 1;
  cp[0] = cn[0] = 0;

  std::vector<ConversionPoint> out;
  for (double f : req.frequencies) {
    if (Status s = ac->factor(f); !s.ok()) return s;
    if (factorizations) ++*factorizations;
    const AcAnalysis::Vector x = ac->solve_factored(b);
    const AcAnalysis::Vector zp = ac->solve_transposed(cp);
    const AcAnalysis::Vector zn = ac->solve_transposed(cn);
    const double w = 2 * kPi * f;
    std::vector<Complex> sp, sn, sdm, scm;
    for (const std::vector<SlotDelta>& d : deltas) {
      Complex ap = 0, an = 0;
      for (const SlotDelta& e : d) {
        const Complex ax = Complex(e.dg, w * e.dc) * x[e.col];
        ap -= zp[e.row] * ax;
        an -= zn[e.row] * ax;
      }
      sp.push_back(ap), sn.push_back(an);
      sdm.push_back(ap - an), scm.push_back((ap + an) / 2.0);
    }
    ConversionPoint pt;
    pt.freq_hz = f;
    pt.vp = x[p] - x[ref];
    pt.vn = x[n] - x[ref];
    const WorstCorner dm = worst_corner(pt.vp - pt.vn, sdm);
    pt.dm_worst = dm.value;
    pt.dm_theta = dm.theta;
    pt.cm_worst = worst_corner((pt.vp + pt.vn) / 2.0, scm).value;
    pt.pin_worst = std::max(worst_corner(pt.vp, sp).value, worst_corner(pt.vn, sn).value);
    pt.sp = std::move(sp);
    pt.sn = std::move(sn);
    out.push_back(std::move(pt));
  }
  return out;
}

namespace {

// The immunity (level units) of a response per unit of injection: differential |dm| and largest
// pin |pin| at the modulation's peak against the receiver budget and the pins' room.
struct ImmunityAt {
  double value = 0;
  bool dm_limited = true;
};
ImmunityAt immunity_of(double dm, double pin, double budget, double pin_room, double peak) {
  const double imm_dm = budget / (std::max(kFloor, dm) * peak);
  const double imm_pin = pin_room / (std::max(kFloor, pin) * peak);
  return {std::min(imm_dm, imm_pin), imm_dm <= imm_pin};
}

// splitmix64 (Steele, Lea, Flood 2014): a fixed, portable sequence, unlike the standard
// distributions, whose algorithms the C++ standard leaves to the library.
uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace

StatisticalImmunity monte_carlo_immunity(const std::vector<ConversionPoint>& conv, size_t groups,
                                         const link::NoiseSpec& ns, uint64_t seed, double budget,
                                         double pin_room, double peak) {
  StatisticalImmunity st;
  st.samples = std::max(1, ns.samples);
  st.seed = seed;
  uint64_t state = seed;
  std::vector<double> d(groups);
  std::vector<std::pair<double, double>> minima;  // (immunity, frequency) per board
  for (int b = 0; b < st.samples; ++b) {
    for (double& x : d) x = 2 * (static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53) - 1;
    std::pair<double, double> worst{std::numeric_limits<double>::infinity(), 0};
    for (const ConversionPoint& c : conv) {
      Complex vp = c.vp, vn = c.vn;
      for (size_t i = 0; i < groups && i < c.sp.size(); ++i)
        vp += c.sp[i] * d[i], vn += c.sn[i] * d[i];
      const double imm = immunity_of(std::abs(vp - vn), std::max(std::abs(vp), std::abs(vn)),
                                     budget, pin_room, peak)
                             .value;
      if (imm < worst.first) worst = {imm, c.freq_hz};
    }
    minima.push_back(worst);
  }
  std::sort(minima.begin(), minima.end());
  // The largest value that at least 99 % of the boards reach.
  const size_t n = minima.size();
  const size_t reach = static_cast<size_t>(std::ceil((1 - st.percentile / 100) * n - 1e-9));
  const size_t k = n - std::min(n, reach);
  st.immunity_min = minima[k].first;
  st.immunity_min_freq = minima[k].second;
  st.median = minima[n / 2].first;
  st.pass = ns.level <= st.immunity_min;
  return st;
}

namespace {

StatusOr<NoiseDirection> analyze_direction(const link::LinkSpec& spec,
                                           const link::PartLibrary& parts,
                                           const NoiseDirectionInput& in, const NoiseOptions& opt,
                                           const NoiseBudget& budget, double peak_factor,
                                           int* factorizations) {
  NoiseDirection nd;
  nd.direction = in.direction;
  nd.budget = budget;
  StatusOr<NoiseCircuit> nc = build_noise_circuit(spec, parts, in.direction, opt);
  if (!nc) return nc.status();
  nd.description = nc->link.description;
  const std::vector<Card>& cards = nc->link.netlist.cards;
  ConversionRequest req;
  req.sources = nc->sources;
  req.ref = nc->rx_ground;
  req.groups = tolerance_groups(cards, spec.noise.tolerance);
  for (const ToleranceGroup& g : req.groups)
    nd.tolerances.push_back(fmt::format("{} +/-{:g} %", g.name, g.tol * 100));
  const link::NoiseSpec& ns = spec.noise;
  req.frequencies = noise_frequencies(ns);
  StatusOr<std::vector<ConversionPoint>> conv =
      conversion_sweep(cards, req, factorizations, &nd.unknowns);
  if (!conv) return conv.status().with_context(nd.description);

  const double pin_room = std::max(0.0, ns.pin_limit - budget.pin_signal);
  nd.immunity_min = std::numeric_limits<double>::infinity();
  const ConversionPoint* weakest = nullptr;
  for (const ConversionPoint& c : *conv) {
    NoisePoint pt;
    pt.freq_hz = c.freq_hz;
    pt.dm = c.vp - c.vn;
    pt.cm = (c.vp + c.vn) / 2.0;
    pt.dm_worst = std::max(kFloor, c.dm_worst);
    pt.cm_worst = c.cm_worst;
    pt.pin_worst = std::max(kFloor, c.pin_worst);
    const double cm_ref = std::max(std::abs(pt.cm), kFloor);
    pt.cm_to_dm_db = std::max(-400.0, db(pt.dm_worst / cm_ref));
    pt.cm_to_dm_nominal_db = std::max(-400.0, db(std::abs(pt.dm) / cm_ref));
    pt.dm_v = pt.dm_worst * ns.level * peak_factor;
    pt.pin_cm_v = pt.cm_worst * ns.level * peak_factor;
    const ImmunityAt imm =
        immunity_of(pt.dm_worst, pt.pin_worst, budget.dm_amplitude, pin_room, peak_factor);
    pt.immunity = imm.value;
    pt.limited_by = imm.dm_limited ? "dm" : "pins";
    if (pt.immunity < nd.immunity_min)
      nd.immunity_min = pt.immunity, nd.immunity_min_freq = c.freq_hz, weakest = &c;
    nd.points.push_back(pt);
  }
  nd.pass_corner = ns.level <= nd.immunity_min;
  // Each direction its own stream of the seed.
  const uint64_t seed = static_cast<uint64_t>(ns.seed) * 2 + (in.direction == link::Direction::kUp);
  nd.statistical = monte_carlo_immunity(*conv, req.groups.size(), ns, seed, budget.dm_amplitude,
                                        pin_room, peak_factor);
  nd.pass = ns.verdict_on == "statistical" ? nd.statistical.pass : nd.pass_corner;
  if (weakest != nullptr) {
    std::vector<Complex> s_dm;
    for (size_t i = 0; i < weakest->sp.size(); ++i) s_dm.push_back(weakest->sp[i] - weakest->sn[i]);
    nd.contributors = contributors_at(req.groups, s_dm, weakest->dm_theta);
  }
  return nd;
}

// Superposes the worst frequency's differential noise (at the level's peak, worst corner) on the
// link's received waveform at `phases` phases and runs the checker on each.
TimeDomainCheck confirm_in_time(const link::LinkSpec& spec, const NoiseDirectionInput& in,
                                const NoiseDirection& nd) {
  TimeDomainCheck td;
  if (!spec.noise.time_domain) {
    td.skipped = "noise.time_domain is false";
    return td;
  }
  if (!spec.stimulus.tones.empty()) {
    td.skipped = "the stimulus has tones (the check covers data frames only)";
    return td;
  }
  if (in.wave == nullptr || in.rules == nullptr || in.wave->samples() < 2) {
    td.skipped = "no waveform";
    return td;
  }
  const NoisePoint* worst = nullptr;
  for (const NoisePoint& p : nd.points)
    if (p.freq_hz == nd.immunity_min_freq) worst = &p;
  if (worst == nullptr) {
    td.skipped = "no frequency";
    return td;
  }
  td.freq_hz = worst->freq_hz;
  td.dm_amplitude = worst->dm_v;
  td.predicted_pass = nd.pass_corner;
  // At least 20 samples per period, never coarser than the simulation's output step.
  const Waveform& w = *in.wave;
  const double span = w.time.back() - w.time.front();
  const double step0 = span / static_cast<double>(w.samples() - 1);
  const double dt = std::min(step0, 1 / (20 * td.freq_hz));
  const size_t count = static_cast<size_t>(span / dt) + 1;
  std::vector<double> t(count), v0(count), v(count);
  for (size_t i = 0; i < count; ++i) {
    t[i] = w.time.front() + dt * static_cast<double>(i);
    v0[i] = w.value_at(0, t[i]);
  }
  eye::CheckOptions co;
  if (!in.expected.empty()) co.expect = in.expected;
  td.phases = 8;
  for (int k = 0; k < td.phases; ++k) {
    const double phi = 2 * kPi * k / td.phases;
    for (size_t i = 0; i < count; ++i)
      v[i] = v0[i] + td.dm_amplitude * std::sin(2 * kPi * td.freq_hz * t[i] + phi);
    StatusOr<eye::CheckResult> r = eye::check_samples(t, v, *in.rules, co);
    if (!r) {
      td.failures.push_back(fmt::format("phase {} deg: {}", 45 * k, r.status().message()));
      continue;
    }
    if (r->pass)
      ++td.phases_pass;
    else if (!r->reasons.empty())
      td.failures.push_back(fmt::format("phase {} deg: {}", 45 * k, r->reasons.front()));
    if (r->expect_match && !r->bytes.empty()) ++td.phases_decoded;
  }
  td.done = true;
  return td;
}

double max_abs_column(const Waveform& w, size_t k) {
  double m = 0;
  if (k < w.columns.size())
    for (double v : w.columns[k]) m = std::max(m, std::abs(v));
  return m;
}

}  // namespace

StatusOr<NoiseResult> analyze_noise(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                    std::span<const NoiseDirectionInput> inputs,
                                    const NoiseOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  // Noise immunity is a small-signal (AC) analysis around the operating point; a TVS or a clamp
  // that conducts under the injected level is outside it, and one that does not is its
  // capacitance: the user says which by giving esd a capacitance.
  if (std::string why = link::linear_only(spec, "noise (a small-signal analysis)"); !why.empty())
    return Status::Error(why);
  if (Status s = measured_cable_injection(spec); !s.ok()) return s;
  NoiseResult r;
  r.spec = spec.noise;
  r.peak_factor = noise_peak_factor(spec.noise);
  r.pass = true;
  for (const NoiseDirectionInput& in : inputs) {
    if (in.check == nullptr || in.rules == nullptr)
      return Status::Error("noise: a direction without its link check");
    const double pin_signal =
        in.wave ? std::max(max_abs_column(*in.wave, 1), max_abs_column(*in.wave, 2)) : 0.0;
    const NoiseBudget budget = noise_budget(*in.check, *in.rules, pin_signal);
    StatusOr<NoiseDirection> d =
        analyze_direction(spec, parts, in, opt, budget, r.peak_factor, &r.factorizations);
    if (!d) return d.status();
    d->time_domain = confirm_in_time(spec, in, *d);
    r.pass = r.pass && d->pass;
    r.directions.push_back(std::move(*d));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

StatusOr<NoiseResult> analyze_noise_of_run(const link::LinkSpec& spec,
                                           const link::PartLibrary& parts, const LinkRun& run) {
  std::vector<NoiseDirectionInput> inputs;
  for (const DirectionRun& d : run.directions) {
    const bool data = d.data.has_value();
    if (!data && !d.tones.has_value()) return Status::Error("noise: a direction without traffic");
    inputs.push_back({d.link.direction, data ? &*d.data : &*d.tones,
                      data ? &d.rules : &d.tone_rules, &d.sim.wave, d.link.expected});
  }
  return analyze_noise(spec, parts, inputs);
}

StatusOr<NoiseRun> run_noise(const link::LinkSpec& spec, const link::PartLibrary& parts) {
  // Refused before the (long) run of a nonlinear link's traffic, as analyze_noise would after.
  if (std::string why = link::linear_only(spec, "noise (a small-signal analysis)"); !why.empty())
    return Status::Error(why);
  if (Status s = measured_cable_injection(spec); !s.ok()) return s;
  NoiseRun out;
  StatusOr<LinkRun> run = run_link(spec, parts);
  if (!run) return run.status();
  out.run = std::move(*run);
  StatusOr<NoiseResult> noise = analyze_noise_of_run(spec, parts, out.run);
  if (!noise) return noise.status();
  out.noise = std::move(*noise);
  return out;
}

VerdictImmunity verdict_immunity(const NoiseDirection& d, const link::NoiseSpec& n) {
  if (n.verdict_on == "statistical")
    return {d.statistical.immunity_min, d.statistical.immunity_min_freq};
  return {d.immunity_min, d.immunity_min_freq};
}

double noise_immunity_min_db(const NoiseResult& r) {
  double worst = std::numeric_limits<double>::infinity();
  for (const NoiseDirection& d : r.directions)
    worst = std::min(worst, verdict_immunity(d, r.spec).value);
  if (r.directions.empty()) return 0;
  return db(worst / r.spec.level);
}

}  // namespace isolink::analysis
