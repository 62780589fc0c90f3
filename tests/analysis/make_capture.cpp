// make_capture SPEC.yaml OUT.csv [KEY=VALUE ...] [--rigol]: a synthetic scope capture of the link
// spec with keys replaced (the truth), through the default ScopeModel (synthetic_capture.h): the
// README's worked example of isolink compare is made with it.
#include <cstdio>
#include <string>
#include <vector>

#include "base/file_io.h"
#include "tests/analysis/synthetic_capture.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: make_capture SPEC.yaml OUT.csv [KEY=VALUE ...] [--rigol]\n");
    return 2;
  }
  isolink::StatusOr<std::string> text = isolink::read_input_file(argv[1]);
  if (!text) {
    std::fprintf(stderr, "%s\n", text.status().message().c_str());
    return 2;
  }
  std::vector<isolink::analysis::sweep::Assignment> truth;
  isolink::testing::ScopeModel scope;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--rigol") {
      scope.layout = "rigol";
      continue;
    }
    const size_t eq = a.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "make_capture: %s: expected KEY=VALUE\n", a.c_str());
      return 2;
    }
    truth.push_back({a.substr(0, eq), a.substr(eq + 1), true});
  }
  isolink::Status s =
      isolink::testing::write_synthetic_capture(*text, argv[1], truth, scope, argv[2]);
  if (!s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 2;
  }
  return 0;
}
