// isolink worst: the worst case over all legal traffic (analysis/worst.h), printed, and with -o
// written as worst.json, worst.md and one worst_<direction>_<metric>.png per worst waveform.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "analysis/worst.h"
#include "base/file_io.h"
#include "base/progress.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "reports/worst_png.h"
#include "reports/worst_report.h"

namespace isolink::cli {
namespace {

struct WorstArgs {
  std::string spec;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  std::optional<std::vector<link::Direction>> directions;  // --direction
  std::string edge_engine = "auto";
  bool json = false;
  bool no_images = false;
  bool quiet = false;
};

int fail(const Status& s) {
  std::fprintf(stderr, "%s\n", s.message().c_str());
  return 2;
}

int run_worst(const WorstArgs& a) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) return fail(spec.status());
  if (a.directions) spec->stimulus.directions = *a.directions;
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());
  // Progress on stderr while it runs, when it is a terminal (base/progress.h).
  ProgressLine line({.label = "isolink worst", .enabled = !a.quiet});
  analysis::WorstOptions opt;
  opt.progress = [&line](const std::string& what, double f) { line.show_fraction(what, f); };
  if (a.edge_engine == "transient") opt.edge_engine = analysis::WorstOptions::EdgeEngine::Transient;
  StatusOr<analysis::WorstResult> w = analysis::worst_case(*spec, *parts, opt);
  line.finish();
  if (!w) return fail(w.status().with_context(a.spec));
  const std::string json = reports::worst_json(*w).dump(2) + "\n";
  if (!a.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.out_dir, ec);
    if (ec)
      return fail(Status::Error(
          fmt::format("{}: error: cannot create the folder: {}", a.out_dir, ec.message())));
    if (Status s = write_file_atomic(a.out_dir + "/worst.json", json); !s.ok()) return fail(s);
    std::string md = fmt::format("# Worst case over all traffic: {}\n\n{}", spec->name,
                                 reports::worst_markdown(*w));
    if (!a.no_images) {
      std::vector<std::string> images;
      if (Status s = reports::render_worst_pngs(*w, spec->name, {}, a.out_dir, &images); !s.ok())
        return fail(s);
      for (const std::string& f : images) md += fmt::format("![{}]({})\n\n", f, f);
    }
    if (Status s = write_file_atomic(a.out_dir + "/worst.md", md); !s.ok()) return fail(s);
  }
  if (a.json) {
    std::fputs(json.c_str(), stdout);
  } else if (!a.quiet) {
    std::fputs(reports::worst_summary_text(*w).c_str(), stdout);
    for (const analysis::DirectionWorst& d : w->directions)
      for (const analysis::WorstMetric& m : d.metrics)
        std::printf("  reproduce %s %s: %s\n", link::direction_name(d.direction), m.name.c_str(),
                    reports::reproduce_stimulus(m, d.direction).c_str());
  }
  return w->pass ? 0 : 1;
}

}  // namespace

void add_worst_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<WorstArgs>();
  CLI::App* cmd = app.add_subcommand(
      "worst",
      "The worst case over all legal traffic: lowest VSTART / VEND, narrowest and widest "
      "pulse, slowest edge, the traffic that causes each and a stimulus that replays it");
  cmd->add_option("spec", args->spec, "Link spec (YAML)")->required();
  cmd->add_option("-o,--output", args->out_dir,
                  "Write worst.json, worst.md and the images to this folder");
  add_parts_option(*cmd, &args->part_dirs);
  add_directions_option(*cmd, &args->directions);
  cmd->add_option("--edge-engine", args->edge_engine,
                  "Edge response: auto (the reduced model, checked against the exact AC solution; "
                  "the transient when it does not pass) | transient")
      ->check(CLI::IsMember({"auto", "transient"}));
  cmd->add_flag("--json", args->json, "Print the JSON instead of the summary");
  cmd->add_flag("--no-images", args->no_images,
                "With -o: skip the worst_<dir>_<metric>.png images");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  cmd->callback([args, exit_code] { *exit_code = run_worst(*args); });
}

}  // namespace isolink::cli
