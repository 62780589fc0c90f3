// isolink export-spice: a link spec expanded into the ngspice-dialect netlist that `isolink sim`
// also reads (one direction per file; down by default).
#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <vector>

#include "base/file_io.h"
#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/spice_writer.h"

namespace isolink::cli {
namespace {

struct ExportArgs {
  std::string spec;
  std::string direction = "down";
  std::string output;
  std::vector<std::string> part_dirs;
};

int run_export(const ExportArgs& a) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) {
    std::fprintf(stderr, "%s\n", spec.status().message().c_str());
    return 2;
  }
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load(a.part_dirs);
  if (!parts) {
    std::fprintf(stderr, "%s\n", parts.status().message().c_str());
    return 2;
  }
  const link::Direction d = a.direction == "up" ? link::Direction::kUp : link::Direction::kDown;
  StatusOr<link::ExpandedLink> ex = link::expand_link(*spec, *parts, d);
  if (!ex) {
    std::fprintf(stderr, "%s\n", ex.status().message().c_str());
    return 2;
  }
  std::string text = write_spice(ex->netlist);
  const std::string out = a.output.empty() ? "-" : a.output;
  if (Status s = write_file_atomic(out, text); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 2;
  }
  if (out == "-") return 0;
  std::fprintf(stderr, "wrote %s (%s, %zu elements)\n", a.output.c_str(), ex->description.c_str(),
               ex->netlist.cards.size());
  return 0;
}

}  // namespace

void add_export_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export-spice",
      "Write a link spec's expanded netlist (ngspice dialect, runs in ngspice and "
      "in `isolink sim`)");
  cmd->add_option("spec", args->spec, "Link spec (YAML)")->required();
  cmd->add_option("--direction", args->direction, "Which end transmits: down (tx end) or up")
      ->check(CLI::IsMember({"down", "up"}));
  cmd->add_option("-o,--output", args->output, "Output file (default: standard output)");
  add_parts_option(*cmd, &args->part_dirs);
  cmd->callback([args, exit_code] { *exit_code = run_export(*args); });
}

}  // namespace isolink::cli
