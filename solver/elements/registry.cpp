// The one explicit table of element kinds (no static self-registration).
#include <fmt/format.h>

#include <array>
#include <cctype>
#include <cmath>

#include "solver/elements/kinds.h"

namespace isolink {

std::span<const ElementKind> element_kinds() {
  static const std::array<ElementKind, 9> kKinds = {
      capacitor_kind(),         diode_kind(),    vccs_kind(),     current_source_kind(),
      mutual_inductance_kind(), inductor_kind(), resistor_kind(), switch_kind(),
      voltage_source_kind(),
  };
  return kKinds;
}

const ElementKind* find_element_kind(char letter) {
  const char l = static_cast<char>(std::tolower(static_cast<unsigned char>(letter)));
  for (const auto& k : element_kinds())
    if (k.letter == l) return &k;
  return nullptr;
}

namespace {
std::string cell(std::string s) {  // a Markdown table cell: escape the column bar
  for (size_t i = 0; (i = s.find('|', i)) != std::string::npos; i += 2) s.insert(i, "\\");
  return s;
}
}  // namespace

std::string element_reference_markdown() {
  std::string out =
      "| kind | usage | parameter | default | unit | meaning |\n|---|---|---|---|---|---|\n";
  for (const ElementKind& k : element_kinds()) {
    bool first = true;
    auto row = [&](const ParamSpec& p, const std::string& name) {
      out += fmt::format("| {} | {} | {} | {} | {} | {} |\n", first ? k.name : "",
                         first ? cell(fmt::format("`{}`", k.usage)) : "", name,
                         std::isnan(p.default_value) ? (p.optional ? "none" : "required")
                                                     : fmt::format("{:g}", p.default_value),
                         p.unit, cell(p.doc));
      first = false;
    };
    for (const ParamSpec& p : k.params) row(p, p.name);
    // The model's parameters (.model NAME TYPE(...)), after the instance's.
    for (const ParamSpec& p : k.model_params)
      row(p, fmt::format(".model {} {}", k.model_type, p.name));
  }
  return out;
}

}  // namespace isolink
