#include "config/yaml_reader.h"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "base/file_io.h"
#include "base/si_number.h"
#include "base/utf8.h"
#include "config/key_path.h"

namespace isolink::config {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Unit symbols accepted after the number (lower case), the first is the canonical one.
std::vector<std::string> unit_words(Unit unit) {
  switch (unit) {
    case Unit::kOhm:
      return {"ohm", "ohms", "r"};
    case Unit::kFarad:
      return {"f"};
    case Unit::kHenry:
      return {"h"};
    case Unit::kSecond:
      return {"s"};
    case Unit::kVolt:
      return {"v"};
    case Unit::kAmpere:
      return {"a"};
    case Unit::kHertz:
      return {"hz"};
    case Unit::kMetre:
      return {"m"};
    case Unit::kCelsius:
      return {"c", "degc"};
    case Unit::kSiemens:
      return {"s"};
    case Unit::kWatt:
      return {"w"};
    case Unit::kNone:
      return {};
  }
  return {};
}

std::string rule_text(Rule rule) {
  switch (rule) {
    case Rule::kPositive:
      return "must be > 0";
    case Rule::kNonNegative:
      return "must be >= 0";
    case Rule::kAny:
      return "";
  }
  return "";
}

bool obeys(Rule rule, double v) {
  if (rule == Rule::kPositive) return v > 0;
  if (rule == Rule::kNonNegative) return v >= 0;
  return true;
}

}  // namespace

const char* unit_symbol(Unit unit) {
  switch (unit) {
    case Unit::kOhm:
      return "ohm";
    case Unit::kFarad:
      return "F";
    case Unit::kHenry:
      return "H";
    case Unit::kSecond:
      return "s";
    case Unit::kVolt:
      return "V";
    case Unit::kAmpere:
      return "A";
    case Unit::kHertz:
      return "Hz";
    case Unit::kMetre:
      return "m";
    case Unit::kCelsius:
      return "degC";
    case Unit::kSiemens:
      return "S";
    case Unit::kWatt:
      return "W";
    case Unit::kNone:
      return "";
  }
  return "";
}

bool parse_quantity(std::string_view text, Unit unit, double* out) {
  std::string s = lower(text);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  size_t start = 0;
  while (start < s.size() && std::isspace(static_cast<unsigned char>(s[start]))) ++start;
  std::string_view body = std::string_view(s).substr(start);
  if (body.empty()) return false;
  const bool neg = body[0] == '-';
  if (body[0] == '+' || body[0] == '-') body.remove_prefix(1);
  const std::vector<std::string> words = unit_words(unit);
  auto is_unit = [&](std::string_view r) {
    if (r.empty()) return true;
    for (const std::string& w : words)
      if (r == w) return true;
    return false;
  };
  // The one SPICE number scanner (base/si_number.h), first stopped before any letter: the unit
  // symbol is tried first, so "2.2f" for a capacitance is 2.2 F, not 2.2 femto.
  std::optional<SiNumber> n = scan_si_number(body, {.scale = false, .unit_letters = false});
  if (!n) return false;
  std::string_view rest = body.substr(n->length);
  const bool spaced = !rest.empty() && rest[0] == ' ';
  while (!rest.empty() && rest[0] == ' ') rest.remove_prefix(1);
  if (!is_unit(rest)) {
    // Lengths and temperatures take no scale suffix: "12m" is 12 metres, not 12 milli.
    if (unit == Unit::kMetre || unit == Unit::kCelsius || unit == Unit::kNone) return false;
    // A scale suffix, then the unit: "2.2nF", "2.2 nF", "10meg", "4k7". Across a blank only
    // letters may follow ("2.2 nF"; not "4 k7" or "1 e5").
    if (spaced && !std::all_of(rest.begin(), rest.end(), [](char c) {
          return std::isalpha(static_cast<unsigned char>(c)) != 0;
        }))
      return false;
    const std::string joined = std::string(body.substr(0, n->length)).append(rest);
    n = scan_si_number(joined, {.scale = true, .unit_letters = false});
    if (!n || !is_unit(std::string_view(joined).substr(n->length))) return false;
  }
  *out = neg ? -n->value : n->value;
  return std::isfinite(*out);
}

