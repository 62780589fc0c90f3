// The one explicit table of element kinds (no static self-registration).
#include <array>
#include <cctype>

#include "solver/elements/kinds.h"

namespace isolink {

std::span<const ElementKind> element_kinds() {
  static const std::array<ElementKind, 6> kKinds = {
      capacitor_kind(), current_source_kind(), mutual_inductance_kind(),
      inductor_kind(),  resistor_kind(),       voltage_source_kind(),
  };
  return kKinds;
}

const ElementKind* find_element_kind(char letter) {
  const char l = static_cast<char>(std::tolower(static_cast<unsigned char>(letter)));
  for (const auto& k : element_kinds())
    if (k.letter == l) return &k;
  return nullptr;
}

}  // namespace isolink
