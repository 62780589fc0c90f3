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

Status add_tx_driver(Circuit& circuit, const std::string& prefix, const std::string& p,
                     const std::string& n, const traffic::Drive& drive, const TxDriverModel& model) {
  if (Status s = model.validate(); !s.ok()) return s;
  for (int sign : {+1, -1}) {
    const std::string side = sign > 0 ? "p" : "n";
    const std::string internal = prefix + "_drv" + side;
    CardArg pwl;
    pwl.kind = CardArg::Kind::Call;
    pwl.word = "pwl";
    StatusOr<std::vector<double>> points = traffic::line_pwl(drive, sign, model.edge, model.vdd);
    if (!points) return points.status().with_context("tx driver");
    pwl.call = std::move(*points);
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