std::string node_kind(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsMap()) return "map";
  if (node.IsSequence()) return "list";
  return "value";
}

std::string node_text(const YAML::Node& node) {
  if (node.IsDefined() && node.IsScalar()) return node.Scalar();
  return "<" + node_kind(node) + ">";
}

StatusOr<YamlDoc> YamlDoc::load_file(const std::string& path) {
  StatusOr<std::string> text = read_input_file(path);  // size-limited; refuses folders
  if (!text) return text.status();
  return from_text(*text, path);
}

namespace {

// Every map in the tree: a key given twice is an error (yaml-cpp keeps both, and the reader
// would silently take the last).
Status check_duplicate_keys(const YamlDoc& doc, const YAML::Node& node) {
  if (node.IsMap()) {
    std::vector<std::pair<std::string, YAML::Node>> seen;
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = it->first.IsScalar() ? it->first.Scalar() : std::string();
      if (it->first.IsScalar())
        for (const auto& [k, first] : seen)
          if (k == key)
            return doc.error(it->first,
                             fmt::format("key '{}' is given twice (first at line {}); give it once",
                                         key, doc.loc(first).line));
      seen.emplace_back(key, it->first);
      if (Status s = check_duplicate_keys(doc, it->second); !s.ok()) return s;
    }
  } else if (node.IsSequence()) {
    for (const YAML::Node& item : node)
      if (Status s = check_duplicate_keys(doc, item); !s.ok()) return s;
  }
  return Status::Ok();
}

// Records where a document's first node starts (no node: an empty document), and the first alias
// of a map or list in it.
class DocumentScan : public YAML::EventHandler {
 public:
  std::optional<YAML::Mark> mark;
  std::optional<YAML::Mark> collection_alias;
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& m, YAML::anchor_t anchor) override {
    note(m);
    if (!collection_alias && collections_.count(anchor) > 0) collection_alias = m;
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t,
                const std::string&) override {
    note(m);
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    note(m);
    if (anchor != YAML::NullAnchor) collections_.insert(anchor);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    note(m);
    if (anchor != YAML::NullAnchor) collections_.insert(anchor);
  }
  void OnMapEnd() override {}

 private:
  void note(const YAML::Mark& m) {
    if (!mark) mark = m;
  }
  std::set<YAML::anchor_t> collections_;  // anchors of maps and lists
};

struct TextScan {
  std::optional<YAML::Mark> second_document;   // where a second document with content starts
  std::optional<YAML::Mark> collection_alias;  // the first alias of a map or list
};

// The events of the first document, and whether a second one has content. Not YAML::LoadAll: in
// yaml-cpp 0.7 (Debian 12) it never returns on some malformed text ("," alone), adding a null
// document per turn until memory runs out (jbeder/yaml-cpp#1040, fixed upstream by #1319 after
// 0.7; found by tests/fuzz). At most two documents are read here.
TextScan scan_text(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentScan first, second;
  TextScan out;
  if (!parser.HandleNextDocument(first)) return out;
  out.collection_alias = first.collection_alias;
  if (!parser.HandleNextDocument(second)) return out;
  out.second_document = second.mark;
  return out;
}

}  // namespace

