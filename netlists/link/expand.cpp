#include "netlists/link/expand.h"

#include <fmt/format.h>

#include <cctype>
#include <utility>

#include "base/hex.h"
#include "netlists/link/board.h"
#include "netlists/link/cable.h"
#include "netlists/link/cards.h"
#include "netlists/spice_writer.h"

namespace isolink::link {

namespace {

// The error of a spec value, at the place it was written.
Status at(const SourceLoc& loc, const std::string& message) {
  return loc.valid() ? error_at(loc, message) : Status::Error(message);
}

StatusOr<BoardNetwork> board_for(const EndSpec& end) {
  StatusOr<BoardNetwork> b = board_preset(end.device);
  if (!b) return b.status();
  const std::string& type = end.isolation.type;
  // BQ79606A: 10 kohm with cap and cap + choke, 1 kohm with a transformer (docs/physics.md 4.4).
  if (end.device == "bq79606a" && type.rfind("transformer", 0) == 0) b->termination = 1e3;
  if (end.series_r) b->r_line = *end.series_r;
  if (end.bypass_c) b->bypass_c = *end.bypass_c;
  if (end.termination) b->termination = *end.termination;
  return b;
}

StatusOr<TransformerModel> transformer_for(const EndSpec& end, const PartLibrary& parts,
                                           const std::string& where) {
  const IsolationSpec& iso = end.isolation;
  std::string number = iso.part;
  if (number.empty()) number = end.device == "bq79606a" ? "CDEP99-102" : "HMU1228NL";
  const Part* part = parts.find(number);
  if (part == nullptr)
    return at(iso.loc, fmt::format("{}.isolation.part: unknown part '{}' (see `isolink parts`)",
                                   where, number));
  if (part->kind != PartKind::Transformer)
    return at(iso.loc, fmt::format("{}.isolation.part: '{}' is not a transformer", where, number));
  TransformerModel m = part->transformer;
  if (iso.inductance) m.inductance = *iso.inductance;
  if (iso.leakage) m.leakage = *iso.leakage;
  if (iso.dcr) m.dcr = *iso.dcr;
  if (iso.winding_c) m.winding_c = *iso.winding_c;
  if (iso.centre_tap_c) m.centre_tap_c = *iso.centre_tap_c;
  if (Status s = m.validate(); !s.ok())
    return at(iso.loc, fmt::format("{}.isolation: {}", where, s.message()));
  return m;
}

StatusOr<ChokeModel> choke_for(const IsolationSpec& iso, const std::string& number,
                               const PartLibrary& parts, const std::string& where) {
  const Part* part = parts.find(number);
  if (part == nullptr)
    return at(iso.loc, fmt::format("{}.isolation.chokes: unknown part '{}' (see `isolink parts`)",
                                   where, number));
  if (part->kind != PartKind::Choke)
    return at(iso.loc,
              fmt::format("{}.isolation.chokes: '{}' is not a common-mode choke", where, number));
  ChokeModel m = part->choke;
  if (iso.choke_loss == "none") m.loss_r = 0;
  if (iso.choke_loss == "resistance") m.loss_r = iso.choke_loss_r;
  return m;
}

// The cable-side caps per line (CBYPASS2): the spec's, else 100 pF with a transformer.
double cable_side_c_of(const IsolationSpec& iso) {
  if (iso.cable_side_c >= 0) return iso.cable_side_c;
  return iso.type.rfind("transformer", 0) == 0 ? 100e-12 : 0.0;
}

// The ESD part of an end on each line (ep, en) to ground: a capacitance, or a TVS part from the
// library as diodes (add_tvs), whose model is named after the part.
Status add_esd(std::vector<Card>& cards, const IsolationSpec& iso, const std::string& side,
               const std::string& ep, const std::string& en, const PartLibrary& parts,
               const std::string& where, std::string* bom) {
  if (iso.esd_part.empty()) {
    *bom += "; ESD " + format_si(iso.esd, "F") + " per line";
    cards.push_back(make_card('c', "c" + side + "esdp", {ep, "0"}, {number_arg(iso.esd)}));
    cards.push_back(make_card('c', "c" + side + "esdn", {en, "0"}, {number_arg(iso.esd)}));
    return Status::Ok();
  }
  const Part* part = parts.find(iso.esd_part);
  if (part == nullptr)
    return at(iso.esd_loc, fmt::format("{}.isolation.esd: '{}' is neither a capacitance (20p) nor "
                                       "a part of the library (see `isolink parts`)",
                                       where, iso.esd_part));
  if (part->kind != PartKind::Tvs)
    return at(iso.esd_loc, fmt::format("{}.isolation.esd: '{}' is a {}, not a TVS", where,
                                       part->number, part_kind_name(part->kind)));
  const TvsModel& m = part->tvs;
  *bom += fmt::format("; TVS {} per line ({}, VBR {:g} V, VCL {:g} V at {:g} A, {} at 0 V)",
                      part->number, m.bidirectional ? "bidirectional" : "unidirectional",
                      m.breakdown, m.clamp, m.clamp_current, format_si(m.capacitance, "F"));
  std::string model_name;
  for (char c : part->number) model_name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  for (auto [line, tag] : {std::pair{ep, "p"}, std::pair{en, "n"}})
    if (Status s = add_tvs(cards, "d" + side + "esd" + tag, line, "0", "tvs_" + model_name, m);
        !s.ok())
      return at(iso.esd_loc, fmt::format("{}.isolation.esd: {}", where, s.message()));
  return Status::Ok();
}

// One end's board and isolation between its device pins (pin_p/pin_n) and its cable connector
// nodes; returns the connector node names.
StatusOr<std::pair<std::string, std::string>> add_end(std::vector<Card>& cards, const EndSpec& end,
                                                      const std::string& side,
                                                      const std::string& where,
                                                      const PartLibrary& parts, std::string* bom) {
  StatusOr<BoardNetwork> board = board_for(end);
  if (!board) return at(end.loc, fmt::format("{}: {}", where, board.status().message()));
  const std::string pin_p = side + "p", pin_n = side + "n";
  std::string p = side + "_lp", n = side + "_ln";
  if (Status s = add_board_network(cards, side + "b", pin_p, pin_n, p, n, *board); !s.ok())
    return at(end.loc, fmt::format("{}: {}", where, s.message()));
  const IsolationSpec& iso = end.isolation;
  const std::string& type = iso.type;
  *bom = fmt::format("{}: {} per line{}, {} bypass, {} termination", end.device,
                     format_si(board->r_line, "ohm"),
                     board->r_pin > 0 ? " + " + format_si(board->r_pin, "ohm") + " at the pin" : "",
                     format_si(board->bypass_c, "F"), format_si(board->termination, "ohm"));
  int stage = 0;
  auto next = [&](const std::string& tag) {
    ++stage;
    return std::pair{fmt::format("{}_{}{}p", side, tag, stage),
                     fmt::format("{}_{}{}n", side, tag, stage)};
  };
  if (type == "none") *bom += "; no isolation";
  if (type == "cap" || type == "capchoke") {
    *bom += "; " + format_si(iso.cap, "F") + " isolation cap per line";
    auto [a, b] = next("c");
    cards.push_back(make_card('c', "c" + side + "isop", {p, a}, {number_arg(iso.cap)}));
    cards.push_back(make_card('c', "c" + side + "ison", {n, b}, {number_arg(iso.cap)}));
    p = a, n = b;
  }
  if (type == "transformer" || type == "transformer_choke") {
    StatusOr<TransformerModel> m = transformer_for(end, parts, where);
    if (!m) return m.status();
    *bom += fmt::format(
        "; transformer {} (OCL {}, leakage {}, DCR {}{})",
        iso.part.empty() ? "(device default part)" : iso.part, format_si(m->inductance, "H"),
        format_si(m->leakage, "H"), format_si(m->dcr, "ohm"),
        m->centre_tap_c > 0 ? ", centre tap " + format_si(m->centre_tap_c, "F") : "");
    auto [a, b] = next("t");
    if (Status s = add_transformer(cards, "t" + side, p, n, a, b, *m); !s.ok())
      return at(iso.loc, fmt::format("{}.isolation: {}", where, s.message()));
    p = a, n = b;
  }
  if (type == "capchoke" || type == "transformer_choke") {
    std::vector<std::string> chokes = iso.chokes;
    if (chokes.empty()) chokes = {"ACT45B-510-2P-TL003"};
    for (size_t i = 0; i < chokes.size(); ++i) {
      StatusOr<ChokeModel> m = choke_for(iso, chokes[i], parts, where);
      if (!m) return m.status();
      *bom += fmt::format("; choke {} ({} per winding, k {:.4f})", chokes[i],
                          format_si(m->inductance, "H"), m->k);
      auto [a, b] = next("k");
      if (Status s = add_choke(cards, fmt::format("l{}{}", side, i + 1), p, n, a, b, *m); !s.ok())
        return at(iso.loc, fmt::format("{}.isolation: {}", where, s.message()));
      p = a, n = b;
    }
  }
  // CBYPASS2: 100 pF per line on the cable side of a transformer (TI's transformer figure).
  // Returning to the chassis, add_connector_caps adds them after the board is regrounded.
  const double cable_side_c = cable_side_c_of(iso);
  if (cable_side_c > 0 && iso.cable_side_return == "board") {
    *bom += "; " + format_si(cable_side_c, "F") + " per line on the cable side";
    cards.push_back(make_card('c', "c" + side + "cabp", {p, "0"}, {number_arg(cable_side_c)}));
    cards.push_back(make_card('c', "c" + side + "cabn", {n, "0"}, {number_arg(cable_side_c)}));
  }
  if (iso.esd > 0 || !iso.esd_part.empty()) {
    // The ESD part sits at the board's ESD node when it has one (BQ79606A), else at the connector.
    const bool esd_node = board->r_pin > 0;
    const std::string ep = esd_node ? side + "b_esdp" : p, en = esd_node ? side + "b_esdn" : n;
    if (Status s = add_esd(cards, iso, side, ep, en, parts, where, bom); !s.ok()) return s;
  }
  if (type != "none") {
    // Behind the isolation the cable has no DC path of its own: give each line the leakage a real
    // board has there (kCableBleed, see expand.h), so the DC point is defined by the circuit and
    // not by the solver's tie for floating nodes, and the solver's warning stays for mistakes.
    cards.push_back(make_card('r', "r" + side + "bleedp", {p, "0"}, {number_arg(kCableBleed)}));
    cards.push_back(make_card('r', "r" + side + "bleedn", {n, "0"}, {number_arg(kCableBleed)}));
  }
  return std::pair{p, n};
}

// Moves the cards from index `from` on off the chassis onto the board ground `ground`.
void reground(std::vector<Card>& cards, size_t from, const std::string& ground) {
  if (ground == "0") return;
  for (size_t i = from; i < cards.size(); ++i)
    for (std::string& node : cards[i].nodes)
      if (node == "0" || node == "gnd") node = ground;
}

// X and Y caps at the connector (p, n) of an end, and the board's capacitance to the chassis
// when its ground is kept apart.
void add_connector_caps(std::vector<Card>& cards, const EndSpec& end, const std::string& side,
                        const std::string& p, const std::string& n, const std::string& ground,
                        std::string* bom) {
  if (end.x_cap > 0) {
    *bom += "; X cap " + format_si(end.x_cap, "F");
    cards.push_back(make_card('c', "c" + side + "x", {p, n}, {number_arg(end.x_cap)}));
  }
  if (end.y_cap > 0) {
    *bom += "; Y caps " + format_si(end.y_cap, "F") + " per line";
    cards.push_back(make_card('c', "c" + side + "yp", {p, "0"}, {number_arg(end.y_cap)}));
    cards.push_back(make_card('c', "c" + side + "yn", {n, "0"}, {number_arg(end.y_cap)}));
  }
  const double cable_side_c = cable_side_c_of(end.isolation);
  if (cable_side_c > 0 && end.isolation.cable_side_return == "chassis") {
    *bom += "; " + format_si(cable_side_c, "F") + " per line on the cable side, to the chassis";
    cards.push_back(make_card('c', "c" + side + "cabp", {p, "0"}, {number_arg(cable_side_c)}));
    cards.push_back(make_card('c', "c" + side + "cabn", {n, "0"}, {number_arg(cable_side_c)}));
  }
  if (ground == "0") return;
  cards.push_back(
      make_card('c', "c" + side + "chassis", {ground, "0"}, {number_arg(end.chassis_c)}));
  if (end.chassis_r > 0) {
    // The bond: a strap or screw, R in series with its L.
    const std::string mid = end.chassis_l > 0 ? ground + "_bond" : "0";
    cards.push_back(
        make_card('r', "r" + side + "bond", {ground, mid}, {number_arg(end.chassis_r)}));
    if (end.chassis_l > 0)
      cards.push_back(make_card('l', "l" + side + "bond", {mid, "0"}, {number_arg(end.chassis_l)}));
  }
}

NetlistOption option(const std::string& key, double v) {
  return NetlistOption{key, number_arg(v), {}};
}

}  // namespace

StatusOr<ExpandedLink> expand_link(const LinkSpec& spec, const PartLibrary& parts, Direction d,
                                   const ExpandOptions& opt) {
  ExpandedLink out;
  out.direction = d;
  const bool down = d == Direction::kDown;
  const EndSpec& from = down ? spec.tx : spec.rx;
  const EndSpec& to = down ? spec.rx : spec.tx;
  const std::string from_key = down ? "tx" : "rx", to_key = down ? "rx" : "tx";
  out.transmitter = from.device;
  out.receiver = to.device;
  out.rules = device_rules(to.device);
  out.description = fmt::format("{}: {} -> {}", direction_name(d), from.device, to.device);

  if (opt.drive) {
    out.drive = *opt.drive;
  } else {
    StatusOr<traffic::Drive> drive = traffic::build_drive(spec.stimulus.to_script(), opt.stimulus);
    if (!drive) return at(spec.stimulus.loc, "stimulus: " + drive.status().message());
    out.drive = std::move(*drive);
  }
  for (const traffic::DriveFrame& f : out.drive.frames)
    out.expected.insert(out.expected.end(), f.bytes.begin(), f.bytes.end());

  std::vector<Card>& cards = out.netlist.cards;
  // The pins' clamps come from the spec's ends (the device at each pin), the rest from opt.
  TxDriverModel driver = opt.driver;
  RxLoadModel load = opt.load;
  driver.clamps.enabled = driver.clamps.enabled || from.pin_clamps == "rails";
  load.clamps.enabled = load.clamps.enabled || to.pin_clamps == "rails";
  if (Status s = add_tx_driver(cards, "tx", "txp", "txn", out.drive, driver); !s.ok())
    return s.with_context("tx driver");
  std::string* from_bom = down ? &out.tx_bom : &out.rx_bom;
  std::string* to_bom = down ? &out.rx_bom : &out.tx_bom;
  auto a = add_end(cards, from, "tx", from_key, parts, from_bom);
  if (!a) return a.status();
  reground(cards, 0, opt.tx_ground);
  add_connector_caps(cards, from, "tx", a->first, a->second, opt.tx_ground, from_bom);
  size_t to_start = cards.size();
  auto b = add_end(cards, to, "rx", to_key, parts, to_bom);
  if (!b) return b.status();
  reground(cards, to_start, opt.rx_ground);
  add_connector_caps(cards, to, "rx", b->first, b->second, opt.rx_ground, to_bom);
  if (Status s = add_cable(cards, "cab", a->first, a->second, b->first, b->second, spec.cable,
                           opt.driver.edge, &out.cable_segments);
      !s.ok())
    return at(spec.cable_loc, "cable: " + s.message());
  out.cable_ends = {a->first, a->second, b->first, b->second};
  const size_t load_start = cards.size();
  if (Status s = add_rx_load(cards, "rx", "rxp", "rxn", load); !s.ok())
    return s.with_context("rx load");
  reground(cards, load_start, opt.rx_ground);

  out.netlist.title = fmt::format("isolink link spec '{}', {}", spec.name, out.description);
  TranSpec tran;
  tran.tstep = spec.sim.tstep;
  tran.tstop = out.drive.duration();
  if (spec.sim.tmax) tran.tmax = *spec.sim.tmax;
  out.netlist.tran = tran;
  if (spec.sim.method == "gear") {
    CardArg w;
    w.kind = CardArg::Kind::Word;
    w.word = "gear";
    out.netlist.options.push_back(NetlistOption{"method", w, {}});
  }
  if (spec.sim.reltol) out.netlist.options.push_back(option("reltol", *spec.sim.reltol));
  return out;
}

std::string circuit_key(const ExpandedLink& x) {
  Netlist n = x.netlist;
  n.title.clear();
  std::string key = write_spice(n);
  key += "\n* rules " + x.rules + "\n* expect " + to_hex(x.expected) + "\n";
  return key;
}

}  // namespace isolink::link
