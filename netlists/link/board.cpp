#include "netlists/link/board.h"

#include <fmt/format.h>

#include <cmath>

#include "netlists/link/cards.h"

namespace isolink::link {

namespace {
Card value_card(char letter, const std::string& name, std::vector<std::string> nodes, double v) {
  return make_card(letter, name, std::move(nodes), {number_arg(v)});
}
}  // namespace

Status BoardNetwork::validate() const {
  auto bad = [](const char* field, double v, const char* rule) {
    return Status::Error(fmt::format("board.{} = {:g}: {}", field, v, rule));
  };
  if (!(r_pin >= 0)) return bad("r_pin", r_pin, "must not be negative");
  if (!(r_line > 0)) return bad("r_line", r_line, "must be positive");
  if (!(bypass_c >= 0)) return bad("bypass_c", bypass_c, "must not be negative");
  if (!(termination > 0)) return bad("termination", termination, "must be positive");
  return Status::Ok();
}

std::vector<std::string> board_preset_names() {
  return {"bq7961x", "bq79600", "bq79606a"};
}

StatusOr<BoardNetwork> board_preset(const std::string& device) {
  if (device == "bq7961x") return BoardNetwork{0.0, 49.0, 220e-12, 1e3};
  if (device == "bq79600") return BoardNetwork{0.0, 49.0, 100e-12, 1e3};
  if (device == "bq79606a") return BoardNetwork{10.0, 43.0, 51e-12, 10e3};
  return Status::Error("unknown device '" + device + "' (known: bq7961x, bq79600, bq79606a)");
}

Status add_board_network(std::vector<Card>& cards, const std::string& prefix,
                         const std::string& pin_p, const std::string& pin_n,
                         const std::string& line_p, const std::string& line_n,
                         const BoardNetwork& b) {
  if (Status s = b.validate(); !s.ok()) return s;
  for (auto [side, pin, line] : {std::tuple{"p", pin_p, line_p}, std::tuple{"n", pin_n, line_n}}) {
    std::string from = pin;
    if (b.r_pin > 0) {
      const std::string esd = prefix + "_esd" + side;
      cards.push_back(value_card('r', "r" + prefix + "pin" + side, {pin, esd}, b.r_pin));
      from = esd;
    }
    cards.push_back(value_card('r', "r" + prefix + "ser" + side, {from, line}, b.r_line));
    if (b.bypass_c > 0)
      cards.push_back(value_card('c', "c" + prefix + "byp" + side, {line, "0"}, b.bypass_c));
  }
  cards.push_back(value_card('r', "r" + prefix + "term", {line_p, line_n}, b.termination));
  return Status::Ok();
}

}  // namespace isolink::link
