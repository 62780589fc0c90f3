#include "analysis/pack_spec.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace isolink::analysis {

using config::read_bool;
using config::read_choice;
using config::read_map;
using config::read_quantity;
using config::read_text;
using config::Rule;
using config::Unit;
using config::YamlDoc;

int PackSpec::devices() const {
  return chain_hops();
}

int PackSpec::chain_hops() const {
  int n = 0;
  for (const HopSpec& h : hops) n += h.ring_return ? 0 : 1;
  return n;
}

bool is_pack_spec(const YamlDoc& doc) {
  const YAML::Node& root = doc.root();
  return root.IsMap() && root["hops"].IsDefined();
}

namespace {

constexpr int kMaxDevices = 64;  // the most devices a pack may hold (our limit)

struct Reader {
  std::string text;  // the pack file
  std::string name;  // its path
  std::string bridge, stack;
  bool has_stimulus = false;
  HopEdit edit;
  // Files already read (a module spec used by many hops is read once).
  std::vector<std::pair<std::string, std::string>> files;

  StatusOr<YamlDoc> fresh() const { return YamlDoc::from_text(text, name); }

  StatusOr<std::string> file_text(const std::string& path) {
    for (const auto& [p, t] : files)
      if (p == path) return t;
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::Error("cannot open");
    std::stringstream ss;
    ss << in.rdbuf();
    files.push_back({path, ss.str()});
    return ss.str();
  }

  // Sets root.end.device to want when absent; an error when the spec names another device.
  Status check_device(YamlDoc& doc, const char* end, const std::string& want,
                      const std::string& role, const std::string& hop) {
    const YAML::Node& root = std::as_const(doc).root();
    const YAML::Node e = root[end];
    if (e.IsDefined() && e.IsMap() && e["device"].IsDefined()) {
      const YAML::Node d = e["device"];
      if (d.IsScalar() && d.Scalar() != want)
        return doc.error(
            d, fmt::format("key '{}.device' = {}: {} is {}, the pack's {} ({})", end, d.Scalar(),
                           hop, want, role, "leave the key out or name the same device"));
      return Status::Ok();
    }
    if (e.IsDefined() && !e.IsNull() && !e.IsMap()) return Status::Ok();  // read_link_spec says
    doc.root()[end]["device"] = want;
    return Status::Ok();
  }

