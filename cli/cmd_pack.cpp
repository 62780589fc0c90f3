// isolink pack: a pack spec (a chain of hops, optionally a ring) simulated hop by hop, each
// distinct circuit once, with the worst case over all traffic beside the spec's (unless
// --no-worst), and the pack report (report.md, report.json, pack.png, hop_NN/) written.
// `isolink run` hands pack specs here too.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "analysis/pack.h"
#include "analysis/pack_spec.h"
#include "base/progress.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/parts.h"
#include "reports/pack_report.h"

namespace isolink::cli {

int run_pack_command(const PackArgs& a) {
  auto fail = [](const Status& s) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 2;
  };
  if (a.jobs < 0)
    return fail(
        Status::Error(fmt::format("error: option -j = {}: must be >= 0 (0: all cores)", a.jobs)));
  StatusOr<analysis::PackSpec> pack = analysis::read_pack_spec_file(a.spec);
  if (!pack) return fail(pack.status());
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());
  analysis::PackOptions opt;
  opt.jobs = a.jobs;
  if (!a.no_worst) opt.worst = analysis::WorstOptions{};
  // Progress on stderr while it runs, when it is a terminal (base/progress.h).
  ProgressLine line({.label = "isolink pack", .enabled = !a.quiet});
  opt.on_job_done = [&line, worst = !a.no_worst](size_t done, size_t total) {
    line.show_fraction(fmt::format("{} of {} {}", done, total,
                                   worst ? "simulations and worst cases" : "simulations"),
                       static_cast<double>(done) / static_cast<double>(total));
  };
  StatusOr<analysis::PackResult> r = analysis::run_pack(*pack, *parts, opt);
  line.finish();
  if (!r) return fail(r.status().with_context(a.spec));

  const std::string dir = a.out_dir.empty() ? "reports/out/" + pack->name : a.out_dir;
  std::vector<std::string> files;
  if (Status s = reports::write_pack_bundle(*pack, *r, dir, a.no_images, &files); !s.ok())
    return fail(s);
  std::vector<std::string> warned;  // hops share most warnings: print each once
  for (const analysis::HopResult& h : r->hops)
    for (const analysis::DirectionRun& d : h.run.directions)
      for (const std::string& w : d.sim.warnings)
        if (std::find(warned.begin(), warned.end(), w) == warned.end()) {
          warned.push_back(w);
          std::fprintf(stderr, "%s\n", w.c_str());
        }
  if (!a.quiet) {
    std::fputs(reports::pack_summary_text(*pack, *r).c_str(), stdout);
    std::printf("report: %s/report.md\n", dir.c_str());
  }
  return r->pass && r->worst_pass ? 0 : 1;
}

void add_pack_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<PackArgs>();
  CLI::App* cmd = app.add_subcommand(
      "pack",
      "Simulate every hop of a pack spec (each distinct circuit once), check the ring's "
      "cable breaks and command timing, write the pack report (report.md, report.json, "
      "pack.png, hop_NN/)");
  cmd->add_option("spec", args->spec, "Pack spec (YAML), e.g. netlists/examples/pack/pack_16.yaml")
      ->required();
  cmd->add_option("-o,--output", args->out_dir, "Report folder (default reports/out/<name>)");
  cmd->add_option("-j,--jobs", args->jobs, "Threads across distinct hops (0: all cores)");
  add_parts_option(*cmd, &args->part_dirs);
  cmd->add_flag("--no-worst", args->no_worst,
                "Skip the worst case over all traffic (its report columns and verdict)");
  cmd->add_flag("--no-images", args->no_images, "Skip pack.png and the per-hop images");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  cmd->callback([args, exit_code] { *exit_code = run_pack_command(*args); });
}

}  // namespace isolink::cli
