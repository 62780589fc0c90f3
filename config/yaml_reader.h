// YAML input files (link specs, sweeps, part libraries) read key by key, with compiler-style
// diagnostics: every error names the file, line and column, the key path and what was expected,
// and shows the source line with a caret.
//
// Usage:
//   StatusOr<YamlDoc> doc = YamlDoc::load_file("link.yaml");
//   if (!doc) return doc.status();                         // file missing, YAML syntax error
//   double length = 1.0;  std::string material = "pp";
//   Status s = read_map(*doc, doc->root(), "cable", {
//       {"length", read_quantity(*doc, Unit::kMetre, Rule::kPositive, &length)},
//       {"material", read_choice(*doc, {"pp", "pvc"}, &material)},
//   });                                                    // unknown keys are errors too
// Quantities take SPICE suffixes and an optional unit symbol: 2.2n, 2.2nF, 49, 49ohm, 10meg.
// A wrong unit ("2.2nH" for a capacitance) is an error. Lengths (metres) take no suffix:
// "12", "12m" and "12 m" are all 12 metres.
// Nodes created in code (a sweep's overrides) carry no position: errors then name the key path.
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"

namespace isolink::config {

enum class Unit {
  kNone,
  kOhm,
  kFarad,
  kHenry,
  kSecond,
  kVolt,
  kAmpere,
  kHertz,
  kMetre,
  kCelsius,
  kSiemens,
  kWatt
};
enum class Rule { kAny, kPositive, kNonNegative };

class YamlDoc {
 public:
  static StatusOr<YamlDoc> load_file(const std::string& path);
  static StatusOr<YamlDoc> from_text(const std::string& text, const std::string& name);

  const YAML::Node& root() const { return root_; }
  YAML::Node& root() { return root_; }
  const std::string& path() const { return file_->path; }
  // Where a node starts (line 0 when it has no position).
  SourceLoc loc(const YAML::Node& node) const;
  // "file:line:col: error: MESSAGE" with the source line and a caret, or "file: error: ..."
  Status error(const YAML::Node& node, const std::string& message) const;

  // Deep merge of the map `overlay`, a node of document `from`, into the root: where both sides
  // hold a map the keys merge one by one, anything else (a value, a list) replaces. Errors about
  // the merged nodes then name `from`'s file, line and column. (Pack specs: a hop's overrides.)
  Status merge(const YAML::Node& overlay, const YamlDoc& from);
  // root[key] = value (a node of `from`), replacing what was there.
  void replace(const std::string& key, const YAML::Node& value, const YamlDoc& from);

 private:
  struct Overlay {
    YAML::Node node;
    std::shared_ptr<const SourceFile> file;
  };
  Status merge_map(YAML::Node target, const YAML::Node& overlay, const YamlDoc& from,
                   const std::string& path);
  std::shared_ptr<const SourceFile> file_of(const YAML::Node& node) const;

  std::shared_ptr<const SourceFile> file_;
  YAML::Node root_;
  std::vector<Overlay> overlays_;  // subtrees merged in from other documents
};

// Reads one value; the handler gets the node and its dotted key path ("tx.isolation.cap").
using FieldReader = std::function<Status(const YAML::Node& node, const std::string& path)>;
struct Field {
  std::string key;
  FieldReader read;
};

// Walks a map: each key must be one of fields (else an error listing the known keys).
// A null node (key present with no value, or absent) reads as an empty map.
Status read_map(const YamlDoc& doc, const YAML::Node& node, const std::string& path,
                const std::vector<Field>& fields);

FieldReader read_quantity(const YamlDoc& doc, Unit unit, Rule rule, double* out);
FieldReader read_quantity(const YamlDoc& doc, Unit unit, Rule rule, std::optional<double>* out);
FieldReader read_text(const YamlDoc& doc, std::string* out);
FieldReader read_choice(const YamlDoc& doc, std::vector<std::string> options, std::string* out);
FieldReader read_bool(const YamlDoc& doc, bool* out);
FieldReader read_int(const YamlDoc& doc, int lo, int hi, int* out);
// A percentage "10%" (or "10 %"), stored as the fraction 0.1; must lie in [0, max_percent].
FieldReader read_percent(const YamlDoc& doc, double max_percent, double* out);
// A list of text items, or one text item.
FieldReader read_text_list(const YamlDoc& doc, std::vector<std::string>* out);

// Parses "2.2n", "2.2nF", "49ohm", "10meg" for the unit; false when the text is not that.
bool parse_quantity(std::string_view text, Unit unit, double* out);
// The unit's symbol as written in messages ("F", "ohm", "m", ...).
const char* unit_symbol(Unit unit);
// "map", "list", "nothing" or "value", for messages.
std::string node_kind(const YAML::Node& node);
// Scalar text of a node, or its kind in angle brackets.
std::string node_text(const YAML::Node& node);

}  // namespace isolink::config
