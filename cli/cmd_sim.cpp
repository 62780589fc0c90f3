// isolink sim NETLIST.cir --probe 'v(rxp,rxn)' [-o wave.csv]: plain transient of a SPICE netlist.
#include <cstdio>
#include <iostream>

#include <fmt/format.h>

#include "cli/commands.h"
#include "cli/simulate.h"

namespace isolink::cli {

namespace {
struct SimArgs {
  std::string netlist;
  std::vector<std::string> probes;
  std::string output;
  double step = 0;
  double tstop = 0, tmax = 0;
  std::string method;
  double reltol = 0;
  bool quiet = false;
};

int run_sim(const SimArgs& a) {
  StatusOr<Netlist> netlist = read_spice_file(a.netlist);
  if (!netlist) {
    std::cerr << netlist.status().message() << "\n";
    return 2;
  }
  SimulationRequest req;
  req.probes = a.probes;
  if (a.tstop > 0) req.tstop = a.tstop;
  if (a.tmax > 0) req.tmax = a.tmax;
  if (a.reltol > 0) req.reltol = a.reltol;
  if (a.method == "trap") req.method = IntegrationMethod::Trapezoidal;
  if (a.method == "gear") req.method = IntegrationMethod::Gear2;
  StatusOr<SimulationResult> r = simulate_netlist(*netlist, req);
  if (!r) {
    std::cerr << a.netlist << ": error: " << r.status().message() << "\n";
    return 2;
  }
  for (const auto& w : r->warnings) std::cerr << w << "\n";
  const Waveform out = a.step > 0 ? r->wave.resampled(a.step) : r->wave;
  if (a.output.empty() || a.output == "-") {
    std::printf("time");
    for (const auto& n : out.names) std::printf(",%s", n.c_str());
    std::printf("\n");
    for (size_t i = 0; i < out.samples(); ++i) {
      std::printf("%.12g", out.time[i]);
      for (const auto& c : out.columns) std::printf(",%.9g", c[i]);
      std::printf("\n");
    }
  } else if (Status s = write_waveform_csv(out, a.output); !s.ok()) {
    std::cerr << "isolink sim: error: " << s.message() << "\n";
    return 2;
  }
  if (!a.quiet)
    std::cerr << fmt::format(
        "isolink sim: {} nodes, {} unknowns; {} steps accepted, {} rejected, {} factorizations "
        "({} reused), {:.3f} s; {} rows{}\n",
        r->nodes, r->unknowns, r->stats.accepted, r->stats.rejected, r->stats.factorizations,
        r->stats.reuses, r->seconds, out.samples(),
        a.output.empty() || a.output == "-" ? "" : " -> " + a.output);
  return 0;
}
}  // namespace

void add_sim_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<SimArgs>();
  CLI::App* cmd = app.add_subcommand("sim", "Transient simulation of a SPICE netlist (ngspice dialect)");
  cmd->add_option("netlist", args->netlist, "SPICE netlist (.cir)")->required();
  cmd->add_option("--probe,-p", args->probes,
                  "signal to record: v(node), v(node,node) or i(Vname|Lname); repeatable")
      ->required();
  cmd->add_option("-o,--output", args->output, "CSV file to write (default: stdout)");
  cmd->add_option("--step", args->step, "resample the output on a uniform grid of DT seconds")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--tstop", args->tstop, "end time in seconds (overrides .tran)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--tmax", args->tmax, "largest time step in seconds (overrides .tran)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--method", args->method, "integration method (overrides .options method)")
      ->check(CLI::IsMember({"trap", "gear"}));
  cmd->add_option("--reltol", args->reltol, "relative truncation-error tolerance (default 1e-3)")
      ->check(CLI::Range(1e-9, 0.1));
  cmd->add_flag("-q,--quiet", args->quiet, "no statistics on stderr");
  cmd->callback([args, exit_code] { *exit_code = run_sim(*args); });
}

}  // namespace isolink::cli
