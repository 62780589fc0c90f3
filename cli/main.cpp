// isolink: signal-integrity analyzer for BMS daisy-chain links.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli/commands.h"
#include "solver/dense_lapack.h"

int main(int argc, char** argv) {
  // Every sweep point, edge response and model allocates and frees the same large arrays (MBs):
  // keep them in the heap (up to 32 MB each, 512 MB of free memory before trimming) rather than
  // unmapped and faulted in again each time. Measured 2026-12-01: a worst-case sweep runs 17 %
  // faster (bench/README.md). Peak memory is unchanged; only freed memory is kept for reuse.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  isolink::stop_blas_worker_threads();
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
  isolink::cli::add_stress_command(app, &exit_code);
  isolink::cli::add_worst_command(app, &exit_code);
  isolink::cli::add_pack_command(app, &exit_code);
  isolink::cli::add_compare_command(app, &exit_code);
  isolink::cli::add_touchstone_command(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return exit_code;
}
