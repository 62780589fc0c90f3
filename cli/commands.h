// The isolink subcommands. Each add_*_command registers one CLI11 subcommand on app; its callback
// runs the command and stores the process exit status in *exit_code
// (0 pass / done, 1 the link fails its rules, 2 bad input or internal error).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace isolink::cli {

void add_sim_command(CLI::App& app, int* exit_code);
void add_check_command(CLI::App& app, int* exit_code);
void add_frame_command(CLI::App& app, int* exit_code);
void add_elements_command(CLI::App& app, int* exit_code);
void add_parts_command(CLI::App& app, int* exit_code);
void add_run_command(CLI::App& app, int* exit_code);
void add_export_command(CLI::App& app, int* exit_code);
void add_sweep_command(CLI::App& app, int* exit_code);
void add_noise_command(CLI::App& app, int* exit_code);
void add_stress_command(CLI::App& app, int* exit_code);
void add_worst_command(CLI::App& app, int* exit_code);
void add_pack_command(CLI::App& app, int* exit_code);
void add_compare_command(CLI::App& app, int* exit_code);
// isolink touchstone and isolink export-touchstone.
void add_touchstone_command(CLI::App& app, int* exit_code);

// isolink pack's options; `isolink run` passes a pack spec on with its own -o, --parts, -q.
struct PackArgs {
  std::string spec;
  std::string out_dir;
  std::vector<std::string> part_dirs;
  int jobs = 0;
  bool no_images = false;
  bool quiet = false;
  bool no_worst = false;  // skip the worst case over all traffic
};
int run_pack_command(const PackArgs& a);

// The element table of the README (`isolink elements --markdown`).

}  // namespace isolink::cli
