// libFuzzer targets for every reader (issue 15), and for .model through the diode (issue 41): one
// source, built once per reader with ISOLINK_FUZZ_READER set (tests/fuzz/CMakeLists.txt). Each
// feeds the bytes to the reader as a file's text; any crash, sanitizer report, leak, timeout or
// memory blow-up is a finding. The readers answer bad input with a Status, so the return value is
// ignored.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#if ISOLINK_FUZZ_READER == 1
#include "netlists/spice_reader.h"
#elif ISOLINK_FUZZ_READER == 2
#include "netlists/link/link_spec.h"
#elif ISOLINK_FUZZ_READER == 3
#include "analysis/sweep_spec.h"
#elif ISOLINK_FUZZ_READER == 4
#include "netlists/link/parts.h"
#elif ISOLINK_FUZZ_READER == 5
#include "eye/rules.h"
#elif ISOLINK_FUZZ_READER == 6
#include "eye/waveform_csv.h"
#elif ISOLINK_FUZZ_READER == 7
#include "netlists/traffic/stimulus.h"
#elif ISOLINK_FUZZ_READER == 8
#include <cstdio>

#include "eye/scope_binary.h"
#elif ISOLINK_FUZZ_READER == 9
#include <cmath>
#include <cstdlib>

#include "netlists/spice_reader.h"
#include "solver/circuit.h"
#elif ISOLINK_FUZZ_READER == 10
#include "netlists/touchstone.h"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
#if ISOLINK_FUZZ_READER == 1
  (void)isolink::read_spice_text(text, "fuzz.cir");
#elif ISOLINK_FUZZ_READER == 2
  (void)isolink::link::read_link_spec_text(text, "fuzz.yaml");
#elif ISOLINK_FUZZ_READER == 3
  (void)isolink::analysis::sweep::read_sweep_text(text, "fuzz.yaml");
#elif ISOLINK_FUZZ_READER == 4
  (void)isolink::link::read_parts_text(text, "fuzz.yaml");
#elif ISOLINK_FUZZ_READER == 5
  (void)isolink::eye::parse_rules(text, "fuzz.yaml");
#elif ISOLINK_FUZZ_READER == 6
  (void)isolink::eye::parse_differential_csv(text, "fuzz.csv");
#elif ISOLINK_FUZZ_READER == 7
  (void)isolink::traffic::build_drive(text);
#elif ISOLINK_FUZZ_READER == 8
  // The binary readers take a path (they read headers in place, not the whole file): the bytes
  // go to a file in the working directory; the format is told by its first bytes, .isf by
  // ":WFMP"/":WFMO" (the extension is .bin, whose own readers are told by their magic too).
  const char* path = "fuzz_scope_input.bin";
  if (std::FILE* f = std::fopen(path, "wb")) {
    const size_t wrote = std::fwrite(data, 1, size, f);
    std::fclose(f);
    if (wrote == size) (void)isolink::eye::read_binary(path);
  }
#elif ISOLINK_FUZZ_READER == 9
  // .model: the netlist read, its circuit built (the diode checks its model's parameters), and
  // every nonlinear port evaluated and limited from -1 kV to 1 kV: a non-finite current, charge
  // or limited voltage from a model the element accepted is a finding (abort).
  auto netlist = isolink::read_spice_text(text, "fuzz.cir");
  if (!netlist) return 0;
  isolink::Circuit circuit;
  for (const auto& card : netlist->cards)
    if (!circuit.add(card).ok()) return 0;
  if (!circuit.finalize().ok()) return 0;
  for (const auto& e : circuit.elements())
    for (int k = 0; k < e->nonlinear_port_count(); ++k)
      for (double v : {-1e3, -100.0, -27.0, -5.0, -0.1, 0.0, 0.1, 0.6, 0.8, 2.0, 30.0, 1e3}) {
        const isolink::PortEval p = e->eval_port(k, v);
        bool limited = false;
        const double vl = e->limit_port(k, v, 0.5 * v, &limited);
        if (!std::isfinite(p.i) || !std::isfinite(p.g) || !std::isfinite(p.q) ||
            !std::isfinite(p.c) || !std::isfinite(vl) || !std::isfinite(e->port_start_voltage(k)))
          std::abort();
      }
#elif ISOLINK_FUZZ_READER == 10
  // The port count of a version 1 file comes from its name: the first byte picks one.
  const char* names[] = {"fuzz.s1p", "fuzz.s2p", "fuzz.s4p", "fuzz.s16p"};
  (void)isolink::read_touchstone_text(text, names[size > 0 ? data[0] % 4 : 0]);
#endif
  return 0;
}
