#include "solver/probe.h"

#include <algorithm>
#include <cctype>

namespace isolink {

StatusOr<Probe> parse_probe(const Circuit& circuit, std::string_view text) {
  std::string s;
  for (char ch : text)
    if (!std::isspace(static_cast<unsigned char>(ch)))
      s += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const std::string usage =
      "probe '" + std::string(text) + "': expected v(node), v(node,node) or i(element)";
  if (s.size() < 4 || (s[0] != 'v' && s[0] != 'i') || s[1] != '(' || s.back() != ')')
    return Status::Error(usage);
  std::string inner = s.substr(2, s.size() - 3);
  Probe p;
  p.label = s;
  if (s[0] == 'i') {
    const Element* e = circuit.find_element(inner);
    if (!e) {  // ngspice's form: i(v.x1.vm) for x1.vm
      inner = unflatten_name(inner);
      e = circuit.find_element(inner);
    }
    if (!e)
      return Status::Error("probe '" + std::string(text) + "': no element named '" + inner + "'");
    if (e->branches().empty())
      return Status::Error("probe '" + std::string(text) + "': '" + inner +
                           "' has no branch current (only V sources and inductors do)");
    p.a = e->branches()[0];
    return p;
  }
  auto comma = inner.find(',');
  std::string na = inner.substr(0, comma);
  std::string nb = comma == std::string::npos ? "0" : inner.substr(comma + 1);
  if (na.empty() || nb.empty()) return Status::Error(usage);
  p.a = circuit.find_node(na);
  p.b = circuit.find_node(nb);
  for (auto [idx, name] : {std::pair{p.a, na}, std::pair{p.b, nb}})
    if (idx < 0)
      return Status::Error("probe '" + std::string(text) + "': no node named '" + name + "'");
  return p;
}

}  // namespace isolink
