#include "eye/rules.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <optional>

#include "base/file_io.h"
#include "config/yaml_reader.h"

namespace isolink::eye {
namespace detail {
const std::vector<std::pair<std::string_view, std::string_view>>& builtin_rule_texts();
}  // namespace detail

namespace {

std::string num_str(double v) {
  return fmt::format("{:g}", v);
}

// A broken limit: the field (dotted path) and what is wrong with it.
struct Issue {
  std::string field;
  std::string message;
};

std::optional<Issue> find_issue(const Rules& r) {
  auto positive = [](const char* field, double v) -> std::optional<Issue> {
    if (!(v > 0)) return Issue{field, fmt::format("{} = {}: must be > 0", field, num_str(v))};
    return std::nullopt;
  };
  if (r.name.empty()) return Issue{"name", "name is empty: a rule set needs a name"};
  for (auto [f, v] : {std::pair{"vth", r.vth},
                      {"timing.pulse_time", r.pulse_time},
                      {"timing.min_pulse", r.min_pulse},
                      {"timing.transition_gap", r.transition_gap},
                      {"timing.edge_max", r.edge_max},
                      {"amplitude.vend_min", r.vend_min},
                      {"amplitude.vstart_min", r.vstart_min},
                      {"amplitude.droop_max", r.droop_max},
                      {"idle.level", r.idle_level},
                      {"idle.tblank", r.tblank}})
    if (auto i = positive(f, v)) return i;
  if (!(r.merge_gap >= 0))
    return Issue{"timing.merge_gap",
                 fmt::format("timing.merge_gap = {}: must be >= 0", num_str(r.merge_gap))};
  if (!(r.vend_offset >= 0) || !(r.vend_offset < r.min_pulse))
    return Issue{"timing.vend_offset",
                 fmt::format("timing.vend_offset = {}: must be >= 0 and < timing.min_pulse = {} "
                             "(so VEND is read inside every pulse)",
                             num_str(r.vend_offset), num_str(r.min_pulse))};
  if (!(r.idle_level < r.vth))
    return Issue{"idle.level", fmt::format("idle.level = {}: must be below vth = {}",
                                           num_str(r.idle_level), num_str(r.vth))};
  if (r.width.empty()) return Issue{"width", "width: at least one class window is needed"};
  for (size_t i = 0; i < r.width.size(); ++i) {
    const WidthWindow& w = r.width[i];
    const std::string f = fmt::format("width[{}]", i);
    if (w.k < 1) return Issue{f + ".class", fmt::format("{}.class = {}: must be >= 1", f, w.k)};
    if (!(w.min > 0))
      return Issue{f + ".min", fmt::format("{}.min = {}: must be > 0", f, num_str(w.min))};
    if (!(w.min < w.max))
      return Issue{f + ".max", fmt::format("{}: min {} >= max {}: a window needs min < max", f,
                                           num_str(w.min), num_str(w.max))};
    const double lo = (w.k - 0.5) * r.pulse_time, hi = (w.k + 0.5) * r.pulse_time;
    if (!(w.min > lo) || !(w.max < hi))
      return Issue{f + ".min",
                   fmt::format("{}: window {}..{} for class {} must lie inside ({}, {}) = "
                               "(k - 1/2, k + 1/2) * pulse_time, so that round(width / T) = k",
                               f, num_str(w.min), num_str(w.max), w.k, num_str(lo), num_str(hi))};
    for (size_t j = 0; j < i; ++j)
      if (r.width[j].k == w.k)
        return Issue{f + ".class", fmt::format("{}.class = {}: class listed twice", f, w.k)};
  }
  if (r.amplitude == AmplitudeRule::kBq7961x) {
    if (!(r.vend_knee >= r.vend_min))
      return Issue{"amplitude.vend_knee",
                   fmt::format("amplitude.vend_knee = {}: must be >= amplitude.vend_min = {}",
                               num_str(r.vend_knee), num_str(r.vend_min))};
    if (!(r.vstart_min_low_vend >= r.vstart_min))
      return Issue{"amplitude.vstart_min_low_vend",
                   fmt::format("amplitude.vstart_min_low_vend = {}: must be >= "
                               "amplitude.vstart_min = {} (a lower VEND needs more start)",
                               num_str(r.vstart_min_low_vend), num_str(r.vstart_min))};
  }
  if (r.frame.sof_value != 0 && r.frame.sof_value != 1)
    return Issue{"decode.sof_value",
                 fmt::format("decode.sof_value = {}: must be 0 or 1", r.frame.sof_value)};
  return std::nullopt;
}

// Reads one YAML document into Rules, key by key, through config's reader (config/yaml_reader.h:
// file:line:col diagnostics, SPICE numbers with units, duplicate keys refused). What it adds:
// every key is required unless the file names a base, and the limits are checked last.
class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}

