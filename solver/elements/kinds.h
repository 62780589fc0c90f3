// The element kinds, one per file in this folder; registry.cpp lists them in one table.
#pragma once

#include "solver/elements/element.h"

namespace isolink {

const ElementKind& resistor_kind();
const ElementKind& capacitor_kind();
const ElementKind& inductor_kind();
const ElementKind& mutual_inductance_kind();
const ElementKind& voltage_source_kind();
const ElementKind& current_source_kind();
const ElementKind& diode_kind();
const ElementKind& vccs_kind();
const ElementKind& switch_kind();

}  // namespace isolink
