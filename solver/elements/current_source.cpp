// I: independent current source; the current flows from n+ through the source to n-.
#include <cmath>

#include "solver/elements/card_values.h"
#include "solver/elements/kinds.h"
#include "solver/elements/source_function.h"
#include "solver/mna.h"

namespace isolink {
namespace {

constexpr ParamSpec kParams[] = {
    {"dc", 0.0, "A", "DC value, or PULSE | PWL | SIN | EXP as for V"},
    {"td", 0.0, "s", "PWL only: delay of the whole PWL"},
    {"r", -1.0, "s", "PWL only: repeat from this time point, as for V; -1: no repeat"},
};

class CurrentSource final : public Element {
 public:
  CurrentSource(const Card& card, SourceFunction f)
      : Element(card.name, card.loc), f_(std::move(f)) {}
  void stamp(MnaStamp&) const override {}
  bool has_excitation() const override { return true; }
  void stamp_rhs(double t, double* b) const override {
    const double i = f_.value(t);
    b[nodes_[0]] -= i, b[nodes_[1]] += i;
  }
  const SourceFunction* source_function() const override { return &f_; }
  void stamp_unit(double* b) const override { b[nodes_[0]] -= 1.0, b[nodes_[1]] += 1.0; }
  void bind_time(double tstep, double tstop) override { f_.bind_time(tstep, tstop); }
  void breakpoints(double tstop, std::vector<double>& out) const override {
    f_.breakpoints(tstop, out);
  }
  void dc_edges(std::vector<DcEdge>& out) const override {
    out.push_back({nodes_[0], nodes_[1], DcLink::CurrentSource});
  }

 private:
  SourceFunction f_;
};

StatusOr<std::unique_ptr<Element>> parse(const Card& card) {
  if (Status s = check_params(card, kParams); !s.ok()) return s;
  StatusOr<SourceFunction> f = SourceFunction::Parse(card);
  if (!f) return f.status();
  return std::unique_ptr<Element>(std::make_unique<CurrentSource>(card, std::move(*f)));
}

}  // namespace

const ElementKind& current_source_kind() {
  static const ElementKind kind{
      'i',
      "current source",
      "Iname n+ n- [DC] value | PULSE(...) | PWL(...) [td=T] [r=T] | SIN(...) | EXP(...)",
      2,
      0,
      kParams,
      parse};
  return kind;
}

}  // namespace isolink
