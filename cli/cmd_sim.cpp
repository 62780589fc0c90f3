// placeholder until the sim command lands
#include "cli/commands.h"

namespace isolink::cli {
void add_sim_command(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("sim", "(not built yet)");
  cmd->callback([exit_code] { std::fputs("isolink sim: not available in this build\n", stderr); *exit_code = 2; });
}
}  // namespace isolink::cli
