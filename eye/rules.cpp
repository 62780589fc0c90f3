#include "eye/rules.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>

#include "base/file_io.h"

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

bool parse_spice_number(std::string_view s, double* out) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr == s.data()) return false;
  std::string rest(ptr, s.data() + s.size());
  std::transform(rest.begin(), rest.end(), rest.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  double scale = 1;
  if (rest.rfind("meg", 0) == 0) {
    scale = 1e6;
    rest.erase(0, 3);
  } else if (!rest.empty()) {
    static const std::map<char, double> kSuffix = {{'f', 1e-15}, {'p', 1e-12}, {'n', 1e-9},
                                                   {'u', 1e-6},  {'m', 1e-3},  {'k', 1e3},
                                                   {'g', 1e9},   {'t', 1e12}};
    auto it = kSuffix.find(rest[0]);
    if (it != kSuffix.end() && rest != "s" && rest != "v") {
      scale = it->second;
      rest.erase(0, 1);
    }
  }
  if (!rest.empty() && rest != "s" && rest != "v") return false;
  *out = v * scale;
  return std::isfinite(*out);
}

// Reads one YAML document into Rules, key by key, remembering each field's line.
class Parser {
 public:
  explicit Parser(std::string source) : source_(std::move(source)) {}

  Status error(const YAML::Mark& m, const std::string& msg) const {
    if (m.line < 0) return Status::Error(fmt::format("{}: error: {}", source_, msg));
    return Status::Error(fmt::format("{}:{}: error: {}", source_, m.line + 1, msg));
  }
  Status error_at_field(const std::string& field, const std::string& msg) const {
    auto it = lines_.find(field);
    if (it == lines_.end()) {
      // fall back to the section, then to the whole file
      std::string f = field;
      while (it == lines_.end()) {
        size_t dot = f.find_last_of(".[");
        if (dot == std::string::npos) break;
        f.erase(dot);
        it = lines_.find(f);
      }
    }
    if (it == lines_.end()) return Status::Error(fmt::format("{}: error: {}", source_, msg));
    return Status::Error(fmt::format("{}:{}: error: {}", source_, it->second, msg));
  }

  using Handler = std::function<Status(const YAML::Node&, const std::string&)>;
  struct Field {
    std::string key;
    Handler handle;
  };