  // One entry of hops: (or ring_return:): the hop's spec with the pack stimulus and the entry's
  // overrides applied. index is the entry's position in its list (-1 for ring_return).
  StatusOr<HopSpec> read_hop(const YamlDoc& pack, const YAML::Node& entry, int index, int from,
                             int to, bool ring_return, int* repeat) {
    const std::string where = ring_return ? "ring_return" : fmt::format("hops[{}]", index);
    HopSpec hop;
    hop.loc = pack.loc(entry);
    hop.from = from;
    hop.to = to;
    hop.ring_return = ring_return;
    if (!entry.IsMap())
      return pack.error(entry, fmt::format("{}: a map with key 'spec' (a link spec file or an "
                                           "inline spec) and optional overrides",
                                           where));
    const YAML::Node spec_node = entry["spec"];
    if (!spec_node.IsDefined() || spec_node.IsNull())
      return pack.error(entry, fmt::format("{}: key 'spec' is missing: a link spec file "
                                           "(relative to the pack file) or an inline spec",
                                           where));
    *repeat = 1;
    if (entry["repeat"].IsDefined()) {
      if (ring_return)
        return pack.error(entry["repeat"], "ring_return: key 'repeat' is only for hops");
      if (Status s =
              config::read_int(pack, 1, kMaxDevices, repeat)(entry["repeat"], where + ".repeat");
          !s.ok())
        return s;
    }

    // The overlay: a fresh parse of the pack file, so that nothing is shared between hops.
    StatusOr<YamlDoc> over = fresh();
    if (!over) return over.status();
    const YAML::Node& oroot = std::as_const(*over).root();
    const YAML::Node oentry = ring_return ? oroot["ring_return"] : oroot["hops"][index];

    StatusOr<YamlDoc> doc = Status::Error("");
    if (spec_node.IsScalar()) {
      std::filesystem::path p(spec_node.Scalar());
      if (p.is_relative()) p = std::filesystem::path(name).parent_path() / p;
      hop.file = p.lexically_normal().string();
      StatusOr<std::string> t = file_text(hop.file);
      if (!t)
        return pack.error(spec_node, fmt::format("{}: key 'spec': cannot open the link spec '{}'",
                                                 where, hop.file));
      doc = YamlDoc::from_text(*t, hop.file);
      if (!doc) return doc.status();
      if (is_pack_spec(*doc))
        return pack.error(spec_node, fmt::format("{}: key 'spec': '{}' is a pack spec, a hop "
                                                 "needs a link spec",
                                                 where, hop.file));
    } else if (spec_node.IsMap()) {
      doc = fresh();
      if (!doc) return doc.status();
      doc->root().reset(oentry["spec"]);
    } else {
      return pack.error(spec_node, fmt::format("{}: key 'spec': a link spec file name or an "
                                               "inline spec (a map)",
                                               where));
    }
    if (has_stimulus) doc->replace("stimulus", oroot["stimulus"], *over);
    YAML::Node overrides(YAML::NodeType::Map);
    for (auto it = oentry.begin(); it != oentry.end(); ++it) {
      const std::string key = it->first.Scalar();
      if (key != "spec" && key != "repeat") overrides[key] = it->second;
    }
    if (Status s = doc->merge(overrides, *over); !s.ok()) return s;
    if (edit)
      if (Status s = edit(ring_return ? to + 1 : to, *doc); !s.ok()) return s;

    const std::string hop_words =
        ring_return ? "the ring's return hop joins the bridge to the top device; its tx end"
        : from == 0 ? "hop 1 starts at the bridge; its tx end"
                    : fmt::format("a hop between stack devices ({} to {}): its tx end", from, to);
    if (Status s = check_device(*doc, "tx", from == 0 ? bridge : stack,
                                from == 0 ? "bridge" : "stack device", hop_words);
        !s.ok())
      return s;
    if (Status s = check_device(*doc, "rx", stack, "stack device",
                                fmt::format("its rx end (device {})", to));
        !s.ok())
      return s;
    StatusOr<link::LinkSpec> spec = link::read_link_spec(*doc);
    if (!spec) return spec.status();
    hop.spec = std::move(*spec);
    return hop;
  }
};

Status read_timing(const YamlDoc& doc, const YAML::Node& node, TimingSpec* t) {
  return read_map(
      doc, node, "timing",
      {
          {"timeout", read_quantity(doc, Unit::kSecond, Rule::kPositive, &t->timeout)},
          {"bridge_delay", read_quantity(doc, Unit::kSecond, Rule::kNonNegative, &t->bridge_delay)},
          {"device_delay", read_quantity(doc, Unit::kSecond, Rule::kNonNegative, &t->device_delay)},
          {"uart_byte", read_quantity(doc, Unit::kSecond, Rule::kPositive, &t->uart_byte)},
          {"chain_byte", read_quantity(doc, Unit::kSecond, Rule::kPositive, &t->chain_byte)},
          {"response_delay",
           read_quantity(doc, Unit::kSecond, Rule::kNonNegative, &t->response_delay)},
      });
}

}  // namespace

