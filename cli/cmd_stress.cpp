// isolink stress: what breaks a daisy chain in the field (analysis/stress.h): module-ground
// steps and an inverter's wave during traffic, IEC 61000-4-2 contact discharges, hot-plugging a
// module and wire faults, simulated with the pins' clamps and the spec's TVS parts; report.md,
// report.json, report.html and stress.png, --export-spice each scenario's netlist. A pack file:
// each hop's wire faults and what the ring still reaches (analysis/pack_stress.h).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "analysis/pack_spec.h"
#include "analysis/pack_stress.h"
#include "analysis/stress.h"
#include "base/file_io.h"
#include "base/progress.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "config/yaml_reader.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/spice_writer.h"
#include "reports/html_report.h"
#include "reports/stress_png.h"
#include "reports/stress_report.h"

namespace isolink::cli {
namespace {

struct StressArgs {
  std::string spec;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  bool json = false;
  bool quiet = false;
  std::string only;  // comma-separated kinds
  std::string spice_dir;
  std::string direction = "both";
  int jobs = 1;
};

int fail(const Status& s) {
  std::fprintf(stderr, "%s\n", s.message().c_str());
  return 2;
}

// "--only cm_step,esd" -> its kinds, each checked before any run.
StatusOr<std::vector<std::string>> parse_only(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  std::stringstream in(text);
  std::string item;
  const std::vector<std::string>& kinds = link::stress_kinds();
  while (std::getline(in, item, ',')) {
    if (std::find(kinds.begin(), kinds.end(), item) == kinds.end())
      return Status::Error(fmt::format(
          "isolink stress: error: --only = '{}': '{}' is not a scenario kind (one of cm_step, "
          "cm_wave, esd, hot_plug, wire, comma-separated)",
          text, item));
    out.push_back(item);
  }
  return out;
}

// The run's options from the command line (checked before: direction, jobs, only).
analysis::StressOptions stress_options(const StressArgs& a, const std::vector<std::string>& only,
                                       ProgressLine& line) {
  analysis::StressOptions so;
  so.only = only;
  so.jobs = a.jobs;
  if (a.direction != "both")
    so.directions = {a.direction == "down" ? link::Direction::kDown : link::Direction::kUp};
  so.progress = [&line](const std::string& what, double f) { line.show_fraction(what, f); };
  return so;
}

// -o, or reports/out/NAME-stress.
std::string report_dir(const StressArgs& a, const std::string& name) {
  return a.out_dir.empty() ? "reports/out/" + safe_path_component(name) + "-stress" : a.out_dir;
}

// report.json and report.md into the bundle.
Status write_reports(const OutputBundle& bundle, const nlohmann::ordered_json& j,
                     const std::string& md) {
  if (Status s = write_file_atomic(bundle.path("report.json"), j.dump(2) + "\n"); !s.ok()) return s;
  return write_file_atomic(bundle.path("report.md"), md);
}

// A pack file: every hop's wire faults and what the ring still reaches (analysis/pack_stress.h).
int run_pack_stress(const StressArgs& a, const std::vector<std::string>& only) {
  if (!a.spice_dir.empty())
    return fail(Status::Error(fmt::format(
        "{}: error: --export-spice is for link specs; run stress on a hop's link spec to export "
        "its scenarios",
        a.spec)));
  StatusOr<analysis::PackSpec> pack = analysis::read_pack_spec_file(a.spec);
  if (!pack) return fail(pack.status());
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());
  const std::string dir = report_dir(a, pack->name);
  StatusOr<OutputBundle> bundle = OutputBundle::open(dir, {"report.md", "report.json"});
  if (!bundle) return fail(bundle.status());
  ProgressLine line({.label = "isolink stress", .enabled = !a.quiet && !a.json});
  const analysis::StressOptions so = stress_options(a, only, line);
  StatusOr<analysis::PackStressResult> r = analysis::run_pack_stress(*pack, *parts, so);
  line.finish();
  if (!r) return fail(r.status().with_context(a.spec));
  const nlohmann::ordered_json j = reports::pack_stress_json(pack->name, *r);
  if (Status s = write_reports(*bundle, j, reports::pack_stress_markdown(pack->name, *r)); !s.ok())
    return fail(s);
  if (Status s = bundle->commit(); !s.ok()) return fail(s);
  if (a.json) {
    std::puts(j.dump(2).c_str());
  } else {
    for (const analysis::HopFault& f : r->faults)
      if (f.breaks_hop || !f.scenario.survives)
        std::printf("hop %-3d %-20s %s\n", f.hop, f.scenario.id.c_str(),
                    f.unreached.empty() ? "stops the hop; the ring reaches every device"
                                        : "stops the hop; devices unreached");
    std::printf("%s\nreport: %s/report.md\n", r->verdict.c_str(), dir.c_str());
  }
  return r->survives && r->all_reached ? 0 : 1;
}

int run_stress(const StressArgs& a) {
  StatusOr<std::vector<std::string>> only = parse_only(a.only);
  if (!only) return fail(only.status());
  if (a.direction != "down" && a.direction != "up" && a.direction != "both")
    return fail(Status::Error(fmt::format(
        "isolink stress: error: --direction = '{}': must be down, up or both", a.direction)));
  if (a.jobs < 0)
    return fail(Status::Error(
        fmt::format("isolink stress: error: -j = {}: must be >= 0 (0: all cores)", a.jobs)));
  if (StatusOr<config::YamlDoc> doc = config::YamlDoc::load_file(a.spec);
      doc && analysis::is_pack_spec(*doc))
    return run_pack_stress(a, *only);
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) return fail(spec.status());
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());
  const std::string dir = report_dir(a, spec->name);
  // The report folder appears whole or not at all; opened before the (long) runs so a bad -o
  // is reported at once.
  StatusOr<OutputBundle> bundle =
      OutputBundle::open(dir, {"report.md", "report.json", "stress.png", "report.html"});
  if (!bundle) return fail(bundle.status());
  ProgressLine line({.label = "isolink stress", .enabled = !a.quiet && !a.json});
  const analysis::StressOptions so = stress_options(a, *only, line);

  std::map<std::string, std::string> netlists;
  if (!a.spice_dir.empty()) {  // written first: a user can replay them even if a run fails
    StatusOr<std::vector<analysis::StressScenario>> built =
        analysis::build_stress_scenarios(*spec, *parts, so);
    if (!built) return fail(built.status().with_context(a.spec));
    std::error_code ec;
    std::filesystem::create_directories(a.spice_dir, ec);
    if (ec)
      return fail(Status::Error(
          fmt::format("{}: error: cannot create the folder: {}", a.spice_dir, ec.message())));
    for (const analysis::StressScenario& s : *built) {
      const std::string path = a.spice_dir + "/" + s.id + ".cir";
      if (Status st = write_file_atomic(path, write_spice(s.link.netlist)); !st.ok())
        return fail(st);
      netlists[s.id] = path;
    }
  }
  StatusOr<analysis::StressResult> r = analysis::run_stress(*spec, *parts, so);
  line.finish();
  if (!r) return fail(r.status().with_context(a.spec));
  const nlohmann::ordered_json j = reports::stress_json(spec->name, *r, netlists);
  if (Status s = write_reports(*bundle, j, reports::stress_markdown(spec->name, *r, netlists));
      !s.ok())
    return fail(s);
  if (Status s = reports::write_stress_png(*r, spec->name, bundle->path("stress.png")); !s.ok())
    return fail(s);
  StatusOr<std::string> png = read_input_file(bundle->path("stress.png"));
  if (!png) return fail(png.status());
  if (Status s =
          write_file_atomic(bundle->path("report.html"), reports::stress_report_html(j, *png, *r));
      !s.ok())
    return fail(s);
  if (Status s = bundle->commit(); !s.ok()) return fail(s);
  if (a.json) {
    std::puts(j.dump(2).c_str());
  } else {
    for (const analysis::StressScenario& s : r->scenarios)
      std::printf("%-4s %-22s %s\n", s.first_broken.empty() ? "ok" : "FAIL", s.id.c_str(),
                  s.first_broken.empty() ? s.description.c_str() : s.first_broken.c_str());
    std::printf("%s\nreport: %s/report.md\n", r->verdict.c_str(), dir.c_str());
  }
  return r->survives && r->communicates ? 0 : 1;
}

}  // namespace