  using Handler = config::FieldReader;
  using Field = config::Field;

  // Walks a map: unknown keys are errors; missing keys are errors unless a base was given.
  Status section(const YAML::Node& node, const std::string& path,
                 const std::vector<Field>& fields) {
    const std::string where = path.empty() ? "the top level" : "'" + path + "'";
    if (!node.IsMap())
      return doc_->error(node, fmt::format("{} must be a map of keys, found a {}", where,
                                           config::node_kind(node)));
    for (auto it = node.begin(); it != node.end(); ++it)
      nodes_[path.empty() ? it->first.Scalar() : path + "." + it->first.Scalar()] = it->first;
    if (Status s = config::read_map(*doc_, node, path, fields); !s.ok()) return s;
    if (!has_base_)
      for (const Field& f : fields)
        if (!node[f.key] && f.key != "base" && f.key != "description" &&
            !(path.empty() && f.key == "decode"))
          return doc_->error(node, fmt::format("missing key '{}{}' in {}",
                                               path.empty() ? "" : path + ".", f.key, where));
    return Status::Ok();
  }
  // An error at the line of field (a dotted path), else of its section, else of the file.
  Status error_at_field(const std::string& field, const std::string& msg) const {
    std::string f = field;
    auto it = nodes_.find(f);
    while (it == nodes_.end()) {
      const size_t dot = f.find_last_of(".[");
      if (dot == std::string::npos) break;
      f.erase(dot);
      it = nodes_.find(f);
    }
    if (it == nodes_.end()) return Status::Error(fmt::format("{}: error: {}", source_, msg));
    return doc_->error(it->second, msg);
  }

  // Times in seconds, levels in volts: SPICE suffixes and the unit symbol ("60n", "60ns").
  Handler seconds(double* dst) {
    return config::read_quantity(*doc_, config::Unit::kSecond, config::Rule::kAny, dst);
  }
  Handler volts(double* dst) {
    return config::read_quantity(*doc_, config::Unit::kVolt, config::Rule::kAny, dst);
  }
  Handler text(std::string* dst) { return config::read_text(*doc_, dst); }
  Handler boolean(bool* dst) { return config::read_bool(*doc_, dst); }
  // Any whole number; the ranges are limits that find_issue checks with the rule's wording.
  Handler integer(int* dst) {
    return config::read_int(*doc_, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
                            dst);
  }
  template <class E>
  Handler choice(E* dst, std::vector<std::pair<std::string, E>> options) {
    return [this, dst, options](const YAML::Node& n, const std::string& key) -> Status {
      std::vector<std::string> names;
      for (const auto& [name, value] : options) names.push_back(name);
      std::string picked;
      if (Status s = config::read_choice(*doc_, names, &picked)(n, key); !s.ok()) return s;
      for (const auto& [name, value] : options)
        if (name == picked) *dst = value;
      return Status::Ok();
    };
  }

  StatusOr<Rules> parse(std::string_view yaml_text);

 private:
  // key 'base': the shipped rule set the file's keys override, into *r.
  Status read_base(const YAML::Node& base, Rules* r);
  // key 'width': the list of {class, min, max} windows (each names all three keys).
  Status read_width(const YAML::Node& n, const std::string& key, Rules* r);
  // key 'amplitude': the rule first (it decides which keys exist), then its levels.
  Status read_amplitude(const YAML::Node& n, const std::string& key, Rules* r);

  std::string source_;
  const config::YamlDoc* doc_ = nullptr;
  std::map<std::string, YAML::Node> nodes_;  // dotted key path -> its key node, for errors
  bool has_base_ = false;
};

