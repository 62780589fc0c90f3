#include "netlists/link/pins.h"

#include <cmath>

#include <fmt/format.h>

namespace isolink::link {

namespace {
Status positive(const char* model, const char* field, double v) {
  if (v > 0 && std::isfinite(v)) return Status::Ok();
  return Status::Error(fmt::format("{}.{} = {:g}: must be positive", model, field, v));
}

Card make_card(char letter, const std::string& name, std::vector<std::string> nodes,
               std::vector<CardArg> args) {
  Card c;
  c.letter = letter;
  c.name = name;
  c.nodes = std::move(nodes);
  c.node_locs.resize(c.nodes.size());
  c.args = std::move(args);
  return c;
}

CardArg number(double v) {
  CardArg a;
  a.number = v;
  return a;
}
}  // namespace

Status TxDriverModel::validate() const {
  if (Status s = positive("tx_driver", "vdd", vdd); !s.ok()) return s;
  if (Status s = positive("tx_driver", "edge", edge); !s.ok()) return s;
  return positive("tx_driver", "r_out", r_out);
}

Status RxLoadModel::validate() const {
  if (Status s = positive("rx_load", "r_in", r_in); !s.ok()) return s;
  return positive("rx_load", "c_in", c_in);
}

std::vector<double> drive_pwl(const traffic::Drive& drive, const TxDriverModel& model,
                              int line_sign) {
  // Line voltage for a level: P follows the level, N its complement; idle = vdd / 2.
  auto volts = [&](int level) { return model.vdd * (0.5 + 0.5 * line_sign * level); };
  std::vector<double> pwl;
  pwl.reserve(4 * drive.segments.size() + 2);
  auto point = [&pwl](double t, double v) {
    pwl.push_back(t);
    pwl.push_back(v);
  };
  point(0.0, volts(drive.segments.empty() ? 0 : drive.segments.front().level));
  for (size_t i = 1; i < drive.segments.size(); ++i) {
    const double t = drive.segments[i].start;
    // The edge starts at the boundary and takes `edge` (clipped to half the shorter neighbour).
    const double room = std::min(drive.segments[i - 1].end - drive.segments[i - 1].start,
                                 drive.segments[i].end - drive.segments[i].start);
    const double e = std::min(model.edge, 0.5 * room);
    const double prev_t = pwl[pwl.size() - 2];
    if (t > prev_t) point(t, volts(drive.segments[i - 1].level));
    point(t + e, volts(drive.segments[i].level));
  }
  return pwl;
}

Status add_tx_driver(Circuit& circuit, const std::string& prefix, const std::string& p,
                     const std::string& n, const traffic::Drive& drive, const TxDriverModel& model) {
  if (Status s = model.validate(); !s.ok()) return s;
  for (int sign : {+1, -1}) {
    const std::string side = sign > 0 ? "p" : "n";
    const std::string internal = prefix + "_drv" + side;
    CardArg pwl;
    pwl.kind = CardArg::Kind::Call;
    pwl.word = "pwl";
    pwl.call = drive_pwl(drive, model, sign);
    if (Status s = circuit.add(make_card('v', "v" + prefix + side, {internal, "0"}, {pwl})); !s.ok())
      return s;
    if (Status s = circuit.add(make_card('r', "r" + prefix + side, {internal, sign > 0 ? p : n},
                                         {number(model.r_out)}));
        !s.ok())
      return s;
  }
  return Status::Ok();
}

Status add_rx_load(Circuit& circuit, const std::string& prefix, const std::string& p,
                   const std::string& n, const RxLoadModel& model) {
  if (Status s = model.validate(); !s.ok()) return s;
  const std::string bias = prefix + "_bias";
  std::vector<Card> cards{
      make_card('v', "v" + prefix + "bias", {bias, "0"}, {number(model.bias)}),
      make_card('r', "r" + prefix + "inp", {p, bias}, {number(model.r_in)}),
      make_card('r', "r" + prefix + "inn", {n, bias}, {number(model.r_in)}),
      make_card('c', "c" + prefix + "inp", {p, "0"}, {number(model.c_in)}),
      make_card('c', "c" + prefix + "inn", {n, "0"}, {number(model.c_in)}),
  };
  for (const Card& c : cards)
    if (Status s = circuit.add(c); !s.ok()) return s;
  return Status::Ok();
}

}  // namespace isolink::link
