// S: the voltage-controlled switch, as ngspice's SW model (src/spicelib/devices/sw) without
// hysteresis: between n+ and n- a resistance RON while the control voltage v(nc+, nc-) is above
// VT, ROFF while it is at or below. The control nodes draw no current.
//
//   .model CONTACT SW(VT=0.5 RON=0.1 ROFF=1e9)
//   S1 n+ n- nc+ nc- CONTACT
//
// One nonlinear port (Element::eval_controlled_port) from n+ to n-, controlled by (nc+, nc-):
// its conductance is a step function of the control voltage, so its derivative with respect to
// the control is 0 (the Newton iteration re-evaluates the state at every iterate, as ngspice's
// SWload does). A switch driven by a PWL source changes state at the source's corners, which are
// breakpoints of both engines. Hysteresis (VH) needs the state of the last time point, which the
// engines do not hand to an element: VH must be 0.
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kModelParams[] = {
    {"vt", 0.0, "V", "threshold: on while v(nc+, nc-) > vt"},
    {"vh", 0.0, "V", "hysteresis: 0 only (not modelled)"},
    {"ron", 1.0, "ohm", "on resistance, positive"},
    {"roff", 1e12, "ohm", "off resistance, positive (ngspice's default: 1 / gmin)"},
};

class Switch final : public Element {
 public:
  Switch(const Card& card, double vt, double ron, double roff)
      : Element(card.name, card.loc), vt_(vt), gon_(1.0 / ron), goff_(1.0 / roff) {}

  bool linear_time_invariant() const override { return false; }
  int nonlinear_port_count() const override { return 1; }
  NonlinearPort nonlinear_port(int) const override {
    NonlinearPort p{nodes_[0], nodes_[1]};
    p.controlled = true;
    p.cp = nodes_[2], p.cn = nodes_[3];
    return p;
  }
  void stamp(MnaStamp& m) const override {
    const int a = nodes_[0], b = nodes_[1];
    // The port's entries, declared here with 0: the Newton iteration adds its linearisation.
    m.g(a, a, 0.0), m.g(b, b, 0.0), m.g(a, b, 0.0), m.g(b, a, 0.0);
  }
  void dc_edges(std::vector<DcEdge>& out) const override {
    out.push_back({nodes_[0], nodes_[1], DcLink::Conductive});  // roff at least
  }
  // Without its control (the port model's view): off.
  PortEval eval_port(int k, double v) const override {
    return eval_controlled_port(k, v, -std::numeric_limits<double>::infinity());
  }
  bool control_state(int, double vc) const override { return vc > vt_; }
  PortEval eval_controlled_port(int, double v, double vc) const override {
    PortEval e;
    e.g = vc > vt_ ? gon_ : goff_;
    e.i = e.g * v;
    return e;
  }

 private:
  double vt_, gon_, goff_;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (!card.model)
    return error_at(card.loc, fmt::format("switch {} names no .model (usage: {})", card.name,
                                          "Sname n+ n- nc+ nc- model"));
  if (!card.args.empty() || !card.params.empty())
    return error_at(card.args.empty() ? card.params.front().second.loc : card.args.front().loc,
                    fmt::format("unexpected value for switch {} (usage: Sname n+ n- nc+ nc- "
                                "model; the initial state on/off is not needed without "
                                "hysteresis)",
                                card.name));
  const CardModel& model = *card.model;
  double v[std::size(kModelParams)];
  SourceLoc where[std::size(kModelParams)];
  for (std::size_t k = 0; k < std::size(kModelParams); ++k) {
    v[k] = kModelParams[k].default_value;
    where[k] = model.loc;
  }
  for (const auto& [key, arg] : model.params) {
    std::size_t k = 0;
    while (k < std::size(kModelParams) && key != kModelParams[k].name) ++k;
    if (k == std::size(kModelParams))
      return error_at(arg.loc, fmt::format("unknown switch model parameter '{}' in model {} "
                                           "(known: vt, vh, ron, roff)",
                                           key, model.name));
    if (arg.kind != CardArg::Kind::Number || !std::isfinite(arg.number))
      return error_at(arg.loc, fmt::format("switch model parameter {} of {} needs a finite number",
                                           key, model.name));
    v[k] = arg.number, where[k] = arg.loc;
  }
  if (v[1] != 0)
    return error_at(where[1], fmt::format("switch model {}: vh = {:g}: must be 0 (hysteresis "
                                          "needs the last time point's state; not modelled)",
                                          model.name, v[1]));
  for (std::size_t k : {2u, 3u})
    if (!(v[k] > 0))
      return error_at(where[k], fmt::format("switch model {}: {} = {:g}: must be positive",
                                            model.name, kModelParams[k].name, v[k]));
  return std::unique_ptr<Element>(std::make_unique<Switch>(card, v[0], v[2], v[3]));
}

}  // namespace

const ElementKind& switch_kind() {
  static const ElementKind kind{'s',  "switch",    "Sname n+ n- nc+ nc- model", 4, 0, {}, parse,
                                "sw", kModelParams};
  return kind;
}

}  // namespace isolink
