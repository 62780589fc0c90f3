#include "analysis/stress.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
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
constexpr double kEsdStart = 20e-9;     // s, idle before the discharge
constexpr double kEsdSpan = 280e-9;     // s, after it (the tail is 0.5 % of the peak at 200 ns)
constexpr double kDuringLead = 10e-6;   // s, bytes starting this much before the step count
constexpr double kHotPlugStart = 1e-6;  // s, idle before the first contact
// s: a contact's reported inrush is its largest mean current over this window, its closing
// time. The instantaneous peak of the ideal contact (20 mohm between two nodes' picofarads: a
// time constant under a picosecond) is set by the time step: 0.9 A in isolink, 141 A in ngspice
// on the same hot-plug circuit, whose charges agreed within 0.1 %.
constexpr double kContactWindow = 1e-9;
constexpr double kHotPlugSettle = 20e-6;  // s, simulated after the second

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

// The spec's traffic sent `copies` times at least, and again until the record runs past
// `until(first data frame)`; the first data frame (an error without one, naming `kind`).
StatusOr<traffic::Drive> repeated_traffic(const link::LinkSpec& spec,
                                          const traffic::StimulusOptions& so,
                                          const std::string& kind, int copies,
                                          const std::function<double(double)>& until,
                                          traffic::DriveFrame* first_data) {
  const std::string once = spec.stimulus.to_script();
  StatusOr<traffic::Drive> drive = traffic::build_drive(once, so);
  if (!drive) return at(spec.stimulus.loc, "stimulus: " + drive.status().message());
  const traffic::DriveFrame* first = nullptr;
  for (const traffic::DriveFrame& f : drive->frames)
    if (f.kind == traffic::FrameKind::kData && first == nullptr) first = &f;
  if (first == nullptr)
    return at(spec.stimulus.loc,
              fmt::format("stress: the {} scenario needs data frames in the stimulus (it scores "
                          "the traffic through the disturbance); give stimulus.frames or "
                          "patterns, or narrow with --only",
                          kind));
  *first_data = *first;
  const double need = until(first->start + (first->end - first->start) / 3);
  for (int k = 2; k <= 64 && (k <= copies || drive->duration() <= need); ++k) {
    std::string script = once;
    for (int i = 1; i < k; ++i) script += "; " + once;
    drive = traffic::build_drive(script, so);
    if (!drive) return at(spec.stimulus.loc, "stimulus: " + drive.status().message());
  }
  return drive;
}

// The link transmitting from `end` (tx: down, rx: up) with its board ground `tx_ground` (the
// receiving board on `rx_ground`), the clamps on, driven by `drive`; fills the scenario's link,
// receiver, pin grounds and ammeters.
Status expand_traffic(StressScenario& s, const link::LinkSpec& spec, const link::PartLibrary& parts,
                      link::Direction d, traffic::Drive drive, const std::string& tx_ground,
                      const std::string& rx_ground) {
  link::ExpandOptions eo = stress_expand_options();
  eo.tx_ground = tx_ground;
  eo.rx_ground = rx_ground;
  eo.drive = std::move(drive);
  StatusOr<link::ExpandedLink> x = link::expand_link(spec, parts, d, eo);
  if (!x) return x.status();
  s.link = std::move(*x);
  s.direction = link::direction_name(d);
  s.tx_end = d == link::Direction::kDown ? "tx" : "rx";
  s.pin_ground = {{"txp", tx_ground}, {"txn", tx_ground}, {"rxp", rx_ground}, {"rxn", rx_ground}};
  s.receiver_p = "rxp", s.receiver_n = "rxn", s.rules = s.link.rules;
  const std::string other = s.tx_end == "tx" ? "rx" : "tx";
  add_ammeters(s, {{"tx", s.tx_end}, {"rx", other}}, tvs_parts(spec, parts, d));
  return Status::Ok();
}

