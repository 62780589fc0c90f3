// isolink compare CAPTURE [CAPTURE_N] LINK.yaml: a scope capture against the link spec's
// simulation of the same traffic, and the spec keys that explain the difference
// (analysis/compare.h). This file maps flags, prints and writes the report folder.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "analysis/compare.h"
#include "analysis/sweep_spec.h"
#include "base/file_io.h"
#include "base/si_number.h"
#include "cli/capture_options.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/parts.h"
#include "reports/compare_png.h"
#include "reports/compare_report.h"

namespace isolink::cli {
namespace {

struct CompareArgs {
  std::vector<std::string> files;  // capture file(s), then the spec
  eye::CsvColumns cols;
  std::string direction = "down";
  std::string frames;
  std::string fit;
  std::vector<std::string> bounds;
  bool json = false;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  int jobs = 0;
  bool local = false;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "isolink compare: %s\n", message.c_str());
  return 2;
}

// "KEY=LO:HI" with LO and HI in the key's unit rules.
Status parse_bound(const std::string& text, analysis::CompareOptions& opt) {
  const size_t eq = text.find('='), colon = text.find(':', eq == std::string::npos ? 0 : eq);
  if (eq == std::string::npos || colon == std::string::npos)
    return Status::Error(
        fmt::format("--bounds: error: '{}': expected KEY=LO:HI, e.g. cable.length=5:30", text));
  const std::string key = text.substr(0, eq);
  const std::string path = key.rfind("ends.", 0) == 0 ? "tx." + key.substr(5) : key;
  auto lo = analysis::sweep::key_number(path, text.substr(eq + 1, colon - eq - 1));
  auto hi = analysis::sweep::key_number(path, text.substr(colon + 1));
  if (!lo || !hi || !(*lo < *hi))
    return Status::Error(fmt::format(
        "--bounds: error: '{}': LO and HI must be numbers of the key's unit with LO < HI", text));
  opt.bounds[key] = {*lo, *hi};
  return Status::Ok();
}

int write_outputs(const analysis::CompareResult& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return fail(fmt::format("{}: error: cannot create the folder: {}", dir, ec.message()));
  if (Status s = reports::write_compare_png(r, dir + "/compare.png"); !s.ok())
    return fail(s.message());
  if (Status s = write_file_atomic(dir + "/report.json", reports::compare_json(r).dump(2) + "\n");
      !s.ok())
    return fail(s.message());
  if (Status s = write_file_atomic(dir + "/report.md",
                                   reports::compare_markdown(r) + "\n![compare](compare.png)\n");
      !s.ok())
    return fail(s.message());
  return 0;
}

int run_compare(const CompareArgs& a) {
  if (a.files.size() < 2) return fail("error: expected CAPTURE [CAPTURE_N] LINK.yaml");
  analysis::CompareInput in;
  in.files.assign(a.files.begin(), a.files.end() - 1);
  in.spec_path = a.files.back();
  in.cols = a.cols;
  analysis::CompareOptions opt;
  opt.direction = a.direction == "up" ? link::Direction::kUp : link::Direction::kDown;
  opt.frames = a.frames;
  if (a.jobs < 0)
    return fail(fmt::format("error: option -j = {}: must be >= 0 (0: all cores)", a.jobs));
  opt.threads = a.jobs;
  opt.global_search = !a.local;
  for (size_t i = 0; i < a.fit.size();) {
    const size_t c = std::min(a.fit.find(',', i), a.fit.size());
    if (c > i) opt.fit.push_back(a.fit.substr(i, c - i));
    i = c + 1;
  }
  for (const std::string& b : a.bounds)
    if (Status s = parse_bound(b, opt); !s.ok()) return fail(s.message());
  for (const auto& [key, range] : opt.bounds)
    if (std::find(opt.fit.begin(), opt.fit.end(), key) == opt.fit.end())
      return fail(fmt::format("--bounds: error: key '{}' is not one of --fit", key));
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) return fail(parts.status().message());
  StatusOr<analysis::CompareResult> r = analysis::compare_capture(in, *parts, opt);
  if (!r) return fail(r.status().message());
  if (!a.out_dir.empty())
    if (int rc = write_outputs(*r, a.out_dir); rc != 0) return rc;
  if (a.json)
    std::printf("%s\n", reports::compare_json(*r).dump(2).c_str());
  else
    std::fputs(reports::compare_text(*r).c_str(), stdout);
  return r->verdict == "match" ? 0 : 1;
}

}  // namespace

void add_compare_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<CompareArgs>();
  auto* cmd = app.add_subcommand(
      "compare",
      "Compare a scope capture of a receiver with the link spec's simulation of the same "
      "traffic, and fit spec keys to it (exit 0 match, 1 mismatch or inconclusive, 2 bad input)");
  cmd->add_option("files", args->files,
                  "CAPTURE [CAPTURE_N] LINK.yaml: a capture as `isolink check` reads it (one file, "
                  "or P then N), then the link spec")
      ->required()
      ->expected(2, 3);
  add_capture_column_options(*cmd, args->cols);
  cmd->add_option("--direction", args->direction, "the receiver probed: down (rx end) or up")
      ->check(CLI::IsMember({"down", "up"}))
      ->capture_default_str();
  cmd->add_option("--frames", args->frames,
                  "traffic when nothing decodes: a stimulus script, e.g. \"stack-write "
                  "reg=0x0100 data=02B778BC\" (default: the spec's stimulus)");
  cmd->add_option("--fit", args->fit,
                  "keys to fit, comma-separated dotted paths as in sweeps: cable.length, "
                  "rx.isolation.cap, tx.isolation.leakage, ends.termination, ...");
  cmd->add_option("--bounds", args->bounds,
                  "KEY=LO:HI bounds of a fitted key (default: R and C 1/10..10x the design value, "
                  "L 1/10..2x, cable.length 0.1..100 m); repeatable");
  cmd->add_flag("--local", args->local,
                "refine from the design only: no scan of the bounds when that leaves the capture "
                "unexplained");
  cmd->add_option("-j,--jobs", args->jobs,
                  "simulations the fit runs at once (its Jacobian's columns; default: all cores)");
  cmd->add_flag("--json", args->json, "print one JSON object instead of the summary");
  cmd->add_option("-o,--output", args->out_dir,
                  "write compare.png, report.md and report.json to this folder");
  add_parts_option(*cmd, &args->part_dirs);
  cmd->callback([args, exit_code] { *exit_code = run_compare(*args); });
}

}  // namespace isolink::cli
