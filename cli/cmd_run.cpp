// isolink run: a link spec simulated with its traffic, each receiver scored, and the report
// bundle (eye.png, wave.png, report.json, report.md, wave.csv) written to a folder.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/commands.h"
#include "base/atomic_file.h"
#include "analysis/link_run.h"
#include "reports/run_images.h"
#include "reports/run_report.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::cli {
using namespace isolink::analysis;  // run_link, LinkRun, run_waveforms
using namespace isolink::reports;   // report.json / report.md, images
namespace {

struct RunArgs {
  std::string spec;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  std::string direction;
  bool no_images = false;
  bool quiet = false;
};

int fail(const Status& s) {
  std::fprintf(stderr, "%s\n", s.message().c_str());
  return 2;
}

int run_run(const RunArgs& a) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) return fail(spec.status());
  if (a.direction == "down") spec->stimulus.directions = {link::Direction::kDown};
  if (a.direction == "up") spec->stimulus.directions = {link::Direction::kUp};
  if (a.direction == "both")
    spec->stimulus.directions = {link::Direction::kDown, link::Direction::kUp};
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());

  StatusOr<LinkRun> run = run_link(*spec, *parts);
  if (!run) return fail(run.status().with_context(a.spec));

  const std::string dir = a.out_dir.empty() ? "reports/out/" + spec->name : a.out_dir;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(Status::Error(fmt::format("{}: error: cannot create the folder: {}", dir,
                                                ec.message())));
  std::vector<std::string> images;
  if (!a.no_images) {
    if (Status s = render_run_images(*spec, *run, dir, &images); !s.ok()) return fail(s);
  }
  const Waveform wave = run_waveforms(*run, spec->sim.tstep);
  if (Status s = write_waveform_csv(wave, dir + "/wave.csv"); !s.ok()) return fail(s);
  if (Status s = write_file_atomic(dir + "/report.json", run_report_json(*spec, *run).dump(2) +
                                                             "\n");
      !s.ok())
    return fail(s);
  if (Status s = write_file_atomic(dir + "/report.md", run_report_markdown(*spec, *run, images));
      !s.ok())
    return fail(s);
  std::vector<std::string> warned;  // both directions share most warnings: print each once
  for (const DirectionRun& d : run->directions)
    for (const std::string& w : d.sim.warnings)
      if (std::find(warned.begin(), warned.end(), w) == warned.end()) {
        warned.push_back(w);
        std::fprintf(stderr, "%s\n", w.c_str());
      }
  if (!a.quiet) {
    std::fputs(run_summary_text(*spec, *run).c_str(), stdout);
    std::printf("report: %s/report.md\n", dir.c_str());
  }
  return run->pass ? 0 : 1;
}

}  // namespace

void add_run_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Simulate a link spec with its traffic, score each receiver and write the report "
             "(eye.png, wave.png, report.json, report.md, wave.csv)");
  cmd->add_option("spec", args->spec, "Link spec (YAML), e.g. netlists/examples/xfmr_12m.yaml")
      ->required();
  cmd->add_option("-o,--output", args->out_dir, "Report folder (default reports/out/<name>)");
  cmd->add_option("--parts", args->part_dirs, "Extra part-library folder (repeatable)");
  cmd->add_option("--direction", args->direction, "Override the spec: down | up | both")
      ->check(CLI::IsMember({"down", "up", "both"}));
  cmd->add_flag("--no-images", args->no_images, "Skip eye.png and wave.png");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  cmd->callback([args, exit_code] { *exit_code = run_run(*args); });
}

}  // namespace isolink::cli
