// isolink run: a link spec simulated with its traffic, each receiver scored, and the report
// bundle (eye.png, wave.png, report.json, report.md, report.html, wave.csv) written to a folder.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "analysis/link_run.h"
#include "analysis/link_run_wave.h"
#include "analysis/pack_spec.h"
#include "analysis/worst.h"
#include "base/file_io.h"
#include "base/progress.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/traffic/stimulus.h"
#include "reports/run_images.h"
#include "reports/run_report.h"
#include "reports/worst_png.h"
#include "reports/worst_report.h"

namespace isolink::cli {
using namespace isolink::analysis;  // run_link, LinkRun, run_waveforms
using namespace isolink::reports;   // report.json / report.md, images
namespace {

struct RunArgs {
  std::string spec;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  std::optional<std::vector<link::Direction>> directions;  // --direction
  Engine engine = Engine::Auto;
  WaveRows wave = WaveRows::Thinned;  // --wave: the rows of wave.csv
  bool no_images = false;
  bool no_worst = false;
  bool quiet = false;
};

// Traffic longer than this gets a warning before the run (simulated seconds; about 250 commands).
constexpr double kLongTrafficSeconds = 20e-3;

// What a report folder holds: an existing folder with anything else in it is not replaced.
// What a report folder holds: the bundle's files and the worst-case images
// (worst_<direction>_<metric>.png, reports/worst_png.h).
const std::vector<std::string> kBundleFiles = [] {
  std::vector<std::string> names = {"eye.png",   "wave.png", "report.json",
                                    "report.md", "wave.csv", "report.html"};
  for (const char* d : {"down", "up"})
    for (const char* m : {"vstart", "vend", "width_min", "width_max", "edge"})
      names.push_back(fmt::format("worst_{}_{}.png", d, m));
  return names;
}();

int fail(const Status& s) {
  std::fprintf(stderr, "%s\n", s.message().c_str());
  return 2;
}

int run_run(const RunArgs& a) {
  // A pack spec (a file with `hops:`) runs as `isolink pack`.
  if (StatusOr<config::YamlDoc> doc = config::YamlDoc::load_file(a.spec);
      doc && analysis::is_pack_spec(*doc)) {
    if (a.directions)
      return fail(
          Status::Error(fmt::format("{}: error: --direction is for link specs; a pack "
                                    "runs each hop in the directions it carries",
                                    a.spec)));
    return run_pack_command({a.spec, a.out_dir, a.part_dirs, 0, a.no_images, a.quiet, a.no_worst});
  }
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) return fail(spec.status());
  if (a.directions) spec->stimulus.directions = *a.directions;
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status());

  // The spec's name becomes a folder name: made safe (no "..", separators or control bytes).
  const std::string dir =
      a.out_dir.empty() ? "reports/out/" + safe_path_component(spec->name) : a.out_dir;
  // The bundle appears whole or not at all (base/file_io.h OutputBundle); opened before the
  // simulation so that a bad -o is reported at once.
  StatusOr<OutputBundle> bundle = OutputBundle::open(dir, kBundleFiles);
  if (!bundle) return fail(bundle.status());
  // A size check before obviously huge work (10,000 frames ran for minutes without a word).
  if (StatusOr<traffic::Drive> d = traffic::build_drive(spec->stimulus.to_script()); d) {
    if (d->duration() > kLongTrafficSeconds)
      std::fprintf(stderr,
                   "isolink run: warning: the stimulus is %.3g ms of traffic (%zu frames) per "
                   "direction, above %.0f ms: long work (each direction is simulated in full); "
                   "shorten it to iterate faster\n",
                   d->duration() * 1e3, d->frames.size(), kLongTrafficSeconds * 1e3);
  }
  // Progress on stderr while the engines run, when it is a terminal (base/progress.h).
  ProgressLine line({.label = "isolink run", .enabled = !a.quiet});
  auto progress = [&line](const std::string& what, double f) { line.show_fraction(what, f); };
  RunOptions ro;
  ro.engine = a.engine;
  ro.progress = progress;
  // --wave rows and grid write from every engine row: the run keeps them all (memory grows with
  // the traffic); thinned keeps what wave.csv's thinning and the checks need.
  if (a.wave != WaveRows::Thinned) ro.record_tol = 0;
  ro.threads = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  StatusOr<LinkRun> run = run_link(*spec, *parts, ro);
  if (!run) return fail(run.status().with_context(a.spec));
  // The worst case over all legal traffic, beside the spec's traffic (its own verdict).
  std::optional<analysis::WorstResult> worst;
  // The worst case superposes edge responses: a nonlinear link (a TVS, the pins' clamps) has
  // none to superpose, so its run is the exact transient of the spec's traffic alone, and the
  // report says why the worst case is missing.
  const std::string no_worst_why =
      link::linear_only(*spec, "the worst case over all legal traffic");
  if (!a.no_worst && no_worst_why.empty()) {
    analysis::WorstOptions wopt;
    wopt.progress = [&](const std::string& what, double f) {
      line.show_fraction("worst case, " + what, f);
    };
    StatusOr<analysis::WorstResult> w = analysis::worst_case(*spec, *parts, wopt);
    if (!w) return fail(w.status().with_context(a.spec + ", worst case"));
    worst = std::move(*w);
  }

