// isolink sim NETLIST.cir --probe 'v(rxp,rxn)' [-o wave.csv]: plain transient of a SPICE netlist.
#include <cstdio>
#include <iostream>
#include <optional>

#include <fmt/format.h>

#include "cli/commands.h"
#include "analysis/simulate.h"
#include "netlists/lexer.h"

namespace isolink::cli {
using namespace isolink::analysis;  // simulate_netlist

namespace {
struct SimArgs {
  std::string netlist;
  std::vector<std::string> probes;
  std::string output;
  std::string step, tstop, tmax;  // SPICE numbers: 10n, 1u
  std::string method;
  double reltol = 0;
  bool quiet = false;
};

// A positive SPICE number from an option ("10n"), or an error naming the option.
std::optional<double> si_option(const char* flag, const std::string& text, bool* bad) {
  if (text.empty()) return std::nullopt;
  double v = 0;
  if (!spice::parse_number(text, v) || !(v > 0)) {
    std::cerr << "isolink sim: error: " << flag << " expects a positive time such as 10n, got '"
              << text << "'\n";
    *bad = true;
    return std::nullopt;
  }
  return v;
}

int run_sim(const SimArgs& a) {
  bool bad = false;
  std::optional<double> step = si_option("--step", a.step, &bad);
  std::optional<double> tstop = si_option("--tstop", a.tstop, &bad);
  std::optional<double> tmax = si_option("--tmax", a.tmax, &bad);
  if (bad) return 2;
  StatusOr<Netlist> netlist = read_spice_file(a.netlist);
  if (!netlist) {
    std::cerr << netlist.status().message() << "\n";
    return 2;
  }
  SimulationRequest req;
  req.probes = a.probes;
  req.tstop = tstop;
  req.tmax = tmax;
  if (a.reltol > 0) req.reltol = a.reltol;
  if (a.method == "trap") req.method = IntegrationMethod::Trapezoidal;
  if (a.method == "gear") req.method = IntegrationMethod::Gear2;
  StatusOr<SimulationResult> r = simulate_netlist(*netlist, req);
  if (!r) {
    const std::string& m = r.status().message();  // diagnostics already say file:line:col
    std::cerr << (m.find(": error: ") == std::string::npos ? "isolink sim: error: " : "") << m << "\n";
    return 2;
  }
  for (const auto& w : r->warnings) std::cerr << w << "\n";
  const Waveform out = step ? r->wave.resampled(*step) : r->wave;
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
  cmd->add_option("--step", args->step, "resample the output on a uniform grid of DT seconds (10n)");
  cmd->add_option("--tstop", args->tstop, "end time in seconds (overrides .tran)");
  cmd->add_option("--tmax", args->tmax, "largest time step in seconds (overrides .tran)");
  cmd->add_option("--method", args->method, "integration method (overrides .options method)")
      ->check(CLI::IsMember({"trap", "gear"}));
  cmd->add_option("--reltol", args->reltol, "relative truncation-error tolerance (default 1e-3)")
      ->check(CLI::Range(1e-9, 0.1));
  cmd->add_flag("-q,--quiet", args->quiet, "no statistics on stderr");
  cmd->callback([args, exit_code] { *exit_code = run_sim(*args); });
}

}  // namespace isolink::cli
