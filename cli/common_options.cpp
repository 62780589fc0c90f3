#include "cli/common_options.h"

namespace isolink::cli {

CLI::Option* add_engine_option(CLI::App& cmd, analysis::Engine* engine) {
  std::vector<std::string> names;
  std::string help = "simulation engine:";
  for (analysis::Engine e : analysis::kEngines) {
    names.emplace_back(analysis::engine_name(e));
    help += std::string(names.size() == 1 ? " " : "; ") + analysis::engine_name(e) + " (" +
            analysis::engine_summary(e) + ")";
  }
  return cmd
      .add_option_function<std::string>(
          "--engine",
          // CLI11 has checked the name against the choices below, so parse_engine succeeds.
          [engine](const std::string& name) { *engine = *analysis::parse_engine(name); }, help)
      ->check(CLI::IsMember(names))
      ->default_str(analysis::engine_name(analysis::Engine::Auto));
}

CLI::Option* add_parts_option(CLI::App& cmd, std::vector<std::string>* dirs) {
  return cmd
      .add_option("--parts", *dirs,
                  "a part-library folder of *.yaml files (or one part file), read after the "
                  "built-in library; repeatable, a later part with the same number replaces an "
                  "earlier one")
      ->allow_extra_args(false);
}

CLI::Option* add_directions_option(CLI::App& cmd,
                                   std::optional<std::vector<link::Direction>>* dirs) {
  return cmd
      .add_option_function<std::string>(
          "--direction",
          [dirs](const std::string& d) {
            if (d == "down") *dirs = {link::Direction::kDown};
            if (d == "up") *dirs = {link::Direction::kUp};
            if (d == "both") *dirs = {link::Direction::kDown, link::Direction::kUp};
          },
          "override the spec's stimulus.direction: down (its tx end transmits), up, or both")
      ->check(CLI::IsMember({"down", "up", "both"}));
}

}  // namespace isolink::cli