StatusOr<StressScenario> build_cm_step(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                       const std::string& end) {
  StressScenario s;
  s.kind = "cm_step";
  s.end = end;
  s.id = "cm_step_" + end;
  const link::Direction d = end == "tx" ? link::Direction::kDown : link::Direction::kUp;
  const link::StressSpec& st = spec.stress;
  // The spec's traffic, sent again until the record runs 30 us past the step (at least twice).
  traffic::DriveFrame first;
  StatusOr<traffic::Drive> drive = repeated_traffic(
      spec, {}, "cm_step", 2, [&](double t0) { return t0 + st.step_rise + 30e-6; }, &first);
  if (!drive) return drive.status();
  s.t_start = first.start + (first.end - first.start) / 3;
  s.t_end = s.t_start + st.step_rise;
  if (Status e = expand_traffic(s, spec, parts, d, std::move(*drive), "gtx", "0"); !e.ok())
    return e;
  s.link.netlist.cards.push_back(link::make_card(
      'v', "vstep", {"gtx", "0"}, {pwl_arg({0, 0, s.t_start, 0, s.t_end, st.step_v})}));
  s.link.netlist.title =
      fmt::format("isolink stress '{}', {}: the {} module's ground steps {} in {}", spec.name, s.id,
                  end, level_text(st.step_v), link::format_si(st.step_rise, "s"));
  s.level = {{"step_V", st.step_v}, {"rise_s", st.step_rise}};
  s.description =
      fmt::format("the {} module's ground steps {} in {} while it transmits ({})", end,
                  level_text(st.step_v), link::format_si(st.step_rise, "s"), s.link.description);
  return s;
}

CardArg call_arg(const char* name, std::vector<double> values) {
  CardArg a = pwl_arg(std::move(values));
  a.word = name;
  return a;
}

// The inverter's disturbance on the transmitting module's ground during traffic: a square
// (PULSE, edges wave_v / wave_dvdt) or a sine (SIN from 0 to wave_v), two periods at least.
StatusOr<StressScenario> build_cm_wave(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                       const std::string& end) {
  StressScenario s;
  s.kind = "cm_wave";
  s.end = end;
  s.id = "cm_wave_" + end;
  const link::Direction d = end == "tx" ? link::Direction::kDown : link::Direction::kUp;
  const link::StressSpec& st = spec.stress;
  const double period = 1 / st.wave_f;
  traffic::DriveFrame first;
  StatusOr<traffic::Drive> drive = repeated_traffic(
      spec, {}, "cm_wave", 1, [&](double t0) { return t0 + 2 * period + 5e-6; }, &first);
  if (!drive) return drive.status();
  s.t_start = first.start + (first.end - first.start) / 3;
  s.t_end = drive->duration();
  if (Status e = expand_traffic(s, spec, parts, d, std::move(*drive), "gtx", "0"); !e.ok())
    return e;
  const bool square = st.wave_shape == "square";
  const double edge = st.wave_v / (st.wave_dvdt * 1e9);
  CardArg wave =
      square ? call_arg("pulse", {0, st.wave_v, s.t_start, edge, edge, period / 2 - edge, period})
             : call_arg("sin", {st.wave_v / 2, st.wave_v / 2, st.wave_f, s.t_start, 0, -90});
  s.link.netlist.cards.push_back(link::make_card('v', "vwave", {"gtx", "0"}, {wave}));
  const std::string what =
      square ? fmt::format("a {} square of {} ({:g} V/ns edges)", link::format_si(st.wave_f, "Hz"),
                           level_text(st.wave_v), st.wave_dvdt)
             : fmt::format("a {} sine of {} peak to peak", link::format_si(st.wave_f, "Hz"),
                           level_text(st.wave_v));
  s.link.netlist.title = fmt::format("isolink stress '{}', {}: {} on the {} module's ground",
                                     spec.name, s.id, what, end);
  s.level = {{"wave_V", st.wave_v}, {"frequency_Hz", st.wave_f}};
  if (square) s.level.push_back({"dvdt_V_per_ns", st.wave_dvdt});
  s.description = fmt::format("{} on the {} module's ground while it transmits ({})", what, end,
                              s.link.description);
  return s;
}