  // Walks map node: unknown keys are errors; missing keys are errors unless a base was given.
  Status section(const YAML::Node& node, const std::string& path,
                 const std::vector<Field>& fields) {
    const std::string where = path.empty() ? "the top level" : "'" + path + "'";
    if (!node.IsMap()) return error(node.Mark(), fmt::format("{} must be a map of keys", where));
    std::vector<bool> seen(fields.size(), false);
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = it->first.Scalar();
      const std::string full = path.empty() ? key : path + "." + key;
      auto f =
          std::find_if(fields.begin(), fields.end(), [&](const Field& x) { return x.key == key; });
      if (f == fields.end()) {
        std::string known;
        for (const Field& x : fields) known += (known.empty() ? "" : ", ") + x.key;
        return error(it->first.Mark(),
                     fmt::format("unknown key '{}' in {} (known keys: {})", full, where, known));
      }
      seen[f - fields.begin()] = true;
      lines_[full] = it->first.Mark().line + 1;
      if (Status s = f->handle(it->second, full); !s.ok()) return s;
    }
    if (!has_base_)
      for (size_t i = 0; i < fields.size(); ++i)
        if (!seen[i] && fields[i].key != "base" && fields[i].key != "description" &&
            !(path.empty() && fields[i].key == "decode"))
          return error(node.Mark(),
                       fmt::format("missing key '{}{}' in {}", path.empty() ? "" : path + ".",
                                   fields[i].key, where));
    return Status::Ok();
  }

  Handler number(double* dst) {
    return [this, dst](const YAML::Node& n, const std::string& key) -> Status {
      if (!n.IsScalar() || !parse_spice_number(n.Scalar(), dst))
        return error(n.Mark(), fmt::format("key '{}': expected a number (SPICE suffixes allowed, "
                                           "e.g. 60n), found '{}'",
                                           key, n.IsScalar() ? n.Scalar() : "a " + kind(n)));
      return Status::Ok();
    };
  }
  Handler text(std::string* dst) {
    return [this, dst](const YAML::Node& n, const std::string& key) -> Status {
      if (!n.IsScalar())
        return error(n.Mark(), fmt::format("key '{}': expected text, found a {}", key, kind(n)));
      *dst = n.Scalar();
      return Status::Ok();
    };
  }
  Handler boolean(bool* dst) {
    return [this, dst](const YAML::Node& n, const std::string& key) -> Status {
      bool b = false;
      if (!n.IsScalar() || !YAML::convert<bool>::decode(n, b))
        return error(n.Mark(), fmt::format("key '{}': expected true or false, found '{}'", key,
                                           n.IsScalar() ? n.Scalar() : "a " + kind(n)));
      *dst = b;
      return Status::Ok();
    };
  }
  Handler integer(int* dst) {
    return [this, dst](const YAML::Node& n, const std::string& key) -> Status {
      const std::string s = n.IsScalar() ? n.Scalar() : "";
      int v = 0;
      auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
        return error(n.Mark(), fmt::format("key '{}': expected an integer, found '{}'", key,
                                           n.IsScalar() ? s : "a " + kind(n)));
      *dst = v;
      return Status::Ok();
    };
  }
  template <class E>
  Handler choice(E* dst, std::vector<std::pair<std::string, E>> options) {
    return [this, dst, options](const YAML::Node& n, const std::string& key) -> Status {
      std::string names;
      for (const auto& [name, value] : options) {
        if (n.IsScalar() && n.Scalar() == name) {
          *dst = value;
          return Status::Ok();
        }
        names += (names.empty() ? "" : " | ") + name;
      }
      return error(n.Mark(), fmt::format("key '{}': expected {}, found '{}'", key, names,
                                         n.IsScalar() ? n.Scalar() : "a " + kind(n)));
    };
  }

  static std::string kind(const YAML::Node& n) {
    if (n.IsMap()) return "map";
    if (n.IsSequence()) return "list";
    if (n.IsNull()) return "nothing";
    return "scalar";
  }

  StatusOr<Rules> parse(std::string_view yaml_text);

 private:
  std::string source_;
  std::map<std::string, int> lines_;
  bool has_base_ = false;
};

