#include "analysis/sweep_spec.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <random>

#include "base/file_io.h"
#include "base/si_number.h"

namespace isolink::analysis::sweep {

using config::Unit;
using config::YamlDoc;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : path) {
    if (c == '.') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

std::string last_key(const std::string& path) {
  const size_t dot = path.rfind('.');
  return dot == std::string::npos ? path : path.substr(dot + 1);
}

// A pack sweep's key: "hops.3.cable.length" -> {3, "cable.length"}, "hops.*.x" -> {0, "x"};
// anything else (a link spec's key, or a malformed hop key) -> {-1, path}.
struct HopPath {
  int hop = -1;
  std::string path;
};
HopPath hop_path(const std::string& path) {
  if (path.rfind("hops.", 0) != 0) return {-1, path};
  const size_t dot = path.find('.', 5);
  if (dot == std::string::npos || dot + 1 == path.size()) return {-1, path};
  const std::string k = path.substr(5, dot - 5);
  if (k == "*") return {0, path.substr(dot + 1)};
  if (k.empty() || k.size() > 4 || k.find_first_not_of("0123456789") != std::string::npos ||
      k[0] == '0')
    return {-1, path};
  return {std::stoi(k), path.substr(dot + 1)};
}

// "ends.x" -> tx.x and rx.x (also after a pack's "hops.K."); anything else as it is.
std::vector<std::string> expand_ends(const std::string& path) {
  const HopPath h = hop_path(path);
  const std::string prefix = h.hop >= 0 ? path.substr(0, path.size() - h.path.size()) : "";
  const std::string rest = h.hop >= 0 ? h.path : path;
  if (rest.rfind("ends.", 0) == 0)
    return {prefix + "tx." + rest.substr(5), prefix + "rx." + rest.substr(5)};
  return {path};
}

// The message of a diagnostic without its "file:line:col: error: " prefix and source lines.
std::string bare_message(const std::string& diagnostic) {
  std::string first = diagnostic.substr(0, diagnostic.find('\n'));
  const size_t e = first.find("error: ");
  return e == std::string::npos ? first : first.substr(e + 7);
}

std::string num_text(double v) {
  return fmt::format("{:.6g}", v);
}

// The spec document of the base (a fresh parse: nodes keep their positions, nothing is shared
// between points or threads).
StatusOr<YamlDoc> base_doc(const SweepSpec& s) {
  StatusOr<YamlDoc> doc = YamlDoc::from_text(s.base_text, s.base_path);
  if (!doc) return doc.status();
  if (s.base_inline) {
    YAML::Node base = doc->root()["base"];
    doc->root().reset(base);
  }
  return doc;
}

// Sets root.<path> = value, creating maps on the way.
Status set_path(YAML::Node root, const std::string& path, const Assignment& a) {
  const std::vector<std::string> keys = split_path(path);
  YAML::Node cur;
  cur.reset(root);
  std::string walked;
  for (size_t i = 0; i + 1 < keys.size(); ++i) {
    walked += (walked.empty() ? "" : ".") + keys[i];
    if (!cur.IsMap() && !cur.IsNull())
      return Status::Error(
          fmt::format("key '{}' is a {}, not a map of keys", walked, config::node_kind(cur)));
    YAML::Node next = cur[keys[i]];
    if (!next.IsDefined() || next.IsNull()) {
      cur[keys[i]] = YAML::Node(YAML::NodeType::Map);
      next.reset(cur[keys[i]]);
    } else if (!next.IsMap()) {
      return Status::Error(
          fmt::format("key '{}' is a {}, not a map of keys", walked, config::node_kind(next)));
    }
    cur.reset(next);
  }
  if (!cur.IsMap() && !cur.IsNull())
    return Status::Error(
        fmt::format("key '{}' is a {}, not a map of keys", walked, config::node_kind(cur)));
  YAML::Node value;
  if (a.scalar) {
    value = YAML::Node(a.yaml);
  } else {
    try {
      value = YAML::Load(a.yaml);
    } catch (const YAML::Exception& e) {
      return Status::Error(fmt::format("key '{}': {}", path, e.msg));
    }
  }
  cur[keys.back()] = value;
  return Status::Ok();
}

Status apply(YAML::Node root, const std::vector<Assignment>& assign) {
  for (const Assignment& a : assign)
    if (Status st = set_path(root, a.path, a); !st.ok()) return st;
  return Status::Ok();
}

// The base with assign applied: a link spec, or for a pack sweep the pack, each "hops.K." /
// "hops.*." assignment set in its hops' link spec trees as the pack is read.
struct Built {
  link::LinkSpec spec;
  std::optional<PackSpec> pack;
};
StatusOr<Built> build(const SweepSpec& s, const std::vector<Assignment>& assign) {
  Built out;
  if (s.pack) {
    const HopEdit edit = [&assign](int hop, YamlDoc& doc) -> Status {
      for (const Assignment& a : assign) {
        const HopPath h = hop_path(a.path);
        if (h.hop != 0 && h.hop != hop) continue;
        if (Status st = set_path(doc.root(), h.path, a); !st.ok())
          return st.with_context(fmt::format("hop {}", hop));
      }
      return Status::Ok();
    };
    StatusOr<PackSpec> p = read_pack_spec_text(s.base_text, s.base_path, edit);
    if (!p) return p.status();
    out.pack = std::move(*p);
    return out;
  }
  StatusOr<YamlDoc> doc = base_doc(s);
  if (!doc) return doc.status();
  if (Status st = apply(doc->root(), assign); !st.ok()) return st;
  StatusOr<link::LinkSpec> spec = link::read_link_spec(*doc);
  if (!spec) return spec.status();
  out.spec = std::move(*spec);
  return out;
}

// A pack sweep's key must address a hop of the pack: hops.<K>.<key> or hops.*.<key>.
Status check_hop_key(const SweepSpec& s, const YamlDoc& doc, const YAML::Node& key_node,
                     const std::string& key, const std::vector<Assignment>& assign) {
  if (!s.pack) return Status::Ok();
  const std::string usage = fmt::format(
      "a pack sweep's keys address hops: hops.<K>.<link-spec key> with K = 1..{}{}, or "
      "hops.*.<key> for every hop",
      s.pack_hops, s.pack_ring ? fmt::format(" ({} is the ring's return hop)", s.pack_hops) : "");
  for (const Assignment& a : assign) {
    const HopPath h = hop_path(a.path);
    if (h.hop < 0) return doc.error(key_node, fmt::format("sweep key '{}': {}", key, usage));
    if (h.hop > s.pack_hops)
      return doc.error(key_node,
                       fmt::format("sweep key '{}': hop {} is not in the pack ({} hops): {}", key,
                                   h.hop, s.pack_hops, usage));
  }
  return Status::Ok();
}

// A value node of the sweep file as an assignment to each of paths.
std::vector<Assignment> assignments(const std::vector<std::string>& paths, const YAML::Node& v) {
  std::vector<Assignment> out;
  for (const std::string& p : paths) {
    Assignment a;
    a.path = p;
    if (v.IsScalar()) {
      a.yaml = v.Scalar();
    } else {
      YAML::Emitter em;
      em << v;
      a.yaml = em.c_str();
      a.scalar = false;
    }
    out.push_back(std::move(a));
  }
  return out;
}

bool is_unknown_key_error(const std::string& msg, const std::vector<Assignment>& assign) {
  for (const Assignment& a : assign) {
    const std::vector<std::string> keys = split_path(hop_path(a.path).path);
    std::string prefix;
    for (const std::string& k : keys) {
      prefix += (prefix.empty() ? "" : ".") + k;
      if (msg.find("unknown key '" + prefix + "'") != std::string::npos) return true;
    }
    if (msg.find("not a map of keys") != std::string::npos) return true;
  }
  return false;
}

// Checks that assign applied to the base spec reads: an unknown key is reported at key_node,
// anything else at value_node.
Status check_value(const SweepSpec& s, const YamlDoc& sweep_doc, const std::string& key,
                   const std::vector<Assignment>& assign, const YAML::Node& key_node,
                   const YAML::Node& value_node, const std::string& value_text) {
  if (Status st = check_hop_key(s, sweep_doc, key_node, key, assign); !st.ok()) return st;
  StatusOr<Built> built = build(s, assign);
  if (built) return Status::Ok();
  const Status st = built.status();
  const std::string msg = bare_message(st.message());
  if (is_unknown_key_error(msg, assign))
    return sweep_doc.error(key_node,
                           fmt::format("sweep key '{}' is not a link-spec key: {}", key, msg));
  return sweep_doc.error(value_node, fmt::format("sweep key '{}': value {} does not make a valid "
                                                 "spec: {}",
                                                 key, value_text, msg));
}

bool parse_number_for(const std::string& path, const std::string& text, double* out) {
  const Unit u = key_unit(path);
  if (u != Unit::kNone) return config::parse_quantity(text, u, out);
  double v = 0;
  if (!parse_si_number(text, v)) return false;
  *out = v;
  return true;
}

bool is_integer_key(const std::string& path) {
  const std::string k = last_key(path);
  return k == "gauge" || k == "segments";
}

// A "10%" text -> 0.1.
bool parse_percent(const std::string& text, double* out) {
  std::string t = text;
  while (!t.empty() && t.back() == ' ') t.pop_back();
  if (t.empty() || t.back() != '%') return false;
  t.pop_back();
  double v = 0;
  if (!config::parse_quantity(t, Unit::kNone, &v) || v < 0) return false;
  *out = v / 100.0;
  return true;
}

// One listed value of a swept key (a scalar, or a map or list given as it is).
Status add_listed_value(const SweepSpec& s, const YamlDoc& doc, const YAML::Node& key_node,
                        const std::vector<std::string>& paths, const YAML::Node& n, Axis* axis) {
  const std::string& key = axis->key;
  AxisValue av;
  av.line = doc.loc(n).line;
  av.assign = assignments(paths, n);
  std::string shown = n.IsScalar() ? "'" + n.Scalar() + "'" : "<" + config::node_kind(n) + ">";
  if (n.IsScalar()) {
    double x = 0;
    if (parse_number_for(key, n.Scalar(), &x)) {
      av.number = x;
      av.label = num_text(x);
    } else {
      av.label = n.Scalar();
    }
  } else {
    YAML::Emitter em;
    em << YAML::Flow << n;
    av.label = em.c_str();
  }
  if (Status st = check_value(s, doc, key, av.assign, key_node, n, shown); !st.ok()) return st;
  axis->values.push_back(std::move(av));
  return Status::Ok();
}

// A range {from, to, steps, scale}: steps values, linear or logarithmic.
Status read_range(const SweepSpec& s, const YamlDoc& doc, const YAML::Node& key_node,
                  const std::vector<std::string>& paths, const YAML::Node& v, Axis* axis) {
  const std::string& key = axis->key;
  std::string from_text, to_text, scale = "lin";
  int steps = 0;
  Status st = config::read_map(
      doc, v, "sweep." + key,
      {
          {"from", config::read_text(doc, &from_text)},
          {"to", config::read_text(doc, &to_text)},
          {"steps",
           [&](const YAML::Node& n, const std::string& p) -> Status {
             const std::string t = n.IsScalar() ? n.Scalar() : "";
             char* end = nullptr;
             const long x = std::strtol(t.c_str(), &end, 10);
             if (t.empty() || *end != '\0' || x < 1 || x > 100000)
               return doc.error(n, fmt::format("key '{}': steps must be a whole number from 1 "
                                               "to 100000, found '{}'",
                                               p, config::node_text(n)));
             steps = static_cast<int>(x);
             return Status::Ok();
           }},
          {"scale", config::read_choice(doc, {"lin", "log"}, &scale)},
      });
  if (!st.ok()) return st;
  for (const char* k : {"from", "to", "steps"})
    if (!v[k])
      return doc.error(v, fmt::format("sweep key '{}': a range needs from, to and steps "
                                      "(missing '{}')",
                                      key, k));
  const std::string in_unit =
      axis->unit == Unit::kNone ? "" : fmt::format(" in {}", config::unit_symbol(axis->unit));
  double from = 0, to = 0;
  if (!parse_number_for(key, from_text, &from))
    return doc.error(v["from"], fmt::format("sweep key '{}': from: expected a number{}, found "
                                            "'{}'",
                                            key, in_unit, from_text));
  if (!parse_number_for(key, to_text, &to))
    return doc.error(v["to"], fmt::format("sweep key '{}': to: expected a number{}, found '{}'",
                                          key, in_unit, to_text));
  axis->log = scale == "log";
  if (axis->log && (from <= 0 || to <= 0))
    return doc.error(v["scale"] ? v["scale"] : v,
                     fmt::format("sweep key '{}': a log range needs from and to > 0 (from {}, "
                                 "to {})",
                                 key, from_text, to_text));
  for (double x : range_values(from, to, steps, axis->log)) {
    AxisValue av;
    av.number = x;
    av.label = num_text(x);
    const std::string text = is_integer_key(key) ? fmt::format("{}", std::lround(x)) : num_text(x);
    YAML::Node n(text);
    av.assign = assignments(paths, n);
    if (Status e = check_value(s, doc, key, av.assign, key_node, v, text); !e.ok()) return e;
    axis->values.push_back(std::move(av));
  }
  return Status::Ok();
}

// Named variants: NAME: {dotted.key: value, ...}.
Status read_variants(const SweepSpec& s, const YamlDoc& doc, const YAML::Node& v, Axis* axis) {
  const std::string& key = axis->key;
  axis->variants = true;
  axis->unit = Unit::kNone;
  for (auto it = v.begin(); it != v.end(); ++it) {
    const std::string name = it->first.Scalar();
    const YAML::Node body = it->second;
    if (!body.IsMap() || body.size() == 0)
      return doc.error(it->second.IsDefined() && !body.IsNull() ? body : it->first,
                       fmt::format("sweep key '{}': variant '{}' must be a map of dotted spec "
                                   "keys to values (a range takes from, to, steps)",
                                   key, name));
    AxisValue av;
    av.label = name;
    av.line = doc.loc(it->first).line;
    for (auto jt = body.begin(); jt != body.end(); ++jt) {
      const std::string sub = jt->first.Scalar();
      std::vector<Assignment> a = assignments(expand_ends(sub), jt->second);
      const std::string shown = jt->second.IsScalar() ? "'" + jt->second.Scalar() + "'"
                                                      : "<" + config::node_kind(jt->second) + ">";
      if (Status st = check_value(s, doc, sub, a, jt->first, jt->second, shown); !st.ok())
        return st;
      av.assign.insert(av.assign.end(), a.begin(), a.end());
    }
    if (Status st = check_value(s, doc, key, av.assign, it->first, it->first, "'" + name + "'");
        !st.ok())
      return st;
    axis->values.push_back(std::move(av));
  }
  return Status::Ok();
}

Status read_axis(const SweepSpec& s, const YamlDoc& doc, const YAML::Node& key_node,
                 const YAML::Node& v, Axis* axis) {
  const std::string key = key_node.Scalar();
  axis->key = key;
  axis->line = doc.loc(key_node).line;
  const std::vector<std::string> paths = expand_ends(key);
  axis->unit = key_unit(key);
  if (v.IsSequence()) {
    if (v.size() == 0) return doc.error(v, fmt::format("sweep key '{}': the list is empty", key));
    for (size_t i = 0; i < v.size(); ++i)
      if (Status st = add_listed_value(s, doc, key_node, paths, v[i], axis); !st.ok()) return st;
    return Status::Ok();
  }
  if (v.IsScalar()) return add_listed_value(s, doc, key_node, paths, v, axis);
  if (!v.IsMap())
    return doc.error(key_node, fmt::format("sweep key '{}' has no values: give a list, a range "
                                           "{{from, to, steps, scale}} or named variants",
                                           key));
  if (v["from"] || v["to"] || v["steps"]) return read_range(s, doc, key_node, paths, v, axis);
  return read_variants(s, doc, v, axis);
}

Status read_tolerance(const SweepSpec& s, const YamlDoc& doc, const link::LinkSpec& base,
                      const YAML::Node& key_node, const YAML::Node& v, Tolerance* t) {
  const std::string key = key_node.Scalar();
  t->key = key;
  t->paths = expand_ends(key);
  t->unit = key_unit(key);
  t->integer = is_integer_key(key);
  t->line = doc.loc(key_node).line;
  // The key must be numeric in the spec: a probe value through the spec reader.
  {
    std::optional<double> nominal = spec_number(base, t->paths[0]);
    YAML::Node probe(num_text(nominal.value_or(1.0)));
    if (t->integer) probe = YAML::Node(fmt::format("{}", std::lround(nominal.value_or(24))));
    if (Status st = check_value(s, doc, key, assignments(t->paths, probe), key_node, key_node,
                                "'" + probe.Scalar() + "'");
        !st.ok())
      return st;
  }
  const std::string usage =
      "a tolerance is '10%' (uniform within +/-10 %), {normal: 10%} (sigma = 10 %/3), "
      "{normal: [mean, sigma]} or {uniform: [lo, hi]}";
  double pct = 0;
  auto pair = [&](const YAML::Node& n, double* a, double* b) -> Status {
    if (!n.IsSequence() || n.size() != 2 || !n[0].IsScalar() || !n[1].IsScalar())
      return doc.error(n, fmt::format("tolerance '{}': {}", key, usage));
    if (!parse_number_for(key, n[0].Scalar(), a))
      return doc.error(
          n[0], fmt::format("tolerance '{}': expected a number, found '{}'", key, n[0].Scalar()));
    if (!parse_number_for(key, n[1].Scalar(), b))
      return doc.error(
          n[1], fmt::format("tolerance '{}': expected a number, found '{}'", key, n[1].Scalar()));
    return Status::Ok();
  };
  if (v.IsScalar()) {
    if (!parse_percent(v.Scalar(), &pct))
      return doc.error(v, fmt::format("tolerance '{}': expected a percentage such as 10%, found "
                                      "'{}' ({})",
                                      key, v.Scalar(), usage));
    t->dist = Dist::kRelUniform;
    t->a = pct;
  } else if (v.IsMap() && v.size() == 1 && v["normal"]) {
    const YAML::Node n = v["normal"];
    if (n.IsScalar()) {
      if (!parse_percent(n.Scalar(), &pct))
        return doc.error(n, fmt::format("tolerance '{}': {}", key, usage));
      t->dist = Dist::kRelNormal;
      t->a = pct;
    } else {
      if (Status st = pair(n, &t->a, &t->b); !st.ok()) return st;
      if (t->b < 0) return doc.error(n[1], fmt::format("tolerance '{}': sigma must be >= 0", key));
      t->dist = Dist::kNormal;
    }
  } else if (v.IsMap() && v.size() == 1 && v["uniform"]) {
    const YAML::Node n = v["uniform"];
    if (n.IsScalar()) {
      if (!parse_percent(n.Scalar(), &pct))
        return doc.error(n, fmt::format("tolerance '{}': {}", key, usage));
      t->dist = Dist::kRelUniform;
      t->a = pct;
    } else {
      if (Status st = pair(n, &t->a, &t->b); !st.ok()) return st;
      if (t->b < t->a)
        return doc.error(n, fmt::format("tolerance '{}': uniform [lo, hi] needs lo <= hi", key));
      t->dist = Dist::kUniform;
    }
  } else {
    return doc.error(v.IsDefined() && !v.IsNull() ? v : key_node,
                     fmt::format("tolerance '{}': {}", key, usage));
  }
  if (t->dist == Dist::kRelUniform || t->dist == Dist::kRelNormal) {
    bool swept = false;
    for (const Axis& ax : s.axes)
      for (const AxisValue& av : ax.values)
        for (const Assignment& a : av.assign)
          if (a.path == t->paths[0] && a.scalar) swept = true;
    if (!swept && !spec_number(base, t->paths[0]))
      return doc.error(v, fmt::format("tolerance '{}' is relative but the key has no nominal "
                                      "value in the base spec (a part's value is not looked "
                                      "up): give the key in the base, or use {{normal: [mean, "
                                      "sigma]}} or {{uniform: [lo, hi]}}",
                                      key));
  }
  return Status::Ok();
}

}  // namespace