// Moves the cable's end at netlist side `side` off its connector nodes onto (p, n): the cable's
// cards are named "<letter>cab...".
void detach_cable(StressScenario& s, const std::string& side, const std::string& p,
                  const std::string& n, bool move_p = true, bool move_n = true) {
  auto [cp, cn] = connector(s.link, side);
  for (Card& c : s.link.netlist.cards) {
    if (c.name.rfind("cab", 1) != 1) continue;
    for (std::string& node : c.nodes) {
      if (move_p && node == cp) node = p;
      if (move_n && node == cn) node = n;
    }
  }
}

// A connector contact: ron 20 mohm (assumed: a crimped automotive contact, 5-20 mohm), closing
// when its control source crosses 0.5 V on its 1 ns ramp from t_close, with an ammeter
// ("vcontact<tag>am", positive from the cable into the module) in series.
void add_contact(std::vector<Card>& cards, const std::string& tag, const std::string& cable,
                 const std::string& module, double t_close, double t_stop) {
  static const std::shared_ptr<CardModel> model = [] {
    auto m = std::make_shared<CardModel>();
    m->name = "contact";
    m->type = "sw";
    m->params = {{"vt", link::number_arg(0.5)},
                 {"ron", link::number_arg(20e-3)},
                 {"roff", link::number_arg(1e12)}};
    return m;
  }();
  // The ammeter on the cable's side of the switch: on the module's side (between the switch and
  // a node of capacitors and clamps) the port model's march rang at its first steps on a
  // reduced hot-plug circuit, depending on the cards' order, and fell back to the transient.
  const std::string ctl = "ctl_" + tag, mid = "contact_" + tag;
  cards.push_back(
      link::make_card('v', "vcontact" + tag + "am", {cable, mid}, {link::number_arg(0)}));
  Card sw = link::make_card('s', "scontact" + tag, {mid, module, ctl, "0"}, {});
  sw.model = model;
  cards.push_back(std::move(sw));
  cards.push_back(link::make_card('v', "vcontact" + tag, {ctl, "0"},
                                  {pwl_arg({0, 0, t_close, 0, t_close + 1e-9, 1, t_stop, 1})}));
}

StatusOr<StressScenario> build_hot_plug(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                        const std::string& end, const std::string& first) {
  StressScenario s;
  s.kind = "hot_plug";
  s.end = end;
  s.line = first;
  s.id = fmt::format("hot_plug_{}_{}_first", end, first);
  const link::StressSpec& st = spec.stress;
  const double t1 = kHotPlugStart, t2 = t1 + st.hot_plug_gap, stop = t2 + kHotPlugSettle;
  link::ExpandOptions eo = stress_expand_options();
  traffic::Drive idle;
  idle.segments.push_back({0, stop, 0});
  eo.drive = idle;
  // The plugged module on its own ground, hot_plug_v above the chassis; the other on it.
  const std::string plug = "gplug";
  (end == "tx" ? eo.tx_ground : eo.rx_ground) = plug;
  StatusOr<link::ExpandedLink> x = link::expand_link(spec, parts, link::Direction::kDown, eo);
  if (!x) return x.status();
  s.link = std::move(*x);
  std::vector<Card>& cards = s.link.netlist.cards;
  cards.push_back(link::make_card('v', "vplug", {plug, "0"}, {link::number_arg(st.hot_plug_v)}));
  auto [cp, cn] = connector(s.link, end);
  detach_cable(s, end, "plug_p", "plug_n");
  const std::string second = first == "p" ? "n" : "p";
  add_contact(cards, first, "plug_" + first, first == "p" ? cp : cn, t1, stop);
  add_contact(cards, second, "plug_" + second, second == "p" ? cp : cn, t2, stop);
  for (const std::string& tag : {first, second})
    s.contacts.push_back({"scontact" + tag, "vcontact" + tag + "am"});
  s.t_start = t1;
  s.t_end = stop;
  if (s.link.netlist.tran) {
    s.link.netlist.tran->tstep = 1e-9;
    s.link.netlist.tran->tmax = 50e-9;
  }
  const std::string order = first == "p" ? "P, then N" : "N, then P";
  s.link.netlist.title = fmt::format(
      "isolink stress '{}', {}: the {} module, {} above the chassis, plugged onto the "
      "cable: {} {} later",
      spec.name, s.id, end, level_text(st.hot_plug_v), order,
      link::format_si(st.hot_plug_gap, "s"));
  s.level = {{"module_V", st.hot_plug_v}, {"gap_s", st.hot_plug_gap}};
  s.description = fmt::format(
      "the {} module, {} above the chassis with its lines floating, plugged onto the cable: "
      "line {} contacts first, the other {} later",
      end, level_text(st.hot_plug_v), first == "p" ? "P" : "N",
      link::format_si(st.hot_plug_gap, "s"));
  const std::string tg = end == "tx" ? plug : "0", rg = end == "rx" ? plug : "0";
  s.pin_ground = {{"txp", tg}, {"txn", tg}, {"rxp", rg}, {"rxn", rg}};
  add_ammeters(s, {{"tx", "tx"}, {"rx", "rx"}}, tvs_parts(spec, parts, link::Direction::kDown));
  return s;
}