void add_stress_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<StressArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stress",
      "What breaks a link in the field: module-ground steps and an inverter's square or sine "
      "during traffic, IEC 61000-4-2 ESD, hot-plugging a module (its contacts as switches, P or "
      "N first) and wire faults (open, short, to ground or chassis, a leaking pin) during "
      "traffic, with the pins' clamps and the TVS parts; report.md, report.json, report.html, "
      "stress.png; a pack spec: each hop's wire faults and what the ring still reaches; exit 1 "
      "when a limit or rule breaks");
  cmd->add_option("spec", args->spec,
                  "Link spec (YAML) with an optional stress: block, or a pack spec (each hop's "
                  "wire faults and what the ring still reaches)")
      ->required();
  cmd->add_option("-o,--output", args->out_dir,
                  "Report folder (default reports/out/<name>-stress)");
  add_parts_option(*cmd, &args->part_dirs);
  cmd->add_flag("--json", args->json, "Print the stress result as JSON on stdout");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress line");
  cmd->add_option("--only", args->only,
                  "Scenario kinds to run, comma-separated: cm_step, cm_wave, esd, hot_plug, wire");
  cmd->add_option("--direction", args->direction,
                  "Which end transmits in the traffic scenarios (cm_step, cm_wave, wire): down "
                  "(the tx end), up (the rx end) or both (default)");
  cmd->add_option("-j,--jobs", args->jobs, "Scenarios run at once (default 1; 0: all cores)");
  cmd->add_option("--export-spice", args->spice_dir,
                  "Write each scenario's netlist (ngspice dialect) into this folder");
  cmd->callback([args, exit_code] { *exit_code = run_stress(*args); });
}

}  // namespace isolink::cli
