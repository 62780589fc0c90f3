// The isolink subcommands. Each add_*_command registers one CLI11 subcommand on app; its callback
// runs the command and stores the process exit status in *exit_code
// (0 pass / done, 1 the link fails its rules, 2 bad input or internal error).
#pragma once

#include <CLI/CLI.hpp>

namespace isolink::cli {

void add_sim_command(CLI::App& app, int* exit_code);
void add_check_command(CLI::App& app, int* exit_code);
void add_frame_command(CLI::App& app, int* exit_code);
void add_elements_command(CLI::App& app, int* exit_code);
void add_parts_command(CLI::App& app, int* exit_code);
void add_run_command(CLI::App& app, int* exit_code);
void add_export_command(CLI::App& app, int* exit_code);
void add_sweep_command(CLI::App& app, int* exit_code);

// The element table of the README (`isolink elements --markdown`).

}  // namespace isolink::cli