Unit key_unit(const std::string& path) {
  const std::string k = last_key(path);
  if (k == "cap" || k == "bypass_c" || k == "esd" || k == "winding_c" || k == "centre_tap_c" ||
      k == "cable_side_c" || k == "c")
    return Unit::kFarad;
  if (k == "inductance" || k == "leakage" || k == "l") return Unit::kHenry;
  if (k == "series_r" || k == "termination" || k == "dcr" || k == "r") return Unit::kOhm;
  if (k == "length") return Unit::kMetre;
  if (k == "temperature") return Unit::kCelsius;
  if (k == "g") return Unit::kSiemens;
  if (k == "tstep" || k == "tmax") return Unit::kSecond;
  return Unit::kNone;
}

std::optional<double> key_number(const std::string& path, const std::string& text) {
  double v = 0;
  if (!parse_number_for(path, text, &v)) return std::nullopt;
  return v;
}

std::optional<double> spec_number(const link::LinkSpec& spec, const std::string& path) {
  const std::vector<std::string> k = split_path(path);
  auto opt = [](const std::optional<double>& o) { return o; };
  if (k.size() >= 2 && (k[0] == "tx" || k[0] == "rx")) {
    const link::EndSpec& e = k[0] == "tx" ? spec.tx : spec.rx;
    if (k.size() == 2) {
      if (k[1] == "series_r") return opt(e.series_r);
      if (k[1] == "bypass_c") return opt(e.bypass_c);
      if (k[1] == "termination") return opt(e.termination);
      return std::nullopt;
    }
    if (k.size() == 3 && k[1] == "isolation") {
      const link::IsolationSpec& i = e.isolation;
      if (k[2] == "cap") return i.cap;
      if (k[2] == "inductance") return opt(i.inductance);
      if (k[2] == "leakage") return opt(i.leakage);
      if (k[2] == "dcr") return opt(i.dcr);
      if (k[2] == "winding_c") return opt(i.winding_c);
      if (k[2] == "centre_tap_c") return opt(i.centre_tap_c);
      if (k[2] == "cable_side_c")
        return i.cable_side_c >= 0 ? std::optional<double>(i.cable_side_c) : std::nullopt;
      if (k[2] == "esd") return i.esd;
    }
    return std::nullopt;
  }
  if (k.size() == 2 && k[0] == "cable") {
    const link::CableSpec& c = spec.cable;
    if (k[1] == "length") return c.length;
    if (k[1] == "temperature") return c.temperature;
    if (k[1] == "gauge") return static_cast<double>(c.gauge);
    if (k[1] == "segments")
      return c.segments > 0 ? std::optional<double>(c.segments) : std::nullopt;
    if (k[1] == "r") return opt(c.r);
    if (k[1] == "l") return opt(c.l);
    if (k[1] == "c") return opt(c.c);
    if (k[1] == "g") return opt(c.g);
    return std::nullopt;
  }
  if (k.size() == 2 && k[0] == "sim") {
    if (k[1] == "tstep") return spec.sim.tstep;
    if (k[1] == "tmax") return opt(spec.sim.tmax);
    if (k[1] == "reltol") return opt(spec.sim.reltol);
  }
  return std::nullopt;
}