// The wire faults, in their ids' words.
struct WireFault {
  const char* id;
  const char* line;  // "p", "n" or ""
  const char* what;
};
constexpr WireFault kWireFaults[] = {
    {"open_p", "p", "line P open at the rx end's connector"},
    {"open_n", "n", "line N open at the rx end's connector"},
    {"short_pn", "", "lines P and N shorted at the rx end's connector"},
    {"p_to_ground", "p", "line P shorted to the rx module's ground at its connector"},
    {"n_to_ground", "n", "line N shorted to the rx module's ground at its connector"},
    {"p_to_chassis", "p", "line P shorted to the chassis at the rx end's connector"},
    {"n_to_chassis", "n", "line N shorted to the chassis at the rx end's connector"},
    {"leak_p", "p", "the rx device's pin P leaking to its ground"},
    {"leak_n", "n", "the rx device's pin N leaking to its ground"},
};

// Resistance of a short (a wire or a crushed cable's contact).
constexpr double kShortOhms = 10e-3;

StatusOr<StressScenario> build_wire(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                    const WireFault& f, link::Direction d) {
  StressScenario s;
  s.kind = "wire";
  s.end = "rx";
  s.line = f.line;
  s.id = fmt::format("wire_{}_{}", f.id, link::direction_name(d));
  const link::StressSpec& st = spec.stress;
  traffic::DriveFrame first;
  StatusOr<traffic::Drive> drive = repeated_traffic(
      spec, {}, "wire", 1, [](double) { return 0.0; }, &first);
  if (!drive) return drive.status();
  s.t_start = 0;
  s.t_end = drive->duration();
  // The spec's rx end is the netlist's rx side going down, its tx side going up.
  const std::string side = d == link::Direction::kDown ? "rx" : "tx";
  const std::string gfault = "gfault";
  if (Status e = expand_traffic(s, spec, parts, d, std::move(*drive), side == "tx" ? gfault : "0",
                                side == "rx" ? gfault : "0");
      !e.ok())
    return e;
  std::vector<Card>& cards = s.link.netlist.cards;
  cards.push_back(link::make_card('v', "vfault", {gfault, "0"}, {link::number_arg(st.hot_plug_v)}));
  auto [cp, cn] = connector(s.link, side);
  const std::string id = f.id, line = f.line == std::string("p") ? cp : cn;
  if (id == "open_p" || id == "open_n")
    detach_cable(s, side, "open_p", "open_n", id == "open_p", id == "open_n");
  if (id == "short_pn")
    cards.push_back(link::make_card('r', "rfault", {cp, cn}, {link::number_arg(kShortOhms)}));
  if (id == "p_to_ground" || id == "n_to_ground")
    cards.push_back(link::make_card('r', "rfault", {line, gfault}, {link::number_arg(kShortOhms)}));
  if (id == "p_to_chassis" || id == "n_to_chassis")
    cards.push_back(link::make_card('r', "rfault", {line, "0"}, {link::number_arg(kShortOhms)}));
  if (id == "leak_p" || id == "leak_n")
    cards.push_back(
        link::make_card('r', "rfault", {side + f.line, gfault}, {link::number_arg(st.leak_ohms)}));
  s.link.netlist.title = fmt::format("isolink stress '{}', {}: {} for the whole record ({})",
                                     spec.name, s.id, f.what, s.link.description);
  s.level = {{"module_V", st.hot_plug_v}};
  if (id.starts_with("leak")) s.level.push_back({"leak_ohm", st.leak_ohms});
  s.description = fmt::format("{} for the whole record, the rx module {} above the chassis ({})",
                              f.what, level_text(st.hot_plug_v), s.link.description);
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
  return tx_node ? s.tx_end : (s.tx_end == "tx" ? "rx" : "tx");
}

