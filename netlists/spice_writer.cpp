#include "netlists/spice_writer.h"

#include <fmt/format.h>

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

}  // namespace

std::string write_spice(const Netlist& n) {
  std::string out = n.title + "\n";
  for (const Card& c : n.cards) {
    out += element_name(c);
    for (const auto& node : c.nodes) out.append(" ").append(node);
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
