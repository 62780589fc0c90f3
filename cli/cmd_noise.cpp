// isolink noise: common-mode noise immunity of a link spec over frequency (analysis/noise.h),
// written as noise.png, report.md and report.json (the run's report with a noise section).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "analysis/noise.h"
#include "base/file_io.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/cards.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "reports/noise_png.h"
#include "reports/noise_report.h"
#include "reports/run_report.h"

namespace isolink::cli {
namespace {

struct NoiseArgs {
  std::string spec;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  bool json = false;
  bool no_images = false;
  std::string spice;
};

int fail(const Status& s) {
  std::fprintf(stderr, "%s\n", s.message().c_str());
  return 2;
}

int run_noise(const NoiseArgs& a) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) return fail(spec.status());
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());
  if (!a.spice.empty()) {  // the noise circuit of the first direction, for ngspice
    StatusOr<analysis::NoiseCircuit> c =
        analysis::build_noise_circuit(*spec, *parts, spec->stimulus.directions.front());
    if (!c) return fail(c.status().with_context(a.spec));
    if (Status s = write_file_atomic(a.spice, analysis::noise_spice(*c, spec->noise)); !s.ok())
      return fail(s);
  }
  // The link's own waveform per direction sets how much noise the receiver can take.
  StatusOr<analysis::NoiseRun> nr = analysis::run_noise(*spec, *parts);
  if (!nr) return fail(nr.status().with_context(a.spec));
  const analysis::LinkRun* run = &nr->run;
  const analysis::NoiseResult* noise = &nr->noise;

  const std::string dir = a.out_dir.empty() ? "reports/out/" + spec->name : a.out_dir;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    return fail(
        Status::Error(fmt::format("{}: error: cannot create the folder: {}", dir, ec.message())));
  std::vector<std::string> images;
  if (!a.no_images) {
    if (Status s = reports::write_noise_png(*noise, spec->name, dir + "/noise.png"); !s.ok())
      return fail(s);
    images.push_back("noise.png");
  }
  nlohmann::ordered_json j = reports::run_report_json(*spec, *run);
  j["noise"] = reports::noise_json(*noise);
  if (Status s = write_file_atomic(dir + "/report.json", j.dump(2) + "\n"); !s.ok()) return fail(s);
  std::string md =
      reports::run_report_markdown(*spec, *run, {}) + "\n" + reports::noise_markdown(*noise);
  for (const std::string& i : images) md += fmt::format("![{}]({})\n", i, i);
  if (Status s = write_file_atomic(dir + "/report.md", md); !s.ok()) return fail(s);

  if (a.json) {
    std::puts(reports::noise_json(*noise).dump(2).c_str());
  } else {
    const char* unit = noise->spec.level_unit();
    for (const analysis::NoiseDirection& d : noise->directions) {
      const bool stat = noise->spec.verdict_on == "statistical";
      std::printf(
          "%s  %s: immunity %s at %s worst corner%s, %s at %s for 99 %% of boards%s (test level "
          "%s)\n",
          d.pass ? "pass" : "FAIL", d.description.c_str(),
          link::format_si(d.immunity_min, unit).c_str(),
          link::format_si(d.immunity_min_freq, "Hz").c_str(), stat ? "" : " (verdict)",
          link::format_si(d.statistical.immunity_min, unit).c_str(),
          link::format_si(d.statistical.immunity_min_freq, "Hz").c_str(), stat ? " (verdict)" : "",
          link::format_si(noise->spec.level, unit).c_str());
      if (!d.contributors.empty())
        std::printf("      top contributor at %s: %s %.0f %%\n",
                    link::format_si(d.immunity_min_freq, "Hz").c_str(),
                    d.contributors[0].element.c_str(), d.contributors[0].share * 100);
    }
    std::printf("report: %s/report.md\n", dir.c_str());
  }
  return noise->pass ? 0 : 1;
}

}  // namespace

void add_noise_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<NoiseArgs>();
  CLI::App* cmd = app.add_subcommand(
      "noise",
      "Common-mode noise immunity of a link spec (BCI, ground shift) over frequency: "
      "noise.png, report.md, report.json; exit 1 when the test level fails");
  cmd->add_option("spec", args->spec, "Link spec (YAML) with an optional noise: block")->required();
  cmd->add_option("-o,--output", args->out_dir, "Report folder (default reports/out/<name>)");
  add_parts_option(*cmd, &args->part_dirs);
  cmd->add_flag("--json", args->json, "Print the noise result as JSON on stdout");
  cmd->add_flag("--no-images", args->no_images, "Skip noise.png");
  cmd->add_option("--export-spice", args->spice,
                  "Also write the first direction's noise circuit with its AC source (ngspice)");
  cmd->callback([args, exit_code] { *exit_code = run_noise(*args); });
}

}  // namespace isolink::cli