  line.finish();
  // The images and wave.csv both only read the run: drawn on a second thread while this one
  // thins and writes the waveform (a long record's eye and its thinning take seconds each).
  std::vector<std::string> images;
  std::future<Status> drawn = std::async(std::launch::async, [&] {
    return a.no_images ? Status::Ok() : render_run_images(*spec, *run, bundle->staging(), &images);
  });
  WaveFile wave = run_wave_file(*run, {.rows = a.wave, .grid_step = spec->sim.tstep});
  Status csv = write_waveform_csv(wave.wave, bundle->path("wave.csv"));
  if (Status s = drawn.get(); !s.ok()) return fail(s);
  if (!csv.ok()) return fail(csv);
  nlohmann::ordered_json json = run_report_json(*spec, *run);
  json["wave_csv"] = {{"rows", wave.wave.time.size()},
                      {"engine_rows", wave.engine_rows},
                      {"mode", wave_rows_name(wave.rows)},
                      {"tolerance_v", wave.tolerance}};
  std::string md = run_report_markdown(*spec, *run, images);
  md += "\n" + wave_file_note(wave) + ".\n";
  wave.wave = Waveform{};  // written and described: its rows are not held beside report.html's
  if (worst) {
    json["worst_case"] = reports::worst_json(*worst);
    md += "\n## Worst case over all traffic\n\n" + reports::worst_markdown(*worst);
    if (!a.no_images) {
      std::vector<std::string> files;
      if (Status s = reports::render_worst_pngs(*worst, spec->name, {}, bundle->staging(), &files);
          !s.ok())
        return fail(s);
      for (const std::string& f : files) md += fmt::format("![{}]({})\n\n", f, f);
    }
  } else if (!a.no_worst) {
    json["worst_case"] = {{"computed", false}, {"why", no_worst_why}};
    md += "\n## Worst case over all traffic\n\nNot computed: " + no_worst_why + ".\n";
    std::fprintf(stderr, "isolink run: note: no worst case: %s\n", no_worst_why.c_str());
  }
  if (Status s = write_file_atomic(bundle->path("report.json"), json.dump(2) + "\n"); !s.ok())
    return fail(s);
  if (Status s = write_file_atomic(bundle->path("report.md"), md); !s.ok()) return fail(s);
  std::string eye_png;
  if (std::find(images.begin(), images.end(), "eye.png") != images.end()) {
    StatusOr<std::string> png = read_input_file(bundle->path("eye.png"));
    if (!png) return fail(png.status());
    eye_png = std::move(*png);
  }
  if (Status s = write_file_atomic(bundle->path("report.html"),
                                   run_report_page(*spec, *run, json, eye_png));
      !s.ok())
    return fail(s);
  if (Status s = bundle->commit(); !s.ok()) return fail(s);
  std::vector<std::string> warned;  // both directions share most warnings: print each once
  for (const DirectionRun& d : run->directions)
    for (const std::string& w : d.sim.warnings)
      if (std::find(warned.begin(), warned.end(), w) == warned.end()) {
        warned.push_back(w);
        std::fprintf(stderr, "%s\n", w.c_str());
      }
  if (!a.quiet) {
    std::fputs(run_summary_text(*spec, *run).c_str(), stdout);
    if (worst) std::fputs(reports::worst_summary_text(*worst).c_str(), stdout);
    std::printf("report: %s/report.md\n", dir.c_str());
  }
  return run->pass ? 0 : 1;
}

}  // namespace

void add_run_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Simulate a link spec with its traffic, score each receiver and write the report "
      "(eye.png, wave.png, report.json, report.md, report.html, wave.csv)");
  cmd->add_option("spec", args->spec,
                  "Link spec (YAML), e.g. netlists/examples/transformer_15m.yaml")
      ->required();
  cmd->add_option("-o,--output", args->out_dir, "Report folder (default reports/out/<name>)");
  add_parts_option(*cmd, &args->part_dirs);
  add_directions_option(*cmd, &args->directions);
  add_engine_option(*cmd, &args->engine);
  cmd->add_option_function<std::string>(
         "--wave",
         // CLI11 has checked the name against the choices, so parse_wave_rows succeeds.
         [args](const std::string& v) { args->wave = *parse_wave_rows(v); },
         "rows of wave.csv: thinned (the engine's rows that linear interpolation needs to stay "
         "within 1 mV of every engine row; the default), rows (every engine row), grid (every "
         "probe resampled onto the spec's sim.tstep)")
      ->check(CLI::IsMember({"thinned", "rows", "grid"}))
      ->default_str("thinned");
  cmd->add_flag("--no-images", args->no_images, "Skip eye.png and wave.png");
  cmd->add_flag("--no-worst", args->no_worst,
                "Skip the worst case over all traffic (its report section and verdict)");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  cmd->callback([args, exit_code] { *exit_code = run_run(*args); });
}

}  // namespace isolink::cli
