// Netlist -> Circuit -> transient waveform: the path shared by `isolink sim` and `isolink run`.
//
//   SimulationRequest req{.probes = {"v(rxp,rxn)"}};
//   StatusOr<SimulationResult> r = simulate_netlist(netlist, req);
//   for (auto& w : r->warnings) print(w);
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "netlists/spice_reader.h"
#include "solver/transient.h"
#include "base/waveform.h"

namespace isolink::analysis {

struct SimulationRequest {
  std::vector<std::string> probes;            // v(a), v(a,b), i(name)
  std::optional<double> tstop, tstep, tmax;   // override the netlist's .tran
  std::optional<IntegrationMethod> method;    // override .options method
  std::optional<double> reltol;               // override .options reltol
};

struct SimulationResult {
  Waveform wave;
  TransientStats stats;
  std::vector<std::string> warnings;  // formatted, for stderr
  int nodes = 0, unknowns = 0, elements = 0;
  double seconds = 0.0;  // wall time of the transient
};

StatusOr<SimulationResult> simulate_netlist(const Netlist& netlist, const SimulationRequest& req);

}  // namespace isolink::analysis