StatusOr<link::LinkSpec> spec_with(const std::string& text, const std::string& name,
                                   const std::vector<Assignment>& assign) {
  StatusOr<YamlDoc> doc = YamlDoc::from_text(text, name);
  if (!doc) return doc.status();
  if (Status st = apply(doc->root(), assign); !st.ok()) return st;
  return link::read_link_spec(*doc);
}

std::vector<double> range_values(double from, double to, int steps, bool log) {
  std::vector<double> v;
  if (steps < 1) return v;
  if (steps == 1) return {from};
  for (int i = 0; i < steps; ++i) {
    const double f = static_cast<double>(i) / (steps - 1);
    if (i == steps - 1)
      v.push_back(to);
    else if (log)
      v.push_back(from * std::pow(to / from, f));
    else
      v.push_back(from + (to - from) * f);
  }
  return v;
}

size_t SweepSpec::grid_size() const {
  if (axes.empty()) return 1;
  if (mode == Mode::kZip) return axes.front().values.size();
  size_t n = 1;
  for (const Axis& a : axes) n *= a.values.size();
  return n;
}

std::vector<size_t> SweepSpec::grid_indices(size_t g) const {
  std::vector<size_t> idx(axes.size(), 0);
  if (mode == Mode::kZip) {
    for (size_t& i : idx) i = g;
    return idx;
  }
  for (size_t k = axes.size(); k-- > 0;) {
    const size_t n = axes[k].values.size();
    idx[k] = g % n;
    g /= n;
  }
  return idx;
}