StatusOr<YamlDoc> YamlDoc::from_text(const std::string& text, const std::string& name) {
  YamlDoc doc;
  doc.file_ = SourceFile::FromText(name, text);
  // YAML is UTF-8 text; names read here reach JSON and file names, so invalid bytes stop here.
  if (const size_t bad = invalid_utf8_at(text); bad != std::string::npos) {
    int line = 1, col = 1;
    for (size_t i = 0; i < bad; ++i) {
      if (text[i] == '\n') ++line, col = 0;
      ++col;
    }
    return error_at(SourceLoc{doc.file_, line, col},
                    fmt::format("byte 0x{:02X} is not UTF-8 text (save the file as UTF-8)",
                                static_cast<unsigned char>(text[bad])));
  }
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    return Status::Error(
        fmt::format("{}: error: a NUL byte at offset {} (is this a text file?)", name, nul));
  try {
    const TextScan scan = scan_text(text);
    // An alias of a map or list shares the node: one inside its own anchor is a cycle, and
    // nested ones multiply ("billion laughs": 30 lines, 2^30 nodes to walk). Aliases of single
    // values stay allowed.
    if (const std::optional<YAML::Mark>& m = scan.collection_alias) {
      const size_t from = static_cast<size_t>(m->pos);
      size_t end = from + 1;
      while (end < text.size() && end - from < 64 &&
             !std::isspace(static_cast<unsigned char>(text[end])) &&
             std::string_view(",]}").find(text[end]) == std::string_view::npos)
        ++end;
      return error_at(SourceLoc{doc.file_, m->line + 1, m->column + 1},
                      fmt::format("'{}' is an alias of a map or list: isolink does not share "
                                  "maps or lists between places; write it out where it is "
                                  "used (aliases of single values are allowed)",
                                  text.substr(from, end - from)));
    }
    if (const std::optional<YAML::Mark>& m = scan.second_document)
      return error_at(SourceLoc{doc.file_, m->line + 1, m->column + 1},
                      "a second YAML document ('---') in the file: isolink reads one "
                      "document per file; remove it or move it to its own file");
    doc.root_ = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    SourceLoc loc{doc.file_, e.mark.line + 1, e.mark.column + 1};
    if (e.mark.line < 0) loc.line = 0;
    return error_at(loc, "YAML syntax: " + e.msg);
  }
  if (Status s = check_duplicate_keys(doc, doc.root_); !s.ok()) return s;
  return doc;
}

namespace {

// Whether node is sub or lies inside it (node identity, not equal text).
bool inside(const YAML::Node& sub, const YAML::Node& node) {
  if (sub.is(node)) return true;
  if (sub.IsMap()) {
    for (auto it = sub.begin(); it != sub.end(); ++it)
      if (it->first.is(node) || inside(it->second, node)) return true;
  } else if (sub.IsSequence()) {
    for (const YAML::Node& child : sub)
      if (inside(child, node)) return true;
  }
  return false;
}

}  // namespace

std::shared_ptr<const SourceFile> YamlDoc::file_of(const YAML::Node& node) const {
  // Latest first: a later merge can replace part of an earlier one.
  for (auto it = overlays_.rbegin(); it != overlays_.rend(); ++it)
    if (it->file != file_ && inside(it->node, node)) return it->file;
  return file_;
}

void YamlDoc::replace(const std::string& key, const YAML::Node& value, const YamlDoc& from) {
  root_[key] = value;
  overlays_.push_back({value, from.file_});
  for (const Overlay& o : from.overlays_) overlays_.push_back(o);
}

Status YamlDoc::merge(const YAML::Node& overlay, const YamlDoc& from) {
  if (!overlay.IsDefined() || overlay.IsNull()) return Status::Ok();
  if (!root_.IsDefined() || root_.IsNull()) root_ = YAML::Node(YAML::NodeType::Map);
  if (!root_.IsMap()) return error(root_, "a map of keys is needed here to merge overrides into");
  for (const Overlay& o : from.overlays_) overlays_.push_back(o);
  return merge_map(root_, overlay, from, "");
}

