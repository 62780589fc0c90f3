// V: independent voltage source, V(n+) - V(n-) = f(t); branch current flows n+ -> source -> n-.
#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/elements/source_function.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"dc", 0.0, "V",
     "DC value (positional, DC VALUE or dc=VALUE); a PULSE(V1 V2 TD TR TF PW PER "
     "NP), PWL(t v ...), SIN(VO VA F TD THETA PHASE) or EXP(V1 V2 TD1 TAU1 TD2 "
     "TAU2) function, parentheses optional, sets the transient"},
    {"td", 0.0, "s", "PWL only: delay of the whole PWL"},
    {"r", -1.0, "s",
     "PWL only: repeat the PWL from this time point (one of its times) to its "
     "last time, for ever; -1: no repeat"},
};

class VoltageSource final : public Element {
 public:
  VoltageSource(const Card& card, SourceFunction f)
      : Element(card.name, card.loc), f_(std::move(f)) {}
  int branch_count() const override { return 1; }
  void stamp(MnaStamp& m) const override {
    const int a = nodes_[0], b = nodes_[1], br = branches_[0];
    m.g(a, br, 1), m.g(b, br, -1), m.g(br, a, 1), m.g(br, b, -1);
  }
  bool has_excitation() const override { return true; }
  void stamp_rhs(double t, double* b) const override { b[branches_[0]] += f_.value(t); }
  const SourceFunction* source_function() const override { return &f_; }
  void stamp_unit(double* b) const override { b[branches_[0]] += 1.0; }
  void bind_time(double tstep, double tstop) override { f_.bind_time(tstep, tstop); }
  void breakpoints(double tstop, std::vector<double>& out) const override {
    f_.breakpoints(tstop, out);
  }
  void dc_edges(std::vector<DcEdge>& out) const override {
    out.push_back({nodes_[0], nodes_[1], DcLink::VoltageDefining});
  }

 private:
  SourceFunction f_;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<SourceFunction> f = SourceFunction::Parse(card);
  if (!f) return f.status();
  return std::unique_ptr<Element>(std::make_unique<VoltageSource>(card, std::move(*f)));
}

}  // namespace

const ElementKind& voltage_source_kind() {
  static const ElementKind kind{
      'v',
      "voltage source",
      "Vname n+ n- [DC] value | PULSE(...) | PWL(...) [td=T] [r=T] | SIN(...) | EXP(...)",
      2,
      0,
      kParams,
      parse};
  return kind;
}

}  // namespace isolink
