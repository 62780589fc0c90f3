// isolink parts: the part library (built-in netlists/parts plus --parts folders) as a table,
// one part's figures with their sources, or JSON. The library itself is netlists/link/parts.h.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/common_options.h"
#include "netlists/link/cards.h"
#include "netlists/link/parts.h"

namespace isolink::cli {
namespace {

using link::Figure;
using link::format_si;
using link::Part;
using link::PartKind;

struct PartsArgs {
  std::vector<std::string> dirs;
  std::string part;
  bool json = false;
};

const char* unit_of(const std::string& key) {
  if (key == "inductance" || key == "leakage") return "H";
  if (key == "dcr" || key == "loss_r" || key == "cm_impedance") return "ohm";
  if (key == "winding_c" || key == "centre_tap_c" || key == "capacitance") return "F";
  if (key == "rating.current") return "A";
  if (key == "rating.voltage" || key == "rating.isolation") return "V";
  return "";
}

std::string range_text(const Figure& f) {
  if (f.tolerance) return fmt::format("+/-{:g} %", *f.tolerance * 100);
  if (f.min && f.max)
    return format_si(*f.min, unit_of(f.key)) + " .. " + format_si(*f.max, unit_of(f.key));
  if (f.min) return "min " + format_si(*f.min, unit_of(f.key));
  if (f.max) return "max " + format_si(*f.max, unit_of(f.key));
  return "";
}

// The nominal values column.
std::string values_text(const Part& p) {
  switch (p.kind) {
    case PartKind::Choke:
      return fmt::format("{}, k {:.5f}", format_si(p.choke.inductance, "H"), p.choke.k);
    case PartKind::Transformer: {
      std::string s = "OCL " + format_si(p.transformer.inductance, "H");
      if (const Figure* f = p.figure("inductance"); f && f->min && f->max)
        s += " (" + format_si(*f->min, "H") + " .. " + format_si(*f->max, "H") + ")";
      s += ", Lleak " + format_si(p.transformer.leakage, "H");
      if (p.transformer.centre_tap_c > 0) s += ", CT " + format_si(p.transformer.centre_tap_c, "F");
      return s;
    }
    case PartKind::Capacitor: {
      std::string s = format_si(p.capacitor.capacitance, "F");
      if (p.capacitor.tolerance > 0) s += fmt::format(" +/-{:g} %", p.capacitor.tolerance * 100);
      if (!p.dielectric.empty()) s += " " + p.dielectric;
      return s;
    }
    case PartKind::Tvs:
      return fmt::format("{}, VRWM {:g} V, VBR {:g} V, VCL {:g} V @ {:g} A, {} @ 0 V",
                         p.tvs.bidirectional ? "bidir" : "unidir", p.tvs.standoff, p.tvs.breakdown,
                         p.tvs.clamp, p.tvs.clamp_current, format_si(p.tvs.capacitance, "F"));
  }
  return "";
}

std::string rating_text(const Part& p) {
  std::vector<std::string> r;
  if (p.rated_current) r.push_back(format_si(*p.rated_current, "A"));
  if (p.rated_voltage) r.push_back(format_si(*p.rated_voltage, "V"));
  if (p.isolation_voltage) r.push_back(format_si(*p.isolation_voltage, "V") + " isolation");
  if (p.kind == PartKind::Tvs) {
    if (p.tvs.peak_power > 0) r.push_back(format_si(p.tvs.peak_power, "W") + " 8/20us");
    if (p.tvs.esd_contact > 0) r.push_back(format_si(p.tvs.esd_contact, "V") + " ESD");
  }
  std::string s;
  for (const std::string& x : r) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "-" : s;
}

std::string zcm_text(const Part& p) {
  if (!p.cm_impedance) return "-";
  return format_si(*p.cm_impedance, "ohm") + " @ " + format_si(p.cm_frequency.value_or(0), "Hz");
}

nlohmann::json to_json(const Part& p) {
  nlohmann::json j;
  j["part"] = p.number;
  j["maker"] = p.maker;
  j["kind"] = link::part_kind_name(p.kind);
  j["file"] = p.loc.file ? p.loc.file->path : "";
  j["line"] = p.loc.line;
  if (!p.description.empty()) j["description"] = p.description;
  if (!p.datasheet.empty()) j["datasheet"] = p.datasheet;
  if (!p.dielectric.empty()) j["dielectric"] = p.dielectric;
  if (!p.overrides.empty()) j["overrides"] = p.overrides;
  nlohmann::json figs = nlohmann::json::object();
  for (const Figure& f : p.figures) {
    nlohmann::json x;
    x["value"] = f.value;
    x["unit"] = unit_of(f.key);
    if (f.min) x["min"] = *f.min;
    if (f.max) x["max"] = *f.max;
    if (f.tolerance) x["tolerance"] = *f.tolerance;
    if (f.frequency) x["frequency"] = *f.frequency;
    if (!f.measured.empty()) x["measured"] = f.measured;
    if (f.fitted) x["fitted"] = true;
    x["source"] = f.source;
    figs[f.key] = x;
  }
  j["figures"] = figs;
  nlohmann::json m;
  switch (p.kind) {
    case PartKind::Choke:
      m = {{"inductance", p.choke.inductance},
           {"k", p.choke.k},
           {"dcr", p.choke.dcr},
           {"winding_c", p.choke.winding_c},
           {"loss_r", p.choke.loss_r}};
      break;
    case PartKind::Transformer:
      m = {{"inductance", p.transformer.inductance},
           {"leakage", p.transformer.leakage},
           {"k", p.transformer.k()},
           {"dcr", p.transformer.dcr},
           {"winding_c", p.transformer.winding_c},
           {"centre_tap_c", p.transformer.centre_tap_c}};
      break;
    case PartKind::Capacitor:
      m = {{"capacitance", p.capacitor.capacitance},
           {"tolerance", p.capacitor.tolerance},
           {"voltage_rating", p.capacitor.voltage_rating}};
      break;
    case PartKind::Tvs:
      m = {{"polarity", p.tvs.bidirectional ? "bidirectional" : "unidirectional"},
           {"standoff", p.tvs.standoff},
           {"breakdown", p.tvs.breakdown},
           {"breakdown_current", p.tvs.breakdown_current},
           {"clamp", p.tvs.clamp},
           {"clamp_current", p.tvs.clamp_current},
           {"capacitance", p.tvs.capacitance},
           {"peak_current", p.tvs.peak_current},
           {"peak_power", p.tvs.peak_power},
           {"esd_contact", p.tvs.esd_contact},
           {"spice",
            {{"is", p.tvs.is},
             {"n", 1},
             {"bv", p.tvs.bv},
             {"ibv", p.tvs.ibv},
             {"rs", p.tvs.rs},
             {"cjo", p.tvs.cjo},
             {"vj", p.tvs.vj},
             {"m", p.tvs.grading}}}};
      break;
  }
  j["model"] = m;
  return j;
}

void print_table(const std::vector<Part>& parts) {
  struct Row {
    std::string cells[6];
  };
  std::vector<Row> rows{{{"PART", "MAKER", "KIND", "VALUE", "ZCM @ F", "RATING"}}};
  for (const Part& p : parts)
    rows.push_back({{p.number, p.maker, link::part_kind_name(p.kind), values_text(p), zcm_text(p),
                     rating_text(p)}});
  size_t width[6] = {};
  for (const Row& r : rows)
    for (int i = 0; i < 6; ++i) width[i] = std::max(width[i], r.cells[i].size());
  for (const Row& r : rows) {
    std::string line;
    for (int i = 0; i < 6; ++i)
      line += i == 5 ? r.cells[i] : fmt::format("{:<{}}  ", r.cells[i], width[i]);
    std::printf("%s\n", line.c_str());
  }
}

void print_part(const Part& p) {
  std::printf("%s  (%s %s, %s)\n", p.number.c_str(), p.maker.c_str(), link::part_kind_name(p.kind),
              p.loc.str().c_str());
  if (!p.description.empty()) std::printf("  %s\n", p.description.c_str());
  if (!p.datasheet.empty()) std::printf("  from: %s\n", p.datasheet.c_str());
  if (!p.overrides.empty()) std::printf("  overrides the part at %s\n", p.overrides.c_str());
  for (const Figure& f : p.figures) {
    std::string v = format_si(f.value, unit_of(f.key));
    if (f.frequency) v += " @ " + format_si(*f.frequency, "Hz");
    if (!f.measured.empty()) v += " (" + f.measured + ")";
    const std::string range = range_text(f);
    if (!range.empty()) v += " [" + range + "]";
    std::printf("  %-17s %s\n  %-17s   %s\n", f.key.c_str(), v.c_str(), "",
                f.source.empty() ? "(no source given)" : f.source.c_str());
  }
  switch (p.kind) {
    case PartKind::Choke:
      std::printf(
          "  model: L %s per winding, k %.6f (CM %s, DM %s per line), DCR %s, "
          "Cw %s, Rloss %s\n",
          format_si(p.choke.inductance, "H").c_str(), p.choke.k,
          format_si(p.choke.inductance * (1 + p.choke.k), "H").c_str(),
          format_si(p.choke.inductance * (1 - p.choke.k), "H").c_str(),
          format_si(p.choke.dcr, "ohm").c_str(), format_si(p.choke.winding_c, "F").c_str(),
          format_si(p.choke.loss_r, "ohm").c_str());
      break;
    case PartKind::Transformer:
      std::printf(
          "  model: OCL %s, k %.6f (leakage %s, other winding shorted), DCR %s per "
          "winding, inter-winding C %s, centre tap %s\n",
          format_si(p.transformer.inductance, "H").c_str(), p.transformer.k(),
          format_si(p.transformer.leakage, "H").c_str(),
          format_si(p.transformer.dcr, "ohm").c_str(),
          format_si(p.transformer.winding_c, "F").c_str(),
          p.transformer.centre_tap_c > 0 ? format_si(p.transformer.centre_tap_c, "F").c_str()
                                         : "none");
      break;
    case PartKind::Capacitor:
      break;
    case PartKind::Tvs:
      std::printf(
          "  model: %s, per junction: .model D(IS=%g N=1 BV=%.6g IBV=%g RS=%.6g CJO=%g VJ=%g "
          "M=%g)%s\n",
          p.tvs.bidirectional ? "two junctions in anti-series per line" : "one junction per line",
          p.tvs.is, p.tvs.bv, p.tvs.ibv, p.tvs.rs, p.tvs.cjo, p.tvs.vj, p.tvs.grading,
          p.tvs.bidirectional ? " (CJO twice the part's: in series they are its capacitance)" : "");
      break;
  }
}

int run_parts(const PartsArgs& a) {
  StatusOr<link::PartLibrary> lib = link::PartLibrary::load(a.dirs);
  if (!lib) {
    std::fprintf(stderr, "isolink parts: %s\n", lib.status().message().c_str());
    return 2;
  }
  for (const std::string& n : lib->notes()) std::fprintf(stderr, "%s\n", n.c_str());
  std::vector<Part> parts = lib->parts();
  if (!a.part.empty()) {
    const Part* p = lib->find(a.part);
    if (p == nullptr) {
      std::fprintf(stderr,
                   "isolink parts: error: no part '%s' in the library (%zu parts; "
                   "`isolink parts` lists them)\n",
                   a.part.c_str(), parts.size());
      return 2;
    }
    parts = {*p};
  }
  if (a.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const Part& p : parts) j.push_back(to_json(p));
    std::printf("%s\n", j.dump(2).c_str());
  } else if (!a.part.empty()) {
    print_part(parts.front());
  } else {
    print_table(parts);
  }
  return 0;
}

}  // namespace

void add_parts_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<PartsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "parts", "List the part library (built-in netlists/parts plus --parts folders)");
  cmd->add_option("part", args->part, "show one part's figures and their sources");
  add_parts_option(*cmd, &args->dirs);
  cmd->add_flag("--json", args->json, "print JSON: figures with ranges and sources, and the model");
  cmd->callback([args, exit_code] { *exit_code = run_parts(*args); });
}

}  // namespace isolink::cli