double column_max_abs(const Waveform& w, size_t k) {
  double m = 0;
  for (double v : w.columns[k]) m = std::max(m, std::abs(v));
  return m;
}

// The trapezoidal running integral of column k from the first row (a current's charge).
std::vector<double> running_integral(const Waveform& w, size_t k) {
  const std::vector<double>& a = w.columns[k];
  std::vector<double> q(w.samples(), 0.0);
  for (size_t j = 1; j < q.size(); ++j)
    q[j] = q[j - 1] + 0.5 * (a[j] + a[j - 1]) * (w.time[j] - w.time[j - 1]);
  return q;
}

// The largest |mean| over any window of `span` seconds of the column whose running integral is
// q (the charge moved in the window over span), the window's far end interpolated linearly.
double window_mean_max_abs(const Waveform& w, const std::vector<double>& q, double span) {
  const size_t n = q.size();
  double best = 0;
  size_t e = 0;
  for (size_t j = 0; j < n && w.time[j] + span <= w.time[n - 1]; ++j) {
    const double t = w.time[j] + span;
    while (e + 1 < n && w.time[e + 1] < t) ++e;
    const double dt = w.time[e + 1] - w.time[e];
    const double f = dt > 0 ? (t - w.time[e]) / dt : 1.0;
    best = std::max(best, std::abs(q[e] + f * (q[e + 1] - q[e]) - q[j]) / span);
  }
  return best;
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
      return Status::Error(fmt::format(
          "--only: '{}' is not a stress scenario (one of cm_step, cm_wave, esd, hot_plug, wire)",
          k));
  auto wanted = [&](const std::string& k) {
    return only.empty() || std::find(only.begin(), only.end(), k) != only.end();
  };
  std::vector<link::Direction> dirs = opt.directions;
  if (dirs.empty()) dirs = {link::Direction::kDown, link::Direction::kUp};
  std::vector<StressScenario> out;
  auto add = [&](StatusOr<StressScenario> sc) -> Status {
    if (!sc) return sc.status();
    out.push_back(std::move(*sc));
    return Status::Ok();
  };
  for (link::Direction d : dirs) {
    const std::string end = d == link::Direction::kDown ? "tx" : "rx";
    if (wanted("cm_step"))
      if (Status e = add(build_cm_step(spec, parts, end)); !e.ok()) return e;
  }
  for (link::Direction d : dirs) {
    const std::string end = d == link::Direction::kDown ? "tx" : "rx";
    if (wanted("cm_wave"))
      if (Status e = add(build_cm_wave(spec, parts, end)); !e.ok()) return e;
  }
  if (wanted("esd"))
    for (const std::string end : {"tx", "rx"})
      for (const std::string line : {"p", "n"})
        for (int sign : {+1, -1})
          if (Status e = add(build_esd(spec, parts, end, line, sign)); !e.ok()) return e;
  if (wanted("hot_plug"))
    for (const std::string end : {"tx", "rx"})
      for (const std::string first : {"p", "n"})
        if (Status e = add(build_hot_plug(spec, parts, end, first)); !e.ok()) return e;
  if (wanted("wire"))
    for (const WireFault& f : kWireFaults)
      for (link::Direction d : dirs)
        if (Status e = add(build_wire(spec, parts, f, d)); !e.ok()) return e;
  return out;
}