std::vector<std::string> SweepSpec::point_columns() const {
  std::vector<std::string> c;
  for (const Axis& a : axes) c.push_back(a.key);
  if (mc.samples > 0) {
    c.push_back("sample");
    for (const Tolerance& t : mc.tolerances) c.push_back("mc." + t.key);
  }
  return c;
}

std::vector<double> draw_sample(const MonteCarlo& mc, size_t sample,
                                const std::vector<double>& nominal) {
  std::mt19937_64 rng(mc.seed + sample);
  // Portable draws (the standard distributions' algorithms differ between libraries).
  auto uniform01 = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };  // [0, 1)
  auto normal01 = [&] {
    const double u1 = 1.0 - uniform01();  // (0, 1]
    const double u2 = uniform01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  };
  std::vector<double> out;
  for (size_t i = 0; i < mc.tolerances.size(); ++i) {
    const Tolerance& t = mc.tolerances[i];
    const double nom = i < nominal.size() ? nominal[i] : kNaN;
    double x = kNaN;
    switch (t.dist) {
      case Dist::kRelUniform:
        x = nom * (1.0 + t.a * (2.0 * uniform01() - 1.0));
        break;
      case Dist::kRelNormal:
        x = nom * (1.0 + normal01() * t.a / 3.0);
        break;
      case Dist::kNormal:
        x = t.a + t.b * normal01();
        break;
      case Dist::kUniform:
        x = t.a + (t.b - t.a) * uniform01();
        break;
    }
    if (t.integer) x = std::round(x);
    out.push_back(x);
  }
  return out;
}

