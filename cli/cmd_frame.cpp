// placeholder until the frame command lands
#include "cli/commands.h"

namespace isolink::cli {
void add_frame_command(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("frame", "(not built yet)");
  cmd->callback([exit_code] { std::fputs("isolink frame: not available in this build\n", stderr); *exit_code = 2; });
}
}  // namespace isolink::cli
