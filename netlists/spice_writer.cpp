#include "netlists/spice_writer.h"

#include <fmt/format.h>

#include <memory>
#include <utility>
#include <vector>

namespace isolink {
namespace {

constexpr std::size_t kValuesPerLine = 8;

std::string num(double v) {
  return fmt::format("{:.12g}", v);
}

void write_arg(std::string& out, const CardArg& a) {
  switch (a.kind) {
    case CardArg::Kind::Number:
      out += num(a.number);
      return;
    case CardArg::Kind::Word:
      out += a.word;
      return;
    case CardArg::Kind::Call:
      out += a.word;
      out += '(';
      for (std::size_t i = 0; i < a.call.size(); ++i) {
        if (i > 0) out += (i % kValuesPerLine == 0) ? "\n+ " : " ";
        out += num(a.call[i]);
      }
      out += ')';
      return;
  }
}

// Hierarchical names are written as ngspice flattens them: "x1.r3" -> "r.x1.r3".
std::string element_name(const Card& c) {
  if (c.name.find('.') == std::string::npos) return c.name;
  return fmt::format("{}.{}", c.letter, c.name);
}

// The .model cards the elements name, each written once. Two different models of one name
// (flattened from two subcircuits' scopes) get distinct names ("dmod", "dmod_2").
class ModelNames {
 public:
  const std::string& name_of(const std::shared_ptr<const CardModel>& m) {
    for (const auto& [model, name] : models_)
      if (model == m.get() || same(*model, *m)) return name;
    std::string name = m->name;
    for (int k = 2; taken(name); ++k) name = fmt::format("{}_{}", m->name, k);
    models_.emplace_back(m.get(), name);
    return models_.back().second;
  }
  std::string cards() const {
    std::string out;
    for (const auto& [m, name] : models_) {
      out += fmt::format(".model {} {}(", name, m->type);
      for (std::size_t i = 0; i < m->params.size(); ++i) {
        out += i ? " " : "";
        out += m->params[i].first + "=";
        write_arg(out, m->params[i].second);
      }
      out += ")\n";
    }
    return out;
  }

 private:
  static bool same(const CardModel& a, const CardModel& b) {
    if (a.name != b.name || a.type != b.type || a.params.size() != b.params.size()) return false;
    for (std::size_t i = 0; i < a.params.size(); ++i) {
      const CardArg &x = a.params[i].second, &y = b.params[i].second;
      if (a.params[i].first != b.params[i].first || x.kind != y.kind || x.number != y.number ||
          x.word != y.word)
        return false;
    }
    return true;
  }
  bool taken(const std::string& name) const {
    for (const auto& [m, n] : models_)
      if (n == name) return true;
    return false;
  }
  std::vector<std::pair<const CardModel*, std::string>> models_;
};

}  // namespace

std::string write_spice(const Netlist& n) {
  std::string out = n.title + "\n";
  ModelNames models;
  for (const Card& c : n.cards) {
    out += element_name(c);
    for (const auto& node : c.nodes) out.append(" ").append(node);
    if (c.model) out.append(" ").append(models.name_of(c.model));
    // K names inductors: a hierarchical one by its flattened name too ("x1.l3" -> "l.x1.l3").
    for (const auto& ref : c.refs)
      out.append(" ").append(ref.find('.') == std::string::npos ? ref : "l." + ref);
    for (const auto& a : c.args) {
      out += ' ';
      write_arg(out, a);
    }
    for (const auto& [key, a] : c.params) {
      out.append(" ").append(key).append("=");
      write_arg(out, a);
    }
    out += '\n';
  }
  out += models.cards();
  for (const auto& o : n.options) {
    out.append(".options ").append(o.key);
    if (o.value.kind != CardArg::Kind::Word || !o.value.word.empty()) {
      out += '=';
      write_arg(out, o.value);
    }
    out += '\n';
  }
  for (const InitialVoltage& ic : n.initial_voltages)
    out += fmt::format(".ic v({})={:.12g}\n", ic.node, ic.value);
  if (n.tran) {
    const TranSpec& t = *n.tran;
    out += fmt::format(".tran {:.12g} {:.12g}", t.tstep, t.tstop);
    if (t.tstart != 0 || t.tmax != 0) out += fmt::format(" {:.12g}", t.tstart);
    if (t.tmax != 0) out += fmt::format(" {:.12g}", t.tmax);
    if (t.uic) out += " uic";
    out += '\n';
  }
  out += ".end\n";
  return out;
}

}  // namespace isolink