Status Parser::read_base(const YAML::Node& base, Rules* r) {
  const std::string base_name = base.IsScalar() ? base.Scalar() : "";
  std::string_view base_text = builtin_rule_text(base_name);
  if (base_text.empty()) {
    std::string names;
    for (const auto& n : builtin_rule_names()) names += (names.empty() ? "" : ", ") + n;
    return doc_->error(
        base, fmt::format("key 'base': '{}' is not a shipped rule set ({})", base_name, names));
  }
  StatusOr<Rules> b = Parser("eye/rules/" + base_name + ".yaml").parse(base_text);
  if (!b) return b.status();
  *r = *b;
  r->name = std::filesystem::path(source_).stem().string();
  has_base_ = true;
  return Status::Ok();
}

Status Parser::read_width(const YAML::Node& n, const std::string& key, Rules* r) {
  if (!n.IsSequence())
    return doc_->error(n, fmt::format("key '{}': expected a list of {{class, min, max}}, "
                                      "found a {}",
                                      key, config::node_kind(n)));
  r->width.clear();
  const bool had_base = has_base_;
  has_base_ = false;  // every window names all three keys
  for (size_t i = 0; i < n.size(); ++i) {
    WidthWindow w;
    const std::string path = fmt::format("{}[{}]", key, i);
    nodes_[path] = n[i];
    Status s = section(
        n[i], path, {{"class", integer(&w.k)}, {"min", seconds(&w.min)}, {"max", seconds(&w.max)}});
    if (!s.ok()) {
      has_base_ = had_base;
      return s;
    }
    r->width.push_back(w);
  }
  has_base_ = had_base;
  return Status::Ok();
}

Status Parser::read_amplitude(const YAML::Node& n, const std::string& key, Rules* r) {
  if (n.IsMap())
    if (const YAML::Node rn = n["rule"]) {
      if (Status s = choice(&r->amplitude,
                            {std::pair{std::string("bq7961x"), AmplitudeRule::kBq7961x},
                             {std::string("bridge"), AmplitudeRule::kBridge}})(rn, key + ".rule");
          !s.ok())
        return s;
    }
  std::vector<Field> fields = {
      {"rule", [](const YAML::Node&, const std::string&) { return Status::Ok(); }},
      {"vend_min", volts(&r->vend_min)},
      {"vstart_min", volts(&r->vstart_min)},
      {"droop_max", volts(&r->droop_max)}};
  if (r->amplitude == AmplitudeRule::kBq7961x) {
    fields.push_back({"vend_knee", volts(&r->vend_knee)});
    fields.push_back({"vstart_min_low_vend", volts(&r->vstart_min_low_vend)});
  }
  return section(n, key, fields);
}

