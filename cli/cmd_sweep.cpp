// isolink sweep: a link spec (or a whole pack: a pack spec base, keys hops.K.key) over a grid of
// key values and / or Monte Carlo tolerances (link specs only), every point
// simulated and checked, into results.csv, summary.json and plots (analysis/sweep_spec.h,
// analysis/sweep_run.h; across machines with mpirun: analysis/sweep_mpi.h).
// Exit status: 0 every point passes, 1 some point fails or could not be simulated, 2 bad input.
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "analysis/sweep_run.h"
#include "analysis/sweep_spec.h"
#include "base/csv.h"
#include "base/file_io.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/parts.h"
#include "reports/plot.h"
#include "reports/sweep_report.h"
#ifdef ISOLINK_HAVE_MPI
#include "analysis/sweep_mpi.h"
#endif

namespace isolink::cli {
using namespace isolink::analysis;  // sweep::
namespace {

struct SweepArgs {
  std::string file;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  int jobs = 0;
  bool resume = false;
  bool keep_waves = false;
  bool no_plots = false;
  bool quiet = false;
  bool list = false;
  Engine engine = Engine::Auto;
  bool simulate = false;
};

int fail(const Status& s) {
  std::fprintf(stderr, "%s\n", s.message().c_str());
  return 2;
}

int list_points(const sweep::SweepSpec& s) {
  std::vector<std::string> header{"point"};
  for (const std::string& c : s.point_columns()) header.push_back(c);
  header.push_back("spec");
  std::fputs(csv_row(header).c_str(), stdout);
  for (size_t i = 0; i < s.size(); ++i) {
    const sweep::PointOutcome p = sweep::make_point(s, i);
    std::vector<std::string> row{fmt::format("{}", i)};
    for (const std::string& c : p.point.cells) row.push_back(c);
    const std::string st = p.status.ok() ? "ok" : p.status.message();
    row.push_back(st.substr(0, st.find('\n')));
    std::fputs(csv_row(row).c_str(), stdout);
  }
  return 0;
}

int run_sweep_command(const SweepArgs& a) {
  bool mpi = false;
  int rank = 0, ranks = 1;
#ifdef ISOLINK_HAVE_MPI
  sweep::MpiWorld world;
  if (sweep::mpi_launched()) {
    world = sweep::mpi_start();
    mpi = world.size > 1;
    rank = world.rank;
    ranks = world.size;
  }
  // Every rank leaves through here (MPI_Finalize once the sweep is over or could not start).
  struct Finalize {
    bool on;
    ~Finalize() {
      if (on) sweep::mpi_stop();
    }
  } finalize{sweep::mpi_launched()};
#else
  if (const char* n = std::getenv("OMPI_COMM_WORLD_SIZE"); n && std::atoi(n) > 1) {
    if (std::getenv("OMPI_COMM_WORLD_RANK") && std::atoi(std::getenv("OMPI_COMM_WORLD_RANK")) == 0)
      std::fprintf(stderr,
                   "isolink sweep: this isolink was built without MPI (ISOLINK_MPI=OFF): "
                   "run it without mpirun, it uses every core by itself\n");
    return 2;
  }
#endif
  // Only rank 0 speaks; the other ranks read the same files and fail the same way.
  auto report = [rank](const Status& s) { return rank == 0 ? fail(s) : 2; };

  StatusOr<sweep::SweepSpec> spec = sweep::read_sweep_file(a.file);
  if (!spec) return report(spec.status());
  if (a.list) return rank == 0 ? list_points(*spec) : 0;
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return report(parts.status());

  sweep::SweepOptions opt;
  opt.out_dir = a.out_dir.empty() ? "reports/out/" + safe_path_component(spec->name) : a.out_dir;
  opt.jobs = a.jobs;
  opt.resume = a.resume;
  opt.keep_waves = a.keep_waves;
  opt.quiet = a.quiet;
  opt.point.run.engine = a.engine;
  opt.point.simulate = a.simulate;
  if (!a.quiet && rank == 0) {
    std::fprintf(stderr, "sweep: %s: %zu points (%zu grid point%s%s)%s -> %s\n", spec->path.c_str(),
                 spec->size(), spec->grid_size(), spec->grid_size() == 1 ? "" : "s",
                 spec->mc.samples > 0
                     ? fmt::format(" x {} Monte Carlo samples", spec->mc.samples).c_str()
                     : "",
                 mpi ? fmt::format(", {} MPI ranks", ranks).c_str() : "", opt.out_dir.c_str());
  }
  // The charts' image plug-in (OpenImageIO and its 261 libraries: 0.4 s of dynamic linking) is
  // loaded on its own thread while the points run, not after them. It starts once the sweep's
  // thread pool is up (on_pool_ready: the pool's own start loads libraries, and would wait for
  // it), at normal priority: at the lowest it got no core until the points were done and the
  // charts waited for it (64 points on 2 cores: 4.9 s at nice 19, 4.75 s at 0).
  std::jthread plugin_loader;  // joined when the command returns
  const bool plots = !a.no_plots;
  if (plots && rank == 0)
    opt.on_pool_ready = [&plugin_loader] {
      plugin_loader = std::jthread([] { reports::load_image_plugin(); });
    };
  StatusOr<sweep::SweepOutcome> out = Status::Error("not run");
#ifdef ISOLINK_HAVE_MPI
  if (mpi)
    out = sweep::run_sweep_mpi(*spec, *parts, opt, world);
  else
#endif
    out = sweep::run_sweep(*spec, *parts, opt);
  if (!out) return report(out.status());
  if (rank != 0) return 0;
  if (Status st = reports::write_sweep_report(*spec, &*out, opt.out_dir, plots); !st.ok())
    return fail(st);
  if (!a.quiet) {
    std::printf(
        "%zu points: %zu pass, %zu fail, %zu error%s\n", out->points, out->pass, out->fail,
        out->error,
        out->skipped ? fmt::format(" ({} from the earlier run)", out->skipped).c_str() : "");
    // Points off the fast path (analysis/README.md): how many and the first one's reason.
    const nlohmann::ordered_json paths = reports::sweep_path_counts(out->results);
    if (paths["simulated"].get<size_t>() > 0)
      std::printf("%zu simulated, not synthesized from edge responses (point %zu: %s)\n",
                  paths["simulated"].get<size_t>(), paths["first_simulated"]["point"].get<size_t>(),
                  paths["first_simulated"]["path"].get<std::string>().c_str());
    for (const std::string& f : out->files)
      std::printf("  %s/%s\n", opt.out_dir.c_str(), f.c_str());
  }
  return out->fail + out->error == 0 ? 0 : 1;
}

}  // namespace

void add_sweep_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep",
      "Run a link spec (or a pack spec, keys hops.K.key / hops.*.key) over a grid "
      "of values and / or Monte Carlo tolerances: results.csv, summary.json, "
      "margin / heatmap / histogram PNGs");
  cmd->add_option("sweep", args->file,
                  "Sweep file (YAML), e.g. netlists/examples/"
                  "sweep_cap_length.yaml")
      ->required();
  cmd->add_option("-o,--output", args->out_dir, "Output folder (default reports/out/<name>)");
  cmd->add_option("-j,--jobs", args->jobs, "Points run at once (default: all cores)")
      ->check(CLI::Range(1, 4096));
  add_parts_option(*cmd, &args->part_dirs);
  add_engine_option(*cmd, &args->engine);
  cmd->add_flag("--simulate", args->simulate,
                "Simulate every point with the engine instead of superposing each direction's "
                "edge response (the fast path; results.csv's path column)");
  cmd->add_flag("--resume", args->resume, "Skip the points already in DIR/results.csv");
  cmd->add_flag("--keep-waves", args->keep_waves,
                "Write every point's waveforms to DIR/waves/point_NNNNN.csv");
  cmd->add_flag("--no-plots", args->no_plots, "Skip the PNG charts");
  cmd->add_flag("--list", args->list,
                "Print the points (CSV) and whether each spec reads; run "
                "nothing");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress or summary, only errors");
  cmd->callback([args, exit_code] { *exit_code = run_sweep_command(*args); });
}

}  // namespace isolink::cli
