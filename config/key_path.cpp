#include "config/key_path.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <string_view>
#include <utility>

namespace isolink::config {

namespace {

constexpr std::string_view kMark = "# isolink: built in memory; locations are key paths";

using KeyPaths = std::map<std::pair<int, int>, std::string>;

// Every node's position (1-based line, column) -> its key path.
void collect(const YAML::Node& node, const std::string& path, KeyPaths* out) {
  const auto note = [out](const YAML::Node& n, const std::string& p) {
    const YAML::Mark m = n.Mark();
    if (!m.is_null()) out->emplace(std::pair{m.line + 1, m.column + 1}, p);
  };
  note(node, path);
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = it->first.IsScalar() ? it->first.Scalar() : "?";
      const std::string sub = path.empty() ? key : path + "." + key;
      note(it->first, sub);
      collect(it->second, sub, out);
    }
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) collect(node[i], fmt::format("{}[{}]", path, i), out);
  }
}

}  // namespace

std::string key_path_document(const std::string& json_text) {
  return std::string(kMark) + "\n" + json_text;
}

bool is_key_path_document(const SourceFile& file) {
  return !file.lines.empty() && file.lines.front() == kMark;
}

std::optional<std::string> key_path_at(const SourceFile& file, int line, int col) {
  if (!is_key_path_document(file)) return std::nullopt;
  // Parsed again from the file's lines: only locations ask (errors, and the few a reader keeps).
  std::string text;
  for (const std::string& l : file.lines) text.append(l).append("\n");
  KeyPaths paths;
  try {
    collect(YAML::Load(text), "", &paths);
  } catch (const YAML::Exception&) {
    return std::nullopt;
  }
  const auto it = paths.find({line, col});
  if (it == paths.end()) return std::nullopt;
  return it->second;
}

}  // namespace isolink::config