StatusOr<PackSpec> read_pack_spec_text(const std::string& text, const std::string& name,
                                       const HopEdit& edit) {
  StatusOr<YamlDoc> doc = YamlDoc::from_text(text, name);
  if (!doc) return doc.status();
  const YAML::Node& root = std::as_const(*doc).root();
  PackSpec pack;
  pack.source = name;
  pack.name = std::filesystem::path(name).stem().string();
  if (!root.IsMap())
    return doc->error(root,
                      "a pack spec is a YAML map with keys name, bridge, stack, stimulus, "
                      "hops, ring, ring_return, timing");
  YAML::Node hops_node, return_node;
  Reader reader{text, name, "", "", false, edit, {}};
  Status s = read_map(
      *doc, root, "",
      {
          {"name", read_text(*doc, &pack.name)},
          {"bridge", read_choice(*doc, {"bq79600"}, &pack.bridge)},
          {"stack", read_choice(*doc, {"bq7961x", "bq79606a"}, &pack.stack)},
          {"stimulus",
           [&](const YAML::Node& n, const std::string&) {
             if (!n.IsMap())
               return doc->error(n, fmt::format("key 'stimulus': a map (frames, tones, patterns, "
                                                "script, direction) as in a link spec, found a {}",
                                                config::node_kind(n)));
             reader.has_stimulus = true;
             return Status::Ok();
           }},
          {"hops",
           [&](const YAML::Node& n, const std::string&) {
             hops_node.reset(n);
             return Status::Ok();
           }},
          {"ring", read_bool(*doc, &pack.ring)},
          {"ring_return",
           [&](const YAML::Node& n, const std::string&) {
             return_node.reset(n);
             return Status::Ok();
           }},
          {"timing", [&](const YAML::Node& n,
                         const std::string&) { return read_timing(*doc, n, &pack.timing); }},
      });
  if (!s.ok()) return s;
  if (pack.name.empty() || pack.name.find_first_of("/\\") != std::string::npos)
    return doc->error(root["name"], fmt::format("key 'name' = '{}': must be a non-empty name "
                                                "without '/' (it names the report folder)",
                                                pack.name));
  reader.bridge = pack.bridge;
  reader.stack = pack.stack;

  if (!hops_node.IsSequence() || hops_node.size() == 0)
    return doc->error(hops_node.IsDefined() ? hops_node : root,
                      "key 'hops': a list of hops in chain order from the bridge up, each "
                      "{spec: FILE.yaml, ...overrides}");
  for (size_t i = 0; i < hops_node.size(); ++i) {
    const int from = pack.chain_hops();
    int repeat = 1;
    StatusOr<HopSpec> hop =
        reader.read_hop(*doc, hops_node[i], static_cast<int>(i), from, from + 1, false, &repeat);
    if (!hop) return hop.status();
    // A repeated first hop: the bridge at the first one's tx end, stack devices at the others'.
    // With an edit, every copy is read on its own (the edit may differ per hop).
    StatusOr<HopSpec> next = hop;
    if ((from == 0 || edit) && repeat > 1)
      next = reader.read_hop(*doc, hops_node[i], static_cast<int>(i), from + 1, from + 2, false,
                             &repeat);
    if (!next) return next.status();
    for (int r = 0; r < repeat; ++r) {
      if (edit && r > 1) {
        next = reader.read_hop(*doc, hops_node[i], static_cast<int>(i), from + r, from + r + 1,
                               false, &repeat);
        if (!next) return next.status();
      }
      HopSpec h = r == 0 ? *hop : *next;
      h.index = h.from = pack.chain_hops();
      h.index += 1;
      h.to = h.index;
      pack.hops.push_back(std::move(h));
    }
    if (pack.chain_hops() > kMaxDevices)
      return doc->error(hops_node[i], fmt::format("key 'hops': {} stack devices so far, at most "
                                                  "{} in one chain",
                                                  pack.chain_hops(), kMaxDevices));
  }
  const int n = pack.chain_hops();
  if (pack.ring) {
    if (!return_node.IsDefined() || return_node.IsNull())
      return doc->error(root["ring"],
                        "key 'ring' is true: give the return hop under "
                        "'ring_return' ({spec: FILE.yaml, ...overrides}), tx end at "
                        "the bridge's COML, rx end at the top device's COMH");
    int repeat = 1;
    StatusOr<HopSpec> hop = reader.read_hop(*doc, return_node, -1, 0, n, true, &repeat);
    if (!hop) return hop.status();
    hop->index = n + 1;
    pack.hops.push_back(std::move(*hop));
  } else if (return_node.IsDefined() && !return_node.IsNull()) {
    return doc->error(return_node, "key 'ring_return' needs 'ring: true'");
  }
  return pack;
}

StatusOr<PackSpec> read_pack_spec_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(fmt::format("{}: error: cannot open the file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return read_pack_spec_text(ss.str(), path);
}

}  // namespace isolink::analysis