PointOutcome make_point(const SweepSpec& s, size_t index) {
  PointOutcome out;
  PointSpec& p = out.point;
  p.index = index;
  p.grid = index / s.samples();
  p.sample = s.mc.samples > 0 ? static_cast<int>(index % s.samples()) : -1;
  p.axis = s.grid_indices(p.grid);
  for (size_t k = 0; k < s.axes.size(); ++k) p.cells.push_back(s.axes[k].values[p.axis[k]].label);
  if (p.sample >= 0) p.cells.push_back(fmt::format("{}", p.sample));

  if (s.pack) {  // no Monte Carlo (refused when the file is read): the axes' values only
    std::vector<Assignment> all;
    for (size_t k = 0; k < s.axes.size(); ++k) {
      const std::vector<Assignment>& a = s.axes[k].values[p.axis[k]].assign;
      all.insert(all.end(), a.begin(), a.end());
    }
    StatusOr<Built> built = build(s, all);
    if (!built)
      out.status = built.status();
    else
      p.pack = std::move(built->pack);
    return out;
  }
  StatusOr<YamlDoc> doc = base_doc(s);
  if (!doc) {
    out.status = doc.status();
    return out;
  }
  for (size_t k = 0; k < s.axes.size(); ++k)
    if (Status st = apply(doc->root(), s.axes[k].values[p.axis[k]].assign); !st.ok()) {
      out.status = st;
      break;
    }
  StatusOr<link::LinkSpec> spec =
      out.status.ok() ? link::read_link_spec(*doc) : StatusOr<link::LinkSpec>(out.status);
  if (p.sample >= 0) {
    std::vector<double> nominal;
    for (const Tolerance& t : s.mc.tolerances)
      nominal.push_back(spec ? spec_number(*spec, t.paths[0]).value_or(kNaN) : kNaN);
    p.mc_values = draw_sample(s.mc, static_cast<size_t>(p.sample), nominal);
    for (size_t i = 0; i < s.mc.tolerances.size(); ++i) {
      const Tolerance& t = s.mc.tolerances[i];
      const double x = p.mc_values[i];
      const std::string text = t.integer ? fmt::format("{}", std::llround(x)) : num_text(x);
      p.cells.push_back(std::isnan(x) ? "" : text);
      if (!out.status.ok()) continue;
      if (std::isnan(x)) {
        out.status =
            Status::Error(fmt::format("tolerance '{}': the key has no nominal value at "
                                      "this point",
                                      t.key));
        continue;
      }
      for (const std::string& path : t.paths)
        if (Status st = set_path(doc->root(), path, Assignment{path, text, true}); !st.ok())
          out.status = st;
    }
    if (out.status.ok()) spec = link::read_link_spec(*doc);
  }
  if (out.status.ok() && !spec) out.status = spec.status();
  if (out.status.ok()) p.spec = std::move(*spec);
  return out;
}

