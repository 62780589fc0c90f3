#include "analysis/stress.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "netlists/link/cards.h"
#include "netlists/traffic/stimulus.h"

namespace isolink::analysis {

namespace {

// IEC 61000-4-2:2008 Annex B, eq. (B.1), at 4 kV.
constexpr double kI1 = 16.6, kTau1 = 1.1e-9, kTau2 = 2e-9;
constexpr double kI2 = 9.3, kTau3 = 12e-9, kTau4 = 37e-9, kN = 1.8;

double heidler(double t, double i, double t_rise, double t_fall) {
  if (t <= 0) return 0;
  const double k = std::exp(-t_rise / t_fall * std::pow(kN * t_fall / t_rise, 1 / kN));
  const double x = std::pow(t / t_rise, kN);
  return i / k * x / (1 + x) * std::exp(-t / t_fall);
}

// Where the disturbed scenarios start: the cm_step inside the first data frame, the ESD here.
constexpr double kEsdStart = 20e-9;    // s, idle before the discharge
constexpr double kEsdSpan = 280e-9;    // s, after it (the tail is 0.5 % of the peak at 200 ns)
constexpr double kDuringLead = 10e-6;  // s, bytes starting this much before the step count

CardArg pwl_arg(std::vector<double> points) {
  CardArg a;
  a.kind = CardArg::Kind::Call;
  a.word = "pwl";
  a.call = std::move(points);
  return a;
}

std::string probe_v(const std::string& node, const std::string& ground) {
  return ground == "0" ? fmt::format("v({})", node) : fmt::format("v({},{})", node, ground);
}

// The cable connector nodes of an end in an expanded netlist (the cable side of its isolation).
std::pair<std::string, std::string> connector(const link::ExpandedLink& x,
                                              const std::string& side) {
  std::string p = side + "_lp", n = side + "_ln";
  for (const Card& c : x.netlist.cards) {
    if (c.name == "r" + side + "bleedp" && !c.nodes.empty()) p = c.nodes[0];
    if (c.name == "r" + side + "bleedn" && !c.nodes.empty()) n = c.nodes[0];
  }
  return {p, n};
}

// The error of a spec value, at the place it was written (when it was).
Status at(const SourceLoc& loc, const std::string& message) {
  return loc.valid() ? error_at(loc, message) : Status::Error(message);
}

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

// Puts a 0 V source in series with each TVS (at its line) and each pin clamp (at its pin), so
// their currents can be probed; fills the scenario's diode list. `end_of` maps a netlist side
// ("tx", "rx") to the spec end it is; `tvs_of` the end's TVS part (null: none).
void add_ammeters(StressScenario& s, const std::map<std::string, std::string>& end_of,
                  const std::map<std::string, const link::Part*>& tvs_of) {
  std::vector<Card>& cards = s.link.netlist.cards;
  std::vector<Card> added;
  for (Card& c : cards) {
    if (c.letter != 'd' || c.nodes.size() < 2) continue;
    for (const std::string side : {"tx", "rx"}) {
      const std::string end = end_of.at(side);
      int terminal = -1;
      std::string what;
      DiodePeak d;
      for (const std::string tag : {"p", "n"}) {
        const std::string tvs = "d" + side + "esd" + tag;
        const link::Part* part = tvs_of.at(side);
        if (part != nullptr && (c.name == tvs || c.name == tvs + "a")) {
          terminal = c.name == tvs ? 1 : 0;  // unidirectional: cathode at the line
          what = fmt::format("TVS {} at the {} end, line {}", part->number, end,
                             tag == "p" ? "P" : "N");
          d.rating_a = part->tvs.peak_current;
          if (const link::Figure* f = part->figure("rating.current")) d.rating_source = f->source;
        }
        if (c.name == "d" + side + "h" + tag) {
          terminal = 0;
          what = fmt::format("{} end pin {} clamp to CVDD", end, tag == "p" ? "P" : "N");
        }
        if (c.name == "d" + side + "l" + tag) {
          terminal = 1;
          what = fmt::format("{} end pin {} clamp to CVSS", end, tag == "p" ? "P" : "N");
        }
      }
      if (terminal < 0) continue;
      d.diode = c.name;
      d.what = what;
      d.ammeter = "v" + c.name + "am";
      const std::string inner = c.name + "_am";
      added.push_back(
          link::make_card('v', d.ammeter, {c.nodes[terminal], inner}, {link::number_arg(0)}));
      c.nodes[terminal] = inner;
      s.diodes.push_back(std::move(d));
    }
  }
  for (Card& c : added) cards.push_back(std::move(c));
}

// The TVS voltage across the part whose line diode is `d` (for its energy): (line, ground).
std::optional<std::pair<std::string, std::string>> tvs_terminals(const StressScenario& s,
                                                                 const DiodePeak& d) {
  if (!starts_with(d.what, "TVS")) return std::nullopt;
  std::string line, ground;
  for (const Card& c : s.link.netlist.cards) {
    if (c.name == d.ammeter) line = c.nodes[0];
    const bool bidir = d.diode.back() == 'a';
    const std::string base = bidir ? d.diode.substr(0, d.diode.size() - 1) : d.diode;
    if (bidir && c.name == base + "b") ground = c.nodes[0];
    if (!bidir && c.name == d.diode) ground = c.nodes[0];
  }
  if (line.empty() || ground.empty()) return std::nullopt;
  return std::pair{line, ground};
}

std::map<std::string, const link::Part*> tvs_parts(const link::LinkSpec& spec,
                                                   const link::PartLibrary& parts,
                                                   link::Direction d) {
  const bool down = d == link::Direction::kDown;
  const link::EndSpec& from = down ? spec.tx : spec.rx;
  const link::EndSpec& to = down ? spec.rx : spec.tx;
  auto part = [&](const link::EndSpec& e) -> const link::Part* {
    return e.isolation.esd_part.empty() ? nullptr : parts.find(e.isolation.esd_part);
  };
  return {{"tx", part(from)}, {"rx", part(to)}};
}

link::ExpandOptions stress_expand_options() {
  link::ExpandOptions eo;
  // The pins' internal clamps are always there in the field: on in every scenario.
  eo.driver.clamps.enabled = true;
  eo.load.clamps.enabled = true;
  return eo;
}

std::string level_text(double v) {
  return link::format_si(v, "V");
}

StatusOr<StressScenario> build_cm_step(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                       const std::string& end) {
  StressScenario s;
  s.kind = "cm_step";
  s.end = end;
  s.id = "cm_step_" + end;
  const link::Direction d = end == "tx" ? link::Direction::kDown : link::Direction::kUp;
  const link::StressSpec& st = spec.stress;
  link::ExpandOptions eo = stress_expand_options();
  eo.tx_ground = "gtx";
  eo.rx_ground = "0";
  // The spec's traffic, sent again until the record runs 30 us past the step (at least twice).
  const std::string once = spec.stimulus.to_script();
  std::string script = once;
  StatusOr<traffic::Drive> drive = traffic::build_drive(script, eo.stimulus);
  if (!drive) return at(spec.stimulus.loc, "stimulus: " + drive.status().message());
  const traffic::DriveFrame* first = nullptr;
  for (const traffic::DriveFrame& f : drive->frames)
    if (f.kind == traffic::FrameKind::kData && first == nullptr) first = &f;
  if (first == nullptr)
    return at(spec.stimulus.loc,
              "stress: the cm_step scenario needs data frames in the stimulus (it scores "
              "the traffic through the step); give stimulus.frames or patterns, or narrow "
              "with --only esd");
  s.t_start = first->start + (first->end - first->start) / 3;
  s.t_end = s.t_start + st.step_rise;
  for (int k = 2; k <= 64; ++k) {
    script = once;
    for (int i = 1; i < k; ++i) script += "; " + once;
    drive = traffic::build_drive(script, eo.stimulus);
    if (!drive) return at(spec.stimulus.loc, "stimulus: " + drive.status().message());
    if (drive->duration() > s.t_end + 30e-6) break;
  }
  eo.drive = *drive;
  StatusOr<link::ExpandedLink> x = link::expand_link(spec, parts, d, eo);
  if (!x) return x.status();
  s.link = std::move(*x);
  s.link.netlist.cards.push_back(link::make_card(
      'v', "vstep", {"gtx", "0"}, {pwl_arg({0, 0, s.t_start, 0, s.t_end, st.step_v})}));
  s.link.netlist.title =
      fmt::format("isolink stress '{}', {}: the {} module's ground steps {} in {}", spec.name, s.id,
                  end, level_text(st.step_v), link::format_si(st.step_rise, "s"));
  s.level = {{"step_V", st.step_v}, {"rise_s", st.step_rise}};
  s.description =
      fmt::format("the {} module's ground steps {} in {} while it transmits ({})", end,
                  level_text(st.step_v), link::format_si(st.step_rise, "s"), s.link.description);
  s.pin_ground = {{"txp", "gtx"}, {"txn", "gtx"}, {"rxp", "0"}, {"rxn", "0"}};
  s.receiver_p = "rxp", s.receiver_n = "rxn", s.rules = s.link.rules;
  const std::string other = end == "tx" ? "rx" : "tx";
  add_ammeters(s, {{"tx", end}, {"rx", other}}, tvs_parts(spec, parts, d));
  return s;
}

StatusOr<StressScenario> build_esd(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                   const std::string& end, const std::string& line, int sign) {
  StressScenario s;
  s.kind = "esd";
  s.end = end;
  s.line = line;
  const double level = sign * spec.stress.esd_v;
  s.id = fmt::format("esd_{}_{}_{}", end, line, sign > 0 ? "pos" : "neg");
  link::ExpandOptions eo = stress_expand_options();
  traffic::Drive idle;
  idle.segments.push_back({0, kEsdStart + kEsdSpan, 0});
  eo.drive = idle;
  // Both boards on the chassis: the discharge returns through the parts to the board ground.
  StatusOr<link::ExpandedLink> x = link::expand_link(spec, parts, link::Direction::kDown, eo);
  if (!x) return x.status();
  s.link = std::move(*x);
  auto [cp, cn] = connector(s.link, end);
  const std::string node = line == "p" ? cp : cn;
  s.link.netlist.cards.push_back(
      link::make_card('i', "iesd", {"0", node}, {pwl_arg(esd_pwl(level, kEsdStart, kEsdSpan))}));
  s.t_start = kEsdStart;
  s.t_end = kEsdStart + kEsdSpan;
  // The rise needs sub-ns steps; the source's corners are breakpoints, this bounds the tail's.
  if (s.link.netlist.tran) {
    s.link.netlist.tran->tstep = 0.2e-9;
    s.link.netlist.tran->tmax = 0.5e-9;
  }
  s.link.netlist.title =
      fmt::format("isolink stress '{}', {}: IEC 61000-4-2 contact discharge {} into {} ({} end)",
                  spec.name, s.id, level_text(level), node, end);
  s.level = {{"contact_kV", level / 1e3}};
  s.description = fmt::format("IEC 61000-4-2 contact discharge {} into the {} end's line {} ({})",
                              level_text(level), end, line == "p" ? "P" : "N", node);
  s.pin_ground = {{"txp", "0"}, {"txn", "0"}, {"rxp", "0"}, {"rxn", "0"}};
  add_ammeters(s, {{"tx", "tx"}, {"rx", "rx"}}, tvs_parts(spec, parts, link::Direction::kDown));
  return s;
}

// Which spec end a pin node ("txp") of a scenario's netlist belongs to.
std::string end_of_pin(const StressScenario& s, const std::string& node) {
  const bool tx_node = starts_with(node, "tx");
  if (s.kind == "cm_step") return tx_node ? s.end : (s.end == "tx" ? "rx" : "tx");
  return tx_node ? "tx" : "rx";
}

double column_max_abs(const Waveform& w, size_t k) {
  double m = 0;
  for (double v : w.columns[k]) m = std::max(m, std::abs(v));
  return m;
}

const StressLimit* limit(const std::vector<StressLimit>& ls, const std::string& key) {
  for (const StressLimit& l : ls)
    if (l.key == key) return &l;
  return nullptr;
}

void score_traffic(StressScenario& s, const Waveform& w) {
  StressTraffic t;
  StatusOr<eye::Rules> rules = eye::load_rules(s.link.rules);
  if (!rules) {
    t.first_failure = rules.status().message();
    s.traffic = t;
    return;
  }
  eye::CheckOptions co;
  co.expect = s.link.expected;
  StatusOr<eye::CheckResult> r = eye::check_samples(w.time, w.columns[0], *rules, co);
  if (!r) {
    t.first_failure = r.status().message();
    s.traffic = t;
    return;
  }
  t.pass = r->pass;
  t.worst = r->worst;
  if (!r->pass && !r->reasons.empty()) t.first_failure = r->reasons.front();
  const double lo = s.t_start - kDuringLead, hi = s.t_end;
  for (const traffic::DriveFrame& f : s.link.drive.frames)
    for (double b : f.byte_starts) {
      ++t.bytes_sent;
      if (b >= lo && b <= hi) ++t.bytes_during;
    }
  for (const eye::FrameResult& f : r->frames) {
    if (!f.byte || f.fails()) continue;
    ++t.bytes_decoded;
    if (f.start >= lo - 1e-6 && f.start <= hi) ++t.decoded_during;
  }
  if (!r->expect_match) t.bytes_decoded = std::min(t.bytes_decoded, t.bytes_sent);
  // Recovery: from the step's end to the end of the last failing pulse after its start.
  const eye::PulseMetrics* last_fail = nullptr;
  for (const eye::PulseMetrics& p : r->pulses)
    if (p.failing() && p.b >= s.t_start) last_fail = &p;
  if (last_fail == nullptr) {
    t.recovery_s = 0.0;
  } else if (last_fail->index + 1 < r->pulses.size()) {
    t.recovery_s = std::max(0.0, last_fail->b - s.t_end);
  }
  s.traffic = std::move(t);
}

}  // namespace

double esd_current(double t, double level_v) {
  const double scale = level_v / 4e3;
  return scale * (heidler(t, kI1, kTau1, kTau2) + heidler(t, kI2, kTau3, kTau4));
}

std::vector<double> esd_pwl(double level_v, double t0, double span) {
  std::vector<double> pts{0, 0};
  if (t0 > 0) pts.insert(pts.end(), {t0, 0});  // no current before the discharge starts
  double t = 0;
  while (t < span) {
    const double step = t < 3e-9 ? 20e-12 : t < 20e-9 ? 0.25e-9 : 2e-9;
    t = std::min(span, t + step);
    pts.push_back(t0 + t);
    pts.push_back(esd_current(t, level_v));
  }
  return pts;
}

std::vector<StressLimit> stress_limits(const link::LinkSpec& spec) {
  const link::StressSpec& st = spec.stress;
  const link::StressSpec defaults;
  auto from_spec = [&](double v, double def, const std::string& key, const std::string& source) {
    return v == def ? source
                    : fmt::format("stress.{} in the spec (default {:g}: {})", key, def, source);
  };
  return {
      {"pin_abs_max_V", st.pin_abs_max,
       from_spec(st.pin_abs_max, defaults.pin_abs_max, "pin_abs_max",
                 "assumed: TI's +-20 V for the COM pins (bq7961x daisy-chain application note, "
                 "docs/physics.md 2), past which the internal ESD structures clamp; this "
                 "repository holds no absolute-maximum table of the devices: set it from the "
                 "data sheet's COMHP/COMHN/COMLP/COMLN rating")},
      {"pin_cm_limit_V", st.pin_cm_limit,
       from_spec(st.pin_cm_limit, defaults.pin_cm_limit, "pin_cm_limit",
                 "TI: the COM pins ride out +-20 V of common mode (docs/physics.md 2)")},
      {"cap_rating_V", st.cap_rating,
       from_spec(st.cap_rating, defaults.cap_rating, "cap_rating",
                 "1206J2K00222KXR's 2 kV DC rating (netlists/parts/knowles_1206j2k.yaml), TI's "
                 "isolation cap; TI asks for at least twice the module's stack voltage")},
  };
}

StatusOr<std::vector<StressScenario>> build_stress_scenarios(const link::LinkSpec& spec,
                                                             const link::PartLibrary& parts,
                                                             const StressOptions& opt) {
  std::vector<std::string> only = opt.only.empty() ? spec.stress.only : opt.only;
  const std::vector<std::string>& kinds = link::stress_kinds();
  for (const std::string& k : only)
    if (std::find(kinds.begin(), kinds.end(), k) == kinds.end())
      return Status::Error(
          fmt::format("--only: '{}' is not a stress scenario (one of cm_step, esd)", k));
  auto wanted = [&](const std::string& k) {
    return only.empty() || std::find(only.begin(), only.end(), k) != only.end();
  };
  std::vector<StressScenario> out;
  if (wanted("cm_step"))
    for (const std::string end : {"tx", "rx"}) {
      StatusOr<StressScenario> s = build_cm_step(spec, parts, end);
      if (!s) return s.status();
      out.push_back(std::move(*s));
    }
  if (wanted("esd"))
    for (const std::string end : {"tx", "rx"})
      for (const std::string line : {"p", "n"})
        for (int sign : {+1, -1}) {
          StatusOr<StressScenario> s = build_esd(spec, parts, end, line, sign);
          if (!s) return s.status();
          out.push_back(std::move(*s));
        }
  return out;
}

Status run_stress_scenario(StressScenario& s, const link::LinkSpec& spec,
                           const link::PartLibrary& parts) {
  const std::vector<StressLimit> limits = stress_limits(spec);
  SimulationRequest req;
  // One transient at reltol 1e-4 (the spec's sim.reltol when given) instead of auto's
  // self-check (runs at 1e-3, 1e-4, ... until two agree): on the bq79606a_tvs_2m ESD scenario
  // the check took 45 s and one run at 1e-4 3.2 s, with the pins' peaks within 0.4 mV of the
  // 1e-3 run; the peaks are held to ngspice in tests/cli/stress_command_test.cpp.
  req.reltol = spec.sim.reltol.value_or(kStressReltol);
  req.probes.push_back("v(rxp,rxn)");
  std::vector<std::string> pins;
  for (const auto& [node, ground] : s.pin_ground) {
    pins.push_back(node);
    req.probes.push_back(probe_v(node, ground));
  }
  const size_t diode0 = req.probes.size();
  for (const DiodePeak& d : s.diodes) req.probes.push_back("i(" + d.ammeter + ")");
  const size_t cap0 = req.probes.size();
  for (const Card& c : s.link.netlist.cards)
    if (c.letter == 'c' && (c.name == "ctxisop" || c.name == "ctxison" || c.name == "crxisop" ||
                            c.name == "crxison")) {
      s.caps.push_back({c.name, 0});
      req.probes.push_back(fmt::format("v({},{})", c.nodes[0], c.nodes[1]));
    }
  std::vector<std::pair<size_t, size_t>> tvs_v;  // diode index, probe column
  for (size_t i = 0; i < s.diodes.size(); ++i)
    if (auto t = tvs_terminals(s, s.diodes[i])) {
      tvs_v.push_back({i, req.probes.size()});
      req.probes.push_back(probe_v(t->first, t->second));
    }
  StatusOr<SimulationResult> r = simulate_netlist(s.link.netlist, req);
  if (!r) return r.status().with_context("stress scenario " + s.id);
  const Waveform& w = r->wave;
  s.seconds = r->seconds;
  s.engine = engine_name(r->engine);
  if (!r->engine_note.empty()) s.engine += " (" + r->engine_note + ")";
  s.pins.time = w.time;
  for (size_t k = 0; k < pins.size(); ++k) {
    const std::vector<double>& col = w.columns[1 + k];
    PinPeak p;
    p.max = *std::max_element(col.begin(), col.end());
    p.min = *std::min_element(col.begin(), col.end());
    s.peak_pin_v[pins[k]] = p;
    s.pins.names.push_back(pins[k]);
    s.pins.columns.push_back(col);
  }
  // Common mode of each device: the mean of its two pins (both to its own ground).
  for (const std::string dev : {"tx", "rx"}) {
    size_t kp = 0, kn = 0;
    for (size_t k = 0; k < pins.size(); ++k) {
      if (pins[k] == dev + "p") kp = 1 + k;
      if (pins[k] == dev + "n") kn = 1 + k;
    }
    for (size_t i = 0; i < w.samples(); ++i) {
      const double cm = 0.5 * (w.columns[kp][i] + w.columns[kn][i]);
      if (std::abs(cm) > s.peak_cm_v) s.peak_cm_v = std::abs(cm), s.peak_cm_device = dev;
    }
  }
  for (size_t i = 0; i < s.diodes.size(); ++i) s.diodes[i].peak_a = column_max_abs(w, diode0 + i);
  for (auto [i, col] : tvs_v) {
    double e = 0;
    const std::vector<double>& v = w.columns[col];
    const std::vector<double>& a = w.columns[diode0 + i];
    for (size_t j = 1; j < w.samples(); ++j)
      e += 0.5 * (std::abs(v[j] * a[j]) + std::abs(v[j - 1] * a[j - 1])) *
           (w.time[j] - w.time[j - 1]);
    s.diodes[i].energy_j = e;
  }
  for (size_t i = 0; i < s.caps.size(); ++i) s.caps[i].peak_v = column_max_abs(w, cap0 + i);

  // The verdict: every limit, in the order an engineer fixes them.
  s.broken.clear();
  const StressLimit* pin = limit(limits, "pin_abs_max_V");
  for (const std::string& node : pins) {
    const PinPeak& p = s.peak_pin_v[node];
    const double worst = std::abs(p.max) >= std::abs(p.min) ? p.max : p.min;
    if (std::abs(worst) > pin->value)
      s.broken.push_back(fmt::format(
          "the {} end's COM pin {} reached {:.3g} V against its device ground, beyond the pin "
          "limit +-{:g} V ({})",
          end_of_pin(s, node), node, worst, pin->value, pin->source));
  }
  const StressLimit* cm = limit(limits, "pin_cm_limit_V");
  if (s.peak_cm_v > cm->value)
    s.broken.push_back(
        fmt::format("the {} end's COM pins' common mode reached {:.3g} V, beyond +-{:g} V ({})",
                    end_of_pin(s, s.peak_cm_device + "p"), s.peak_cm_v, cm->value, cm->source));
  const StressLimit* cap = limit(limits, "cap_rating_V");
  for (const CapPeak& c : s.caps)
    if (c.peak_v > cap->value)
      s.broken.push_back(fmt::format("isolation cap {} saw {:.4g} V, beyond its rating {:g} V ({})",
                                     c.cap, c.peak_v, cap->value, cap->source));
  // IPP is an 8/20 us surge rating: it bounds the step's currents, not an ESD pulse's (a
  // nanosecond event, which the part's IEC 61000-4-2 rating covers, below).
  for (const DiodePeak& d : s.diodes)
    if (s.kind != "esd" && d.rating_a > 0 && d.peak_a > d.rating_a)
      s.broken.push_back(fmt::format("{} carried {:.3g} A, beyond its rated IPP {:g} A ({})",
                                     d.what, d.peak_a, d.rating_a, d.rating_source));
  if (s.kind == "esd") {
    const std::map<std::string, const link::Part*> tvs =
        tvs_parts(spec, parts, link::Direction::kDown);
    const link::Part* part = tvs.at(s.end);
    if (part != nullptr && part->tvs.esd_contact > 0 && spec.stress.esd_v > part->tvs.esd_contact)
      s.broken.push_back(fmt::format(
          "{} is rated for {} contact discharge, below the {} applied ({})", part->number,
          level_text(part->tvs.esd_contact), level_text(spec.stress.esd_v),
          part->figure("rating.esd") ? part->figure("rating.esd")->source : "its data sheet"));
  }
  s.survives = s.broken.empty();
  if (s.kind == "cm_step") {
    score_traffic(s, w);
    s.communicates = s.traffic->pass;
    if (!s.traffic->pass)
      s.broken.push_back(fmt::format(
          "the traffic fails the {} rules at the receiver ({}, {}): {}", s.rules, s.receiver_p,
          s.receiver_n,
          s.traffic->first_failure.empty() ? "see the check" : s.traffic->first_failure));
  }
  s.first_broken = s.broken.empty() ? "" : s.broken.front();
  return Status::Ok();
}

StatusOr<StressResult> run_stress(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                  const StressOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  StressResult out;
  out.limits = stress_limits(spec);
  StatusOr<std::vector<StressScenario>> built = build_stress_scenarios(spec, parts, opt);
  if (!built) return built.status();
  out.scenarios = std::move(*built);
  for (size_t i = 0; i < out.scenarios.size(); ++i) {
    StressScenario& s = out.scenarios[i];
    if (opt.progress) opt.progress(s.id, static_cast<double>(i) / out.scenarios.size());
    if (Status st = run_stress_scenario(s, spec, parts); !st.ok()) return st;
    out.survives = out.survives && s.survives;
    if (s.communicates) out.communicates = out.communicates && *s.communicates;
  }
  const StressScenario* first = nullptr;
  for (const StressScenario& s : out.scenarios)
    if (!s.first_broken.empty() && first == nullptr) first = &s;
  int broke = 0;
  for (const StressScenario& s : out.scenarios) broke += s.first_broken.empty() ? 0 : 1;
  out.verdict =
      first == nullptr
          ? fmt::format("survives and communicates: {} scenarios, no limit or rule broken",
                        out.scenarios.size())
          : fmt::format("{} of {} scenarios break something; first, {}: {}", broke,
                        out.scenarios.size(), first->id, first->first_broken);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace isolink::analysis
