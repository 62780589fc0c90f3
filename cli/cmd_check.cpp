// placeholder until the check command lands
#include "cli/commands.h"

namespace isolink::cli {
void add_check_command(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("check", "(not built yet)");
  cmd->callback([exit_code] { std::fputs("isolink check: not available in this build\n", stderr); *exit_code = 2; });
}
}  // namespace isolink::cli