StatusOr<SweepSpec> read_sweep_file(const std::string& path) {
  StatusOr<std::string> text = read_input_file(path);  // size-limited; refuses folders
  if (!text) return text.status();
  return read_sweep_text(*text, path);
}

namespace {

// The sweep file's own keys, kept for the steps that need what comes before them.
struct SweepKeys {
  YAML::Node base, sweep, monte_carlo;
};

// The top-level map: name, mode and outputs into s; base, sweep and monte_carlo kept for later.
Status read_top_keys(const YamlDoc& doc, SweepSpec* s, SweepKeys* keys) {
  const YAML::Node& root = doc.root();
  if (!root.IsMap())
    return doc.error(
        root, "a sweep file is a YAML map with keys base, sweep, mode, monte_carlo, outputs");
  std::string mode = "grid";
  std::vector<std::string> outputs;
  auto keep = [](YAML::Node* into) {
    return [into](const YAML::Node& n, const std::string&) {
      into->reset(n);
      return Status::Ok();
    };
  };
  Status st = config::read_map(doc, root, "",
                               {
                                   {"base", keep(&keys->base)},
                                   {"name", config::read_text(doc, &s->name)},
                                   {"sweep", keep(&keys->sweep)},
                                   {"mode", config::read_choice(doc, {"grid", "zip"}, &mode)},
                                   {"monte_carlo", keep(&keys->monte_carlo)},
                                   {"outputs", config::read_text_list(doc, &outputs)},
                               });
  if (!st.ok()) return st;
  for (size_t i = 0; i < outputs.size(); ++i) {
    const std::string& o = outputs[i];
    const YAML::Node on = root["outputs"];
    if (o == "noise")
      s->noise_outputs = true;
    else if (o == "worst")
      s->worst_outputs = true;
    else if (o == "stress")
      s->stress_outputs = true;
    else
      return doc.error(on.IsSequence() ? YAML::Node(on[i]) : on,
                       fmt::format("key 'outputs': '{}' is not a result family; the ones known "
                                   "are noise (the noise-immunity columns), worst (the worst "
                                   "case over all legal traffic) and stress (isolink stress's "
                                   "verdict and peaks)",
                                   o));
  }
  s->mode = mode == "zip" ? Mode::kZip : Mode::kGrid;
  if (s->name.empty() || s->name.find_first_of("/\\") != std::string::npos)
    return doc.error(root["name"], "key 'name': a non-empty name without '/'");
  return Status::Ok();
}

// The base spec's text: a file named relative to the sweep file, or the sweep file itself when
// the base is inline.
Status read_base_text(const YamlDoc& doc, const YAML::Node& base_node, const std::string& text,
                      const std::string& name, SweepSpec* s) {
  if (!base_node.IsDefined() || base_node.IsNull())
    return doc.error(doc.root(), "key 'base' is missing: a link spec file or an inline spec");
  if (base_node.IsScalar()) {
    std::filesystem::path p(base_node.Scalar());
    if (p.is_relative()) p = std::filesystem::path(name).parent_path() / p;
    StatusOr<std::string> base_text = read_input_file(p.string());
    if (!base_text) {
      const std::string& m = base_text.status().message();  // "PATH: error: REASON"
      const size_t at = m.find(": error: ");
      return doc.error(base_node,
                       fmt::format("key 'base': cannot read the link spec '{}': {}", p.string(),
                                   at == std::string::npos ? m : m.substr(at + 9)));
    }
    s->base_path = p.lexically_normal().string();
    s->base_text = std::move(*base_text);
  } else if (base_node.IsMap()) {
    s->base_path = name;
    s->base_text = text;
    s->base_inline = true;
  } else {
    return doc.error(base_node, "key 'base': a link spec file name or an inline spec (a map)");
  }
  return Status::Ok();
}

// The base read as a pack spec (every point a pack run; the keys address its hops) or a link
// spec (into *base_spec); a pack refuses Monte Carlo and the result families.
Status read_base_spec(const YamlDoc& doc, const SweepKeys& keys, const std::string& name,
                      SweepSpec* s, link::LinkSpec* base_spec) {
  StatusOr<YamlDoc> bdoc = base_doc(*s);
  if (!bdoc) return bdoc.status();
  if (!is_pack_spec(*bdoc)) {
    StatusOr<link::LinkSpec> spec = link::read_link_spec(*bdoc);
    if (!spec) return spec.status().with_context(fmt::format("{}: the base spec", name));
    *base_spec = std::move(*spec);
    return Status::Ok();
  }
  if (s->base_inline)
    return doc.error(keys.base,
                     "key 'base': an inline base is a link spec; give a pack spec "
                     "as a file (base: pack.yaml)");
  StatusOr<PackSpec> pack = read_pack_spec_text(s->base_text, s->base_path);
  if (!pack) return pack.status().with_context(fmt::format("{}: the base pack", name));
  s->pack = true;
  s->pack_hops = static_cast<int>(pack->hops.size());
  s->pack_ring = pack->ring;
  if (keys.monte_carlo.IsDefined() && !keys.monte_carlo.IsNull())
    return doc.error(keys.monte_carlo,
                     "key 'monte_carlo': not available when the base is a pack spec "
                     "(sweep the hops' keys on a grid instead)");
  for (const auto& [on, family] :
       {std::pair{s->noise_outputs, "noise"}, std::pair{s->worst_outputs, "worst"},
        std::pair{s->stress_outputs, "stress"}})
    if (on)
      return doc.error(doc.root()["outputs"],
                       fmt::format("key 'outputs': {0} is not available when the base is a "
                                   "pack spec (sweep a hop's own link spec with outputs: [{0}] "
                                   "instead)",
                                   family));
  return Status::Ok();
}

// The swept keys (each once); in zip mode, the same number of values for each.
Status read_swept_keys(const YamlDoc& doc, const YAML::Node& sweep_node, SweepSpec* s) {
  if (sweep_node.IsDefined() && !sweep_node.IsNull()) {
    if (!sweep_node.IsMap())
      return doc.error(sweep_node, "key 'sweep': a map of dotted spec keys to their values");
    for (auto it = sweep_node.begin(); it != sweep_node.end(); ++it) {
      Axis axis;
      if (Status e = read_axis(*s, doc, it->first, it->second, &axis); !e.ok()) return e;
      for (const Axis& other : s->axes)
        if (other.key == axis.key)
          return doc.error(it->first, fmt::format("sweep key '{}' is given twice", axis.key));
      s->axes.push_back(std::move(axis));
    }
  }
  if (s->mode != Mode::kZip || s->axes.empty()) return Status::Ok();
  for (const Axis& a : s->axes)
    if (a.values.size() != s->axes.front().values.size()) {
      std::string sizes;
      for (const Axis& b : s->axes)
        sizes += fmt::format("{}{} has {}", sizes.empty() ? "" : ", ", b.key, b.values.size());
      const YAML::Node& root = doc.root();
      return doc.error(root["mode"] ? root["mode"] : sweep_node,
                       fmt::format("mode zip needs the same number of values for every key: "
                                   "{}",
                                   sizes));
    }
  return Status::Ok();
}

// The monte_carlo block: samples, seed and the tolerances (each key once), checked against the
// base spec.
Status read_monte_carlo(const YamlDoc& doc, const YAML::Node& mc_node, const link::LinkSpec& base,
                        SweepSpec* s) {
  if (!mc_node.IsDefined() || mc_node.IsNull()) return Status::Ok();
  YAML::Node tol_node;
  int samples = 0, seed = 1;
  Status e = config::read_map(
      doc, mc_node, "monte_carlo",
      {
          {"samples", config::read_int(doc, 1, 10000000, &samples)},
          {"seed", config::read_int(doc, 0, std::numeric_limits<int>::max(), &seed)},
          {"tolerances",
           [&](const YAML::Node& n, const std::string&) {
             tol_node.reset(n);
             return Status::Ok();
           }},
      });
  if (!e.ok()) return e;
  if (!mc_node["samples"])
    return doc.error(mc_node, "key 'monte_carlo.samples' is missing: how many samples");
  if (!tol_node.IsMap() || tol_node.size() == 0)
    return doc.error(tol_node.IsDefined() ? tol_node : mc_node,
                     "key 'monte_carlo.tolerances': a map of dotted spec keys to tolerances "
                     "(10%, {normal: [mean, sigma]}, {uniform: [lo, hi]})");
  s->mc.samples = samples;
  s->mc.seed = static_cast<uint64_t>(seed);
  for (auto it = tol_node.begin(); it != tol_node.end(); ++it) {
    Tolerance t;
    if (Status te = read_tolerance(*s, doc, base, it->first, it->second, &t); !te.ok()) return te;
    for (const Tolerance& other : s->mc.tolerances)
      if (other.key == t.key)
        return doc.error(it->first, fmt::format("tolerance '{}' is given twice", t.key));
    s->mc.tolerances.push_back(std::move(t));
  }
  return Status::Ok();
}

// Something to sweep, and a point count within kMaxSweepPoints, with overflow checks, before
// anything is sized by it (64 two-valued axes are 2^64 points: size_t wraps to 0).
Status check_point_count(const YamlDoc& doc, const YAML::Node& sweep_node, const SweepSpec& s) {
  if (s.axes.empty() && s.mc.samples == 0)
    return doc.error(doc.root(), "nothing to sweep: give 'sweep' keys or 'monte_carlo'");
  size_t points = 1;
  bool over = false;
  if (s.mode == Mode::kZip && !s.axes.empty())
    points = s.axes.front().values.size();
  else
    for (const Axis& a : s.axes)
      over = over || __builtin_mul_overflow(points, a.values.size(), &points);
  over = over || __builtin_mul_overflow(points, s.samples(), &points);
  if (over || points > kMaxSweepPoints)
    return doc.error(
        sweep_node.IsDefined() ? sweep_node : doc.root(),
        fmt::format("the sweep has {} points; the limit is {} (fewer values per key, "
                    "fewer keys, or fewer Monte Carlo samples)",
                    over ? std::string("2^64 or more") : std::to_string(points), kMaxSweepPoints));
  return Status::Ok();
}

}  // namespace

StatusOr<SweepSpec> read_sweep_text(const std::string& text, const std::string& name) {
  StatusOr<YamlDoc> doc = YamlDoc::from_text(text, name);
  if (!doc) return doc.status();
  SweepSpec s;
  s.path = name;
  s.name = std::filesystem::path(name).stem().string();
  // Keys in the order they are needed: base first, then sweep (checked against it), then Monte
  // Carlo (its tolerances can depend on the swept keys).
  SweepKeys keys;
  if (Status st = read_top_keys(*doc, &s, &keys); !st.ok()) return st;
  if (Status st = read_base_text(*doc, keys.base, text, name, &s); !st.ok()) return st;
  link::LinkSpec base_spec;
  if (Status st = read_base_spec(*doc, keys, name, &s, &base_spec); !st.ok()) return st;
  if (Status st = read_swept_keys(*doc, keys.sweep, &s); !st.ok()) return st;
  if (Status st = read_monte_carlo(*doc, keys.monte_carlo, base_spec, &s); !st.ok()) return st;
  if (Status st = check_point_count(*doc, keys.sweep, s); !st.ok()) return st;
  return s;
}

}  // namespace isolink::analysis::sweep