Status YamlDoc::merge_map(YAML::Node target, const YAML::Node& overlay, const YamlDoc& from,
                          const std::string& path) {
  if (!overlay.IsMap())
    return from.error(overlay,
                      fmt::format("overrides{} must be a map of keys, found a {}",
                                  path.empty() ? "" : " of '" + path + "'", node_kind(overlay)));
  for (auto it = overlay.begin(); it != overlay.end(); ++it) {
    if (!it->first.IsScalar()) return from.error(it->first, "a key must be a plain value");
    const std::string key = it->first.Scalar();
    const std::string full = path.empty() ? key : path + "." + key;
    YAML::Node existing = target[key];
    if (existing.IsDefined() && existing.IsMap() && it->second.IsMap()) {
      if (Status s = merge_map(existing, it->second, from, full); !s.ok()) return s;
      continue;
    }
    if (existing.IsDefined()) {
      target[key] = it->second;
    } else {
      target.force_insert(it->first, it->second);  // keeps the key node: errors point at it
      overlays_.push_back({it->first, from.file_});
    }
    overlays_.push_back({it->second, from.file_});
  }
  return Status::Ok();
}

SourceLoc YamlDoc::loc(const YAML::Node& node) const {
  SourceLoc l{overlays_.empty() ? file_ : file_of(node), 0, 0};
  if (node.IsDefined()) {
    const YAML::Mark m = node.Mark();
    if (m.line >= 0 && !m.is_null()) l.line = m.line + 1, l.col = m.column + 1;
  }
  // A document built in memory (a Python dict) is located by key path: a "file" of that name,
  // without lines to show (config/key_path.h).
  if (l.line > 0 && is_key_path_document(*l.file))
    if (std::optional<std::string> key = key_path_at(*l.file, l.line, l.col))
      return SourceLoc{SourceFile::FromText(key->empty() ? l.file->path : *key, ""), 0, 0};
  return l;
}

Status YamlDoc::error(const YAML::Node& node, const std::string& message) const {
  return error_at(loc(node), message);
}

Status read_map(const YamlDoc& doc, const YAML::Node& node, const std::string& path,
                const std::vector<Field>& fields) {
  if (!node.IsDefined() || node.IsNull()) return Status::Ok();
  const std::string where = path.empty() ? "the top level" : "'" + path + "'";
  if (!node.IsMap())
    return doc.error(node,
                     fmt::format("{} must be a map of keys, found a {}", where, node_kind(node)));
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.Scalar();
    const std::string full = path.empty() ? key : path + "." + key;
    const Field* f = nullptr;
    for (const Field& x : fields)
      if (x.key == key) f = &x;
    if (f == nullptr) {
      std::string known;
      for (const Field& x : fields) known += (known.empty() ? "" : ", ") + x.key;
      return doc.error(it->first,
                       fmt::format("unknown key '{}' in {} (known keys: {})", full, where, known));
    }
    if (Status s = f->read(it->second, full); !s.ok()) return s;
  }
  return Status::Ok();
}

FieldReader read_quantity(const YamlDoc& doc, Unit unit, Rule rule, double* out) {
  return [&doc, unit, rule, out](const YAML::Node& n, const std::string& key) -> Status {
    double v = 0;
    const char* sym = unit_symbol(unit);
    if (!n.IsScalar() || !parse_quantity(n.Scalar(), unit, &v)) {
      std::string expect = unit == Unit::kMetre || unit == Unit::kCelsius || unit == Unit::kNone
                               ? fmt::format("a number{}{}", *sym ? " in " : "", sym)
                               : fmt::format(
                                     "a value in {} (SPICE suffixes allowed, e.g. 2.2n "
                                     "or 2.2n{})",
                                     sym, sym);
      return doc.error(n,
                       fmt::format("key '{}': expected {}, found '{}'", key, expect, node_text(n)));
    }
    if (!obeys(rule, v))
      return doc.error(n, fmt::format("key '{}' = {}: {}", key, n.Scalar(), rule_text(rule)));
    *out = v;
    return Status::Ok();
  };
}

