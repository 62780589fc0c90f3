// isolink: signal-integrity analyzer for BMS daisy-chain links.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli/commands.h"

int main(int argc, char** argv) {
  CLI::App app{"isolink: signal integrity of BMS daisy-chain links (BQ7961x, BQ79600, BQ79606A)"};
  app.require_subcommand(1);
  int exit_code = 0;
  isolink::cli::add_run_command(app, &exit_code);
  isolink::cli::add_sim_command(app, &exit_code);
  isolink::cli::add_check_command(app, &exit_code);
  isolink::cli::add_frame_command(app, &exit_code);
  isolink::cli::add_elements_command(app, &exit_code);
  isolink::cli::add_parts_command(app, &exit_code);
  isolink::cli::add_export_command(app, &exit_code);
  isolink::cli::add_sweep_command(app, &exit_code);
  isolink::cli::add_noise_command(app, &exit_code);
  isolink::cli::add_worst_command(app, &exit_code);
  isolink::cli::add_pack_command(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return exit_code;
}