namespace {

// The scenario's peaks from its run: pins (and each device's common mode), diode currents and
// TVS energies, isolation-cap voltages. Columns: 0 v(rxp,rxn), then the pins, the diodes'
// currents from diode0, the caps from cap0; tvs_v pairs a diode with its voltage's column.
void measure_peaks(StressScenario& s, const Waveform& w, const std::vector<std::string>& pins,
                   size_t diode0, size_t cap0, size_t contact0,
                   const std::vector<std::pair<size_t, size_t>>& tvs_v) {
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
  for (size_t i = 0; i < s.contacts.size(); ++i) {
    const std::vector<double> q = running_integral(w, contact0 + i);
    s.contacts[i].peak_1ns_a = window_mean_max_abs(w, q, kContactWindow);
    s.contacts[i].charge_c = q.empty() ? 0.0 : q.back();
  }
}

// Every limit the scenario's peaks break, in the order an engineer fixes them, into s.broken.
void judge_limits(StressScenario& s, const link::LinkSpec& spec, const link::PartLibrary& parts,
                  const std::vector<std::string>& pins) {
  const std::vector<StressLimit> limits = stress_limits(spec);
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
}

}  // namespace

Status run_stress_scenario(StressScenario& s, const link::LinkSpec& spec,
                           const link::PartLibrary& parts) {
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
  const size_t contact0 = req.probes.size();
  for (const ContactPeak& c : s.contacts) req.probes.push_back("i(" + c.ammeter + ")");
  StatusOr<SimulationResult> r = simulate_netlist(s.link.netlist, req);
  if (!r) return r.status().with_context("stress scenario " + s.id);
  const Waveform& w = r->wave;
  s.seconds = r->seconds;
  s.engine = engine_name(r->engine);
  if (!r->engine_note.empty()) s.engine += " (" + r->engine_note + ")";
  measure_peaks(s, w, pins, diode0, cap0, contact0, tvs_v);
  judge_limits(s, spec, parts, pins);
  s.survives = s.broken.empty();
  if (!s.receiver_p.empty()) {
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

Status run_stress_scenarios(std::vector<StressScenario>& scenarios,
                            const std::vector<const link::LinkSpec*>& specs,
                            const link::PartLibrary& parts, const StressOptions& opt) {
  // Each scenario is its own circuit and run: oneTBB runs them side by side, each writing only
  // its own scenario and status; the first failure in scenario order is the error.
  std::vector<Status> status(scenarios.size());
  std::mutex progress_mu;
  size_t done = 0;
  tbb::task_arena arena(opt.jobs > 0 ? opt.jobs : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, scenarios.size(), 1),
        [&](const tbb::blocked_range<size_t>& range) {
          for (size_t i = range.begin(); i != range.end(); ++i) {
            StressScenario& s = scenarios[i];
            if (opt.progress) {
              std::lock_guard<std::mutex> lock(progress_mu);
              opt.progress(s.id, static_cast<double>(done) / scenarios.size());
            }
            status[i] = run_stress_scenario(s, *specs[i], parts);
            if (opt.results_only) {
              s.link = link::ExpandedLink{};
              s.pins = Waveform{};
            }
            std::lock_guard<std::mutex> lock(progress_mu);
            ++done;
          }
        },
        tbb::simple_partitioner());
  });
  for (const Status& st : status)
    if (!st.ok()) return st;
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
  const std::vector<const link::LinkSpec*> specs(out.scenarios.size(), &spec);
  if (Status st = run_stress_scenarios(out.scenarios, specs, parts, opt); !st.ok()) return st;
  for (const StressScenario& s : out.scenarios) {
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