FieldReader read_quantity(const YamlDoc& doc, Unit unit, Rule rule, std::optional<double>* out) {
  return [&doc, unit, rule, out](const YAML::Node& n, const std::string& key) -> Status {
    double v = 0;
    if (Status s = read_quantity(doc, unit, rule, &v)(n, key); !s.ok()) return s;
    *out = v;
    return Status::Ok();
  };
}

FieldReader read_text(const YamlDoc& doc, std::string* out) {
  return [&doc, out](const YAML::Node& n, const std::string& key) -> Status {
    if (!n.IsScalar())
      return doc.error(n, fmt::format("key '{}': expected text, found a {}", key, node_kind(n)));
    *out = n.Scalar();
    return Status::Ok();
  };
}

FieldReader read_choice(const YamlDoc& doc, std::vector<std::string> options, std::string* out) {
  return [&doc, options, out](const YAML::Node& n, const std::string& key) -> Status {
    std::string names;
    for (const std::string& o : options) {
      if (n.IsScalar() && lower(n.Scalar()) == o) {
        *out = o;
        return Status::Ok();
      }
      names += (names.empty() ? "" : " | ") + o;
    }
    return doc.error(n, fmt::format("key '{}': expected {}, found '{}'", key, names, node_text(n)));
  };
}

FieldReader read_bool(const YamlDoc& doc, bool* out) {
  return [&doc, out](const YAML::Node& n, const std::string& key) -> Status {
    bool b = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, b))
      return doc.error(
          n, fmt::format("key '{}': expected true or false, found '{}'", key, node_text(n)));
    *out = b;
    return Status::Ok();
  };
}

FieldReader read_int(const YamlDoc& doc, int lo, int hi, int* out) {
  return [&doc, lo, hi, out](const YAML::Node& n, const std::string& key) -> Status {
    const std::string s = n.IsScalar() ? n.Scalar() : "";
    int v = 0;
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
      return doc.error(
          n, fmt::format("key '{}': expected a whole number, found '{}'", key, node_text(n)));
    if (v < lo || v > hi)
      return doc.error(n, fmt::format("key '{}' = {}: must be in {}..{}", key, v, lo, hi));
    *out = v;
    return Status::Ok();
  };
}

FieldReader read_percent(const YamlDoc& doc, double max_percent, double* out) {
  return [&doc, max_percent, out](const YAML::Node& n, const std::string& key) -> Status {
    std::string s = n.IsScalar() ? n.Scalar() : "";
    while (!s.empty() && s.back() == ' ') s.pop_back();
    const bool has_sign = !s.empty() && s.back() == '%';
    if (has_sign) s.pop_back();
    while (!s.empty() && s.back() == ' ') s.pop_back();
    double v = 0;
    if (!has_sign || !parse_quantity(s, Unit::kNone, &v))
      return doc.error(n, fmt::format("key '{}': expected a percentage, e.g. 10%, found '{}'", key,
                                      node_text(n)));
    if (!(v >= 0 && v <= max_percent))
      return doc.error(
          n, fmt::format("key '{}' = {}: must be in 0..{:g} %", key, n.Scalar(), max_percent));
    *out = v / 100.0;
    return Status::Ok();
  };
}

FieldReader read_text_list(const YamlDoc& doc, std::vector<std::string>* out) {
  return [&doc, out](const YAML::Node& n, const std::string& key) -> Status {
    out->clear();
    if (n.IsScalar()) {
      out->push_back(n.Scalar());
      return Status::Ok();
    }
    if (!n.IsSequence())
      return doc.error(
          n, fmt::format("key '{}': expected a list of text, found a {}", key, node_kind(n)));
    for (size_t i = 0; i < n.size(); ++i) {
      if (!n[i].IsScalar())
        return doc.error(
            n[i], fmt::format("key '{}[{}]': expected text, found a {}", key, i, node_kind(n[i])));
      out->push_back(n[i].Scalar());
    }
    return Status::Ok();
  };
}

}  // namespace isolink::config
