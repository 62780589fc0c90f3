#include "analysis/simulate.h"

#include <chrono>

#include "solver/circuit.h"

namespace isolink::analysis {

namespace {
StatusOr<SimulationResult> simulate(const Netlist& netlist, const SimulationRequest& req,
                                    SimulationResult& result) {
  TransientOptions opt;
  if (netlist.tran) {
    opt.tstep = netlist.tran->tstep;
    opt.tstop = netlist.tran->tstop;
    opt.tstart = netlist.tran->tstart;
    opt.tmax = netlist.tran->tmax;
    opt.uic = netlist.tran->uic;
  }
  for (const auto& o : netlist.options) {
    bool known = true;
    if (Status s = opt.set_option(o.key, o.value, &known); !s.ok()) return s;
    if (!known)
      result.warnings.push_back(format_diagnostic(
          o.loc, "warning", "option '" + o.key + "' is not used by isolink; ignored"));
  }
  if (req.tstop) opt.tstop = *req.tstop;
  if (req.tstep) opt.tstep = *req.tstep;
  if (req.tmax) opt.tmax = *req.tmax;
  if (req.method) opt.method = *req.method;
  if (req.reltol) opt.reltol = *req.reltol;
  if (!netlist.tran && !req.tstop)
    return Status::Error("no .tran card in the netlist and no --tstop given: nothing to simulate");
  if (opt.tstep <= 0 && opt.tstop > 0) opt.tstep = opt.tstop / 1000;
  if (Status s = opt.validate(); !s.ok()) return s;

  Circuit circuit;
  for (const Card& card : netlist.cards)
    if (Status s = circuit.add(card); !s.ok()) return s;
  if (Status s = circuit.finalize(); !s.ok()) return s;
  for (const auto& w : circuit.warnings()) result.warnings.push_back(w);
  for (const InitialVoltage& ic : netlist.initial_voltages) {
    const int node = circuit.find_node(ic.node);
    if (node <= 0)
      return error_at(ic.loc,
                      node == 0 ? "'.ic' on the ground node"
                                : "'.ic' names node '" + ic.node + "', which no element connects");
    opt.node_ic.emplace_back(node, ic.value);
  }

  std::vector<Probe> probes;
  for (const auto& text : req.probes) {
    StatusOr<Probe> p = parse_probe(circuit, text);
    if (!p) return p.status();
    probes.push_back(*p);
  }
  if (probes.empty())
    return Status::Error("no --probe given: say what to record, e.g. --probe 'v(rxp,rxn)'");

  const auto start = std::chrono::steady_clock::now();
  StatusOr<Waveform> wave = run_transient(circuit, opt, probes, &result.stats);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!wave) return wave.status();
  result.wave = std::move(*wave);
  result.nodes = circuit.node_count() - 1;
  result.unknowns = circuit.unknown_count();
  result.elements = static_cast<int>(circuit.elements().size());
  return result;
}
}  // namespace

StatusOr<SimulationResult> simulate_netlist(const Netlist& netlist, const SimulationRequest& req) {
  SimulationResult result;
  result.warnings = netlist.warnings;
  StatusOr<SimulationResult> r = simulate(netlist, req, result);
  if (r.ok() || result.warnings.empty()) return r;
  // Warnings first: a skipped card or a tied node may be why the run failed.
  std::string text;
  for (const std::string& w : result.warnings) text += w + "\n";
  return Status::Error(text + r.status().message());
}

}  // namespace isolink::analysis
