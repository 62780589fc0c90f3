#include "netlists/link/pins.h"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <utility>

#include "netlists/link/cards.h"

namespace isolink::link {

namespace {
Status positive(const char* model, const char* field, double v) {
  if (v > 0 && std::isfinite(v)) return Status::Ok();
  return Status::Error(fmt::format("{}.{} = {:g}: must be positive", model, field, v));
}

// The pins' clamp diodes and their rail (pins.h).
void add_clamps(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                const std::string& n, const PinClampModel& m) {
  if (!m.enabled) return;
  const std::string rail = prefix + "_cvdd";
  cards.push_back(make_card('v', "v" + prefix + "cvdd", {rail, "0"}, {number_arg(m.vdd)}));
  auto model = std::make_shared<CardModel>();
  model->name = prefix + "_clamp";
  model->type = "d";
  model->params = {{"is", number_arg(m.is)}, {"n", number_arg(1)}, {"rs", number_arg(m.rs)}};
  for (auto [pin, side] : {std::pair{p, "p"}, std::pair{n, "n"}}) {
    Card hi = make_card('d', "d" + prefix + "h" + side, {pin, rail}, {});
    Card lo = make_card('d', "d" + prefix + "l" + side, {"0", pin}, {});
    hi.model = lo.model = model;
    cards.push_back(std::move(hi));
    cards.push_back(std::move(lo));
  }
}

}  // namespace

Status PinClampModel::validate() const {
  if (!enabled) return Status::Ok();
  if (Status s = positive("pin_clamps", "vdd", vdd); !s.ok()) return s;
  if (Status s = positive("pin_clamps", "is", is); !s.ok()) return s;
  return positive("pin_clamps", "rs", rs);
}

Status TxDriverModel::validate() const {
  if (Status s = clamps.validate(); !s.ok()) return s;
  if (Status s = positive("tx_driver", "vdd", vdd); !s.ok()) return s;
  if (Status s = positive("tx_driver", "edge", edge); !s.ok()) return s;
  return positive("tx_driver", "r_out", r_out);
}

Status RxLoadModel::validate() const {
  if (Status s = clamps.validate(); !s.ok()) return s;
  if (Status s = positive("rx_load", "r_in", r_in); !s.ok()) return s;
  return positive("rx_load", "c_in", c_in);
}

Status add_tx_driver(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                     const std::string& n, const traffic::Drive& drive,
                     const TxDriverModel& model) {
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
    cards.push_back(make_card('v', "v" + prefix + side, {internal, "0"}, {pwl}));
    cards.push_back(make_card('r', "r" + prefix + side, {internal, sign > 0 ? p : n},
                              {number_arg(model.r_out)}));
  }
  add_clamps(cards, prefix, p, n, model.clamps);
  return Status::Ok();
}

Status add_rx_load(std::vector<Card>& cards, const std::string& prefix, const std::string& p,
                   const std::string& n, const RxLoadModel& model) {
  if (Status s = model.validate(); !s.ok()) return s;
  const std::string bias = prefix + "_bias";
  for (Card& c : std::vector<Card>{
           make_card('v', "v" + prefix + "bias", {bias, "0"}, {number_arg(model.bias)}),
           make_card('r', "r" + prefix + "inp", {p, bias}, {number_arg(model.r_in)}),
           make_card('r', "r" + prefix + "inn", {n, bias}, {number_arg(model.r_in)}),
           make_card('c', "c" + prefix + "inp", {p, "0"}, {number_arg(model.c_in)}),
           make_card('c', "c" + prefix + "inn", {n, "0"}, {number_arg(model.c_in)}),
       })
    cards.push_back(std::move(c));
  add_clamps(cards, prefix, p, n, model.clamps);
  return Status::Ok();
}

}  // namespace isolink::link
