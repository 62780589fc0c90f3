// isolink sim NETLIST.cir --probe 'v(rxp,rxn)' [-o wave.csv] [--engine auto|lti|port|transient]:
// the response of a SPICE netlist, by the LTI engine where it is the cheaper engine, else the
// transient (see analysis/simulate.h).
#include <fmt/format.h>

#include <cstdio>
#include <iostream>
#include <optional>
#include <thread>

#include "analysis/simulate.h"
#include "base/progress.h"
#include "base/si_number.h"
#include "cli/commands.h"
#include "cli/common_options.h"

namespace isolink::cli {
using namespace isolink::analysis;  // simulate_netlist

namespace {
// The most rows --step may ask for (about 300 MB of CSV with one probe).
constexpr size_t kMaxResampledRows = 10'000'000;

struct SimArgs {
  std::string netlist;
  std::vector<std::string> probes;
  std::string output;
  std::string step, tstop, tmax;  // SPICE numbers: 10n, 1u
  std::string method;
  Engine engine = Engine::Auto;
  double reltol = 0;
  bool quiet = false;
};

// A positive SPICE number from an option ("10n"), or an error naming the option.
std::optional<double> si_option(const char* flag, const std::string& text, bool* bad) {
  if (text.empty()) return std::nullopt;
  double v = 0;
  if (!parse_si_number(text, v) || !(v > 0)) {
    std::cerr << "isolink sim: error: " << flag << " expects a positive time such as 10n, got '"
              << text << "'\n";
    *bad = true;
    return std::nullopt;
  }
  return v;
}

// The run's statistics on stderr: the engine, why auto took it when it fell back, how long each
// part took and the accuracy it promises (analysis::engine_accuracy).
void print_sim_stats(const SimulationResult& r, size_t rows, const std::string& target) {
  const std::string grid =
      r.grid.coarse_step > 0
          ? fmt::format("{} rows at most {:g} s apart, down to {:g} s where the response bends",
                        rows, r.grid.coarse_step, r.grid.step)
          : fmt::format("{} rows every {:g} s", rows, r.grid.step);
  if (r.engine == Engine::Lti && r.lti.method == "reduced model")
    std::cerr << fmt::format(
        "isolink sim: LTI engine, reduced model: {} nodes, {} unknowns; order {} ({} poles, {} "
        "expansion points), transfer within {:.1e} of the peak at {} check frequencies ({} "
        "factorizations); {} corners; {:.3f} s; {}{}\n",
        r.nodes, r.unknowns, r.lti.model.order, r.lti.model.poles, r.lti.model.expansion_points,
        r.lti.model.error, r.lti.model.check_points, r.lti.factorizations, r.grid.corners,
        r.seconds, grid, target);
  else if (r.engine == Engine::Lti)
    std::cerr << fmt::format(
        "isolink sim: LTI engine, march: {} nodes, {} unknowns; responses to {:g} s in {} steps "
        "({} rejected, {} factorizations){}; {} corners; {:.3f} s; {}{}\n",
        r.nodes, r.unknowns, r.lti.settled_at, r.lti.steps, r.lti.rejected, r.lti.factorizations,
        r.lti.settled ? ", settled" : "", r.grid.corners, r.seconds, grid, target);
  if (r.engine == Engine::Lti && !r.lti.note.empty())
    std::cerr << fmt::format(
        "isolink sim: the march ran because the reduced model did not pass its check ({}); the "
        "model took {:.3f} s, the march {:.3f} s\n",
        r.lti.note, r.lti.model_seconds, r.lti.march_seconds);
  if (r.engine == Engine::PortModel)
    std::cerr << fmt::format(
        "isolink sim: port model engine (the circuit has diodes; the full transient is its "
        "fallback): {} nodes, {} unknowns; {} ports, {} modes (order {}, "
        "{} expansion points), transfer within {:.1e} of the peak at {} check frequencies, DC "
        "state within {:.1e} V; model {:.3f} s; {} steps accepted, {} rejected, {} Newton "
        "iterations on the ports; {:.3f} s; {} rows{}\n",
        r.nodes, r.unknowns, r.port.ports, r.port.modes, r.port.model.order,
        r.port.model.expansion_points, r.port.model.error, r.port.model.check_points,
        r.port.dc_mismatch, r.port.model_seconds, r.port.accepted, r.port.rejected,
        r.port.newton_iterations, r.seconds, rows, target);
  if (r.engine == Engine::Transient && r.engine_note.rfind("the port model", 0) == 0)
    std::cerr << fmt::format(
        "isolink sim: transient engine, because {} (the attempt took {:.3f} s)\n", r.engine_note,
        r.lti_attempt_seconds);
  else if (r.engine == Engine::Transient && !r.engine_note.empty())
    std::cerr << fmt::format(
        "isolink sim: transient engine, not LTI: {} (the LTI attempt took {:.3f} s)\n",
        r.engine_note, r.lti_attempt_seconds);
  if (r.engine == Engine::Transient)
    std::cerr << fmt::format(
        "isolink sim: {} nodes, {} unknowns; {} steps accepted, {} rejected, {} factorizations "
        "({} reused), {:.3f} s; {} rows{}\n",
        r.nodes, r.unknowns, r.stats.accepted, r.stats.rejected, r.stats.factorizations,
        r.stats.reuses, r.seconds, rows, target);
  std::cerr << "isolink sim: accuracy: " << engine_accuracy(r) << "\n";
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
  req.engine = a.engine;
  req.lti_threads = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  if (step) req.grid_step = *step;
  if (a.reltol > 0) req.reltol = a.reltol;
  if (a.method == "trap") req.method = IntegrationMethod::Trapezoidal;
  if (a.method == "gear") req.method = IntegrationMethod::Gear2;
  // Progress on stderr while the engine runs, when it is a terminal (base/progress.h).
  ProgressLine line({.label = "isolink sim", .enabled = !a.quiet});
  req.progress = [&line](const char* phase, double f) { line.show_fraction(phase, f); };
  StatusOr<SimulationResult> r = simulate_netlist(*netlist, req);
  line.finish();
  if (!r) {
    const std::string& m = r.status().message();  // diagnostics already say file:line:col
    std::cerr << (m.find(": error: ") == std::string::npos ? "isolink sim: error: " : "") << m
              << "\n";
    return 2;
  }
  for (const auto& w : r->warnings) std::cerr << w << "\n";
  if (step && !r->wave.time.empty()) {
    // Refused before allocating: 1e-14 over 5 us would be 5e8 rows (bad_alloc), 1e-30 overflows.
    const double span = r->wave.time.back() - r->wave.time.front();
    const double rows = span / *step + 1;
    if (!(rows <= static_cast<double>(kMaxResampledRows))) {
      std::cerr << fmt::format(
          "isolink sim: error: --step {} over the {:.6g} s run asks for {:.3g} rows; the limit is "
          "{} rows (use a larger --step, or no --step for the solver's own time points)\n",
          a.step, span, rows, kMaxResampledRows);
      return 2;
    }
  }
  // The LTI engine already wrote its rows on the --step grid.
  const Waveform out = step && r->engine != Engine::Lti ? r->wave.resampled(*step) : r->wave;
  if (Status s = write_waveform_csv(out, a.output.empty() ? "-" : a.output); !s.ok()) {
    const std::string& m = s.message();
    std::cerr << (m.find(": error: ") == std::string::npos ? "isolink sim: error: " : "") << m
              << "\n";
    return 2;
  }
  const std::string target = a.output.empty() || a.output == "-" ? "" : " -> " + a.output;
  if (!a.quiet) print_sim_stats(*r, out.samples(), target);
  return 0;
}
}  // namespace

void add_sim_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<SimArgs>();
  CLI::App* cmd =
      app.add_subcommand("sim", "Simulate a SPICE netlist (ngspice dialect): LTI or transient");
  cmd->add_option("netlist", args->netlist, "SPICE netlist (.cir)")->required();
  cmd->add_option("--probe,-p", args->probes,
                  "signal to record: v(node), v(node,node) or i(Vname|Lname); repeatable")
      ->required();
  cmd->add_option("-o,--output", args->output, "CSV file to write (default: stdout)");
  cmd->add_option("--step", args->step,
                  "output on a uniform grid of DT seconds (10n); default: LTI picks a grid where "
                  "linear interpolation is within 1 mV, the transient writes its steps");
  add_engine_option(*cmd, &args->engine);
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