StatusOr<Rules> Parser::parse(std::string_view yaml_text) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::Exception& e) {
    return error(e.mark, "YAML syntax: " + e.msg);
  }
  if (!root.IsMap())
    return error(root.Mark(), "a rule file is a YAML map of keys (name, vth, timing, ...)");

  Rules r;
  if (const YAML::Node base = root["base"]) {
    const std::string base_name = base.IsScalar() ? base.Scalar() : "";
    std::string_view base_text = builtin_rule_text(base_name);
    if (base_text.empty()) {
      std::string names;
      for (const auto& n : builtin_rule_names()) names += (names.empty() ? "" : ", ") + n;
      return error(base.Mark(), fmt::format("key 'base': '{}' is not a shipped rule set ({})",
                                            base_name, names));
    }
    StatusOr<Rules> b = Parser("eye/rules/" + base_name + ".yaml").parse(base_text);
    if (!b) return b.status();
    r = *b;
    r.name = std::filesystem::path(source_).stem().string();
    has_base_ = true;
  }
  r.source = source_;

  std::string kind_name = r.tone ? "tone" : "data";
  bool decode_seen = false;
  YAML::Mark decode_mark;
  auto width_handler = [this, &r](const YAML::Node& n, const std::string& key) -> Status {
    if (!n.IsSequence())
      return error(n.Mark(),
                   fmt::format("key '{}': expected a list of {{class, min, max}}, found a {}", key,
                               kind(n)));
    r.width.clear();
    const bool had_base = has_base_;
    has_base_ = false;  // every window names all three keys
    for (size_t i = 0; i < n.size(); ++i) {
      WidthWindow w;
      const std::string path = fmt::format("{}[{}]", key, i);
      lines_[path] = n[i].Mark().line + 1;
      Status s = section(
          n[i], path, {{"class", integer(&w.k)}, {"min", number(&w.min)}, {"max", number(&w.max)}});
      if (!s.ok()) {
        has_base_ = had_base;
        return s;
      }
      r.width.push_back(w);
    }
    has_base_ = had_base;
    return Status::Ok();
  };
  auto timing = [this, &r](const YAML::Node& n, const std::string& key) {
    return section(n, key,
                   {{"pulse_time", number(&r.pulse_time)},
                    {"merge_gap", number(&r.merge_gap)},
                    {"min_pulse", number(&r.min_pulse)},
                    {"transition_gap", number(&r.transition_gap)},
                    {"edge_max", number(&r.edge_max)},
                    {"vend_offset", number(&r.vend_offset)}});
  };
  auto amplitude = [&, this](const YAML::Node& n, const std::string& key) -> Status {
    // the rule decides which keys exist, so read it first
    if (n.IsMap())
      if (const YAML::Node rn = n["rule"]) {
        if (Status s = choice(&r.amplitude,
                              {std::pair{std::string("bq7961x"), AmplitudeRule::kBq7961x},
                               {std::string("bridge"), AmplitudeRule::kBridge}})(rn, key + ".rule");
            !s.ok())
          return s;
      }
    std::vector<Field> fields = {
        {"rule", [](const YAML::Node&, const std::string&) { return Status::Ok(); }},
        {"vend_min", number(&r.vend_min)},
        {"vstart_min", number(&r.vstart_min)},
        {"droop_max", number(&r.droop_max)}};
    if (r.amplitude == AmplitudeRule::kBq7961x) {
      fields.push_back({"vend_knee", number(&r.vend_knee)});
      fields.push_back({"vstart_min_low_vend", number(&r.vstart_min_low_vend)});
    }
    return section(n, key, fields);
  };
  auto idle = [this, &r](const YAML::Node& n, const std::string& key) {
    return section(n, key, {{"level", number(&r.idle_level)}, {"tblank", number(&r.tblank)}});
  };
  auto decode = [&, this](const YAML::Node& n, const std::string& key) -> Status {
    decode_seen = true;
    decode_mark = n.Mark();
    return section(n, key,
                   {{"sof", boolean(&r.frame.sof)},
                    {"sof_value", integer(&r.frame.sof_value)},
                    {"bit_order",
                     choice(&r.frame.bit_order, {std::pair{std::string("lsb"), BitOrder::kLsbFirst},
                                                 {std::string("msb"), BitOrder::kMsbFirst}})}});
  };
  const bool base_given = has_base_;
  Status s =
      section(root, "",
              {{"base", [](const YAML::Node&, const std::string&) { return Status::Ok(); }},
               {"name", text(&r.name)},
               {"description", text(&r.description)},
               {"kind", choice(&kind_name, {std::pair{std::string("data"), std::string("data")},
                                            {std::string("tone"), std::string("tone")}})},
               {"vth", number(&r.vth)},
               {"timing", timing},
               {"width", width_handler},
               {"amplitude", amplitude},
               {"idle", idle},
               {"decode", decode}});
  if (!s.ok()) return s;
  r.tone = kind_name == "tone";
  if (r.tone && decode_seen)
    return error(decode_mark,
                 "key 'decode': only data rules decode bytes (this one is kind: tone)");
  if (!r.tone && !decode_seen && !base_given)
    return error(root.Mark(), "missing key 'decode' at the top level (needed for kind: data)");
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
  if (std::string_view text = builtin_rule_text(name_or_path); !text.empty())
    return parse_rules(text, "eye/rules/" + name_or_path + ".yaml");
  if (!std::filesystem::exists(name_or_path)) {
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
