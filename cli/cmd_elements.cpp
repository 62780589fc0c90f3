// isolink elements: the element kinds and their parameters, from the kinds' own tables.
// The README's "Element reference" section is this command's --markdown output.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "cli/commands.h"
#include "solver/elements/element.h"

namespace isolink::cli {

void add_elements_command(CLI::App& app, int* exit_code) {
  auto markdown = std::make_shared<bool>(false);
  CLI::App* cmd =
      app.add_subcommand("elements", "List the netlist element kinds and their parameters");
  cmd->add_flag("--markdown", *markdown, "print the table as Markdown (as in the README)");
  cmd->callback([markdown, exit_code] {
    if (*markdown) {
      std::fputs(element_reference_markdown().c_str(), stdout);
    } else {
      for (const ElementKind& k : element_kinds()) {
        std::printf("%c  %-18s %s\n", k.letter, k.name, k.usage);
        for (const ParamSpec& p : k.params)
          std::printf("     %-6s %-10s %-4s %s\n", p.name,
                      std::isnan(p.default_value) ? (p.optional ? "none" : "required")
                                                  : fmt::format("{:g}", p.default_value).c_str(),
                      p.unit, p.doc);
      }
    }
    *exit_code = 0;
  });
}

}  // namespace isolink::cli