StatusOr<Rules> Parser::parse(std::string_view yaml_text) {
  StatusOr<config::YamlDoc> loaded = config::YamlDoc::from_text(std::string(yaml_text), source_);
  if (!loaded) return loaded.status();
  const config::YamlDoc& doc = *loaded;
  doc_ = &doc;
  const YAML::Node& root = doc.root();
  if (!root.IsMap())
    return doc.error(root, "a rule file is a YAML map of keys (name, vth, timing, ...)");

  Rules r;
  if (const YAML::Node base = root["base"])
    if (Status s = read_base(base, &r); !s.ok()) return s;
  r.source = source_;

  std::string kind_name = r.tone ? "tone" : "data";
  bool decode_seen = false;
  YAML::Node decode_node;
  auto timing = [this, &r](const YAML::Node& n, const std::string& key) {
    return section(n, key,
                   {{"pulse_time", seconds(&r.pulse_time)},
                    {"merge_gap", seconds(&r.merge_gap)},
                    {"min_pulse", seconds(&r.min_pulse)},
                    {"transition_gap", seconds(&r.transition_gap)},
                    {"edge_max", seconds(&r.edge_max)},
                    {"vend_offset", seconds(&r.vend_offset)}});
  };
  auto idle = [this, &r](const YAML::Node& n, const std::string& key) {
    return section(n, key, {{"level", volts(&r.idle_level)}, {"tblank", seconds(&r.tblank)}});
  };
  auto decode = [&, this](const YAML::Node& n, const std::string& key) -> Status {
    decode_seen = true;
    decode_node = n;
    return section(n, key,
                   {{"sof", boolean(&r.frame.sof)},
                    {"sof_value", integer(&r.frame.sof_value)},
                    {"bit_order",
                     choice(&r.frame.bit_order, {std::pair{std::string("lsb"), BitOrder::kLsbFirst},
                                                 {std::string("msb"), BitOrder::kMsbFirst}})}});
  };
  const bool base_given = has_base_;
  Status s = section(
      root, "",
      {{"base", [](const YAML::Node&, const std::string&) { return Status::Ok(); }},
       {"name", text(&r.name)},
       {"description", text(&r.description)},
       {"kind", choice(&kind_name, {std::pair{std::string("data"), std::string("data")},
                                    {std::string("tone"), std::string("tone")}})},
       {"vth", volts(&r.vth)},
       {"timing", timing},
       {"width",
        [this, &r](const YAML::Node& n, const std::string& key) { return read_width(n, key, &r); }},
       {"amplitude", [this, &r](const YAML::Node& n,
                                const std::string& key) { return read_amplitude(n, key, &r); }},
       {"idle", idle},
       {"decode", decode}});
  if (!s.ok()) return s;
  r.tone = kind_name == "tone";
  if (r.tone && decode_seen)
    return doc.error(decode_node,
                     "key 'decode': only data rules decode bytes (this one is kind: tone)");
  if (!r.tone && !decode_seen && !base_given)
    return doc.error(root, "missing key 'decode' at the top level (needed for kind: data)");
  if (std::optional<Issue> issue = find_issue(r))
    return error_at_field(issue->field, issue->message);
  return r;
}

}  // namespace

double Rules::vstart_required(double vend) const {
  if (amplitude == AmplitudeRule::kBridge) return vstart_min;
  return vend > vend_knee ? vstart_min : vstart_min_low_vend;
}

const WidthWindow* Rules::window(int k) const {
  for (const WidthWindow& w : width)
    if (w.k == k) return &w;
  return nullptr;
}

std::vector<std::string> builtin_rule_names() {
  std::vector<std::string> names;
  for (const auto& [name, text] : detail::builtin_rule_texts()) names.emplace_back(name);
  std::sort(names.begin(), names.end());
  return names;
}

std::string_view builtin_rule_text(std::string_view name) {
  for (const auto& [n, text] : detail::builtin_rule_texts())
    if (n == name) return text;
  return {};
}

StatusOr<Rules> parse_rules(std::string_view yaml_text, const std::string& source) {
  return Parser(source).parse(yaml_text);
}

StatusOr<Rules> load_rules(const std::string& name_or_path) {
  if (std::string_view text = builtin_rule_text(name_or_path); !text.empty()) {
    // The shipped sets are embedded and never change: each is parsed once (0.25 ms of YAML,
    // three times per sweep point otherwise) and copied out.
    static std::mutex mu;
    static std::map<std::string, Rules, std::less<>> parsed;
    std::lock_guard<std::mutex> lock(mu);
    if (auto it = parsed.find(name_or_path); it != parsed.end()) return it->second;
    StatusOr<Rules> r = parse_rules(text, "eye/rules/" + name_or_path + ".yaml");
    if (r) parsed.emplace(name_or_path, *r);
    return r;
  }
  std::error_code ec;  // a name too long for a path is "no such rule set", not an exception
  if (!std::filesystem::exists(name_or_path, ec)) {
    std::string names;
    for (const auto& n : builtin_rule_names()) names += (names.empty() ? "" : ", ") + n;
    return Status::Error(
        fmt::format("{}: error: no such rule set: not a shipped name ({}) and "
                    "not a readable file",
                    name_or_path, names));
  }
  StatusOr<std::string> text = read_input_file(name_or_path);  // size-limited; refuses folders
  if (!text) return text.status();
  return parse_rules(*text, name_or_path);
}

Status validate_rules(const Rules& r) {
  if (std::optional<Issue> issue = find_issue(r))
    return Status::Error("rules '" + r.name + "': " + issue->message);
  return Status::Ok();
}

}  // namespace isolink::eye
