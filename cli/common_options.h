// The options several isolink commands share, each declared once here so that every command
// accepts the same values and its --help shows the same line (tests/cli/common_options_test.cpp
// holds them to it). A command's own options stay in its cmd_*.cpp.
//
//   analysis::Engine engine = analysis::Engine::Auto;
//   add_engine_option(*cmd, &engine);     // --engine auto|lti|transient
//   add_parts_option(*cmd, &part_dirs);   // --parts DIR, repeatable
//   add_directions_option(*cmd, &dirs);   // --direction down|up|both over a link spec
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/simulate.h"
#include "netlists/link/link_spec.h"

namespace isolink::cli {

// --engine: one of analysis::kEngines by its engine_name ("auto", "lti", "transient"), written
// to *engine when given (otherwise *engine keeps its value, Auto by convention). The choices and
// the help come from the enum's own list (engine_name, engine_summary); another value is refused
// by CLI11 before the command runs (exit 2). engine must outlive the parse.
CLI::Option* add_engine_option(CLI::App& cmd, analysis::Engine* engine);

// --parts DIR: a part-library folder of *.yaml files, or one part file, searched after the
// built-in library (link::PartLibrary::load); repeatable, one path per --parts, appended to *dirs
// in order (a later part with the same number replaces an earlier one). dirs must outlive the
// parse.
CLI::Option* add_parts_option(CLI::App& cmd, std::vector<std::string>* dirs);

// --direction down|up|both (`isolink run`, `worst`): replaces the link spec's
// stimulus.direction with down ({kDown}: the spec's tx end transmits), up ({kUp}) or both
// ({kDown, kUp}); *dirs stays empty when the option is not given. Another value is refused by
// CLI11 (exit 2). dirs must outlive the parse. (`export-spice` and `compare` take one direction
// with a meaning of their own and declare it themselves.)
CLI::Option* add_directions_option(CLI::App& cmd,
                                   std::optional<std::vector<link::Direction>>* dirs);

}  // namespace isolink::cli
