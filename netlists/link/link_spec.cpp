#include "netlists/link/link_spec.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "netlists/link/touchstone_cable.h"
#include "netlists/traffic/stimulus.h"

namespace isolink::link {

using config::Field;
using config::read_bool;
using config::read_choice;
using config::read_int;
using config::read_map;
using config::read_quantity;
using config::read_text;
using config::read_text_list;
using config::Rule;
using config::Unit;
using config::YamlDoc;

const char* direction_name(Direction d) {
  return d == Direction::kDown ? "down" : "up";
}

std::vector<std::string> device_names() {
  return {"bq79600", "bq7961x", "bq79606a"};
}

std::string device_rules(const std::string& device) {
  return device == "bq79600" ? "bq79600" : "bq7961x";
}

std::vector<std::string> nonlinear_parts(const LinkSpec& spec) {
  std::vector<std::string> out;
  for (auto [key, end] : {std::pair{"tx", &spec.tx}, std::pair{"rx", &spec.rx}}) {
    if (!end->isolation.esd_part.empty())
      out.push_back(fmt::format("{}.isolation.esd: TVS {}", key, end->isolation.esd_part));
    if (end->pin_clamps != "none")
      out.push_back(fmt::format("{}.pin_clamps: {}", key, end->pin_clamps));
  }
  return out;
}

std::string linear_only(const LinkSpec& spec, const std::string& what) {
  const std::vector<std::string> parts = nonlinear_parts(spec);
  if (parts.empty()) return "";
  std::string list;
  for (const std::string& p : parts) list += (list.empty() ? "" : "; ") + p;
  return fmt::format(
      "{} needs a linear link (it superposes the link's responses or linearises them), and "
      "this one has nonlinear parts ({}): `isolink run` simulates it exactly "
      "(on the port model, or the full nonlinear transient), or give esd a capacitance (the "
      "TVS's at 0 V) and "
      "pin_clamps none for the linear approximation",
      what, list);
}

std::string StimulusSpec::to_script() const {
  std::string s;
  auto add = [&s](const std::string& item) { s += (s.empty() ? "" : "; ") + item; };
  for (const std::string& t : tones) add("tone " + t);
  for (size_t i = 0; i < frames.size(); ++i) {
    if (i < gaps.size()) add(fmt::format("gap {:.12g}", gaps[i]));
    add(frames[i]);
  }
  for (const std::string& p : patterns) add("pattern " + p);
  if (!script.empty()) add(script);
  return s;
}

namespace {

Status read_isolation(const YamlDoc& doc, const YAML::Node& node, const std::string& path,
                      IsolationSpec* iso) {
  iso->loc = doc.loc(node);
  std::string chokes_key;
  Status s = read_map(
      doc, node, path,
      {
          {"type", read_choice(doc, {"none", "cap", "capchoke", "transformer", "transformer_choke"},
                               &iso->type)},
          {"cap", read_quantity(doc, Unit::kFarad, Rule::kPositive, &iso->cap)},
          {"chokes", read_text_list(doc, &iso->chokes)},
          {"part", read_text(doc, &iso->part)},
          {"inductance", read_quantity(doc, Unit::kHenry, Rule::kPositive, &iso->inductance)},
          {"leakage", read_quantity(doc, Unit::kHenry, Rule::kNonNegative, &iso->leakage)},
          {"dcr", read_quantity(doc, Unit::kOhm, Rule::kNonNegative, &iso->dcr)},
          {"winding_c", read_quantity(doc, Unit::kFarad, Rule::kNonNegative, &iso->winding_c)},
          {"centre_tap_c",
           read_quantity(doc, Unit::kFarad, Rule::kNonNegative, &iso->centre_tap_c)},
          {"cable_side_c",
           read_quantity(doc, Unit::kFarad, Rule::kNonNegative, &iso->cable_side_c)},
          {"esd",
           [&](const YAML::Node& n, const std::string& p) -> Status {
             iso->esd_loc = doc.loc(n);
             double c = 0;
             // A capacitance (today's linear ESD part) or a TVS part number from the library.
             if (n.IsScalar() && config::parse_quantity(n.Scalar(), Unit::kFarad, &c)) {
               if (!(c >= 0) || !std::isfinite(c))
                 return doc.error(n, fmt::format("key '{}' = {}: a capacitance must be >= 0", p,
                                                 config::node_text(n)));
               iso->esd = c;
               return Status::Ok();
             }
             if (!n.IsScalar() || n.Scalar().empty())
               return doc.error(n, fmt::format("key '{}': expected a capacitance per line (20p) "
                                               "or a TVS part number (PESD2CAN), found {}",
                                               p, config::node_text(n)));
             iso->esd_part = n.Scalar();
             return Status::Ok();
           }},
          {"cable_side_return", read_choice(doc, {"board", "chassis"}, &iso->cable_side_return)},
          {"choke_loss",
           [&](const YAML::Node& n, const std::string& p) -> Status {
             if (n.IsScalar() && (n.Scalar() == "fitted" || n.Scalar() == "none")) {
               iso->choke_loss = n.Scalar();
               return Status::Ok();
             }
             double r = 0;
             if (!n.IsScalar() || !config::parse_quantity(n.Scalar(), Unit::kOhm, &r) || !(r > 0) ||
                 !std::isfinite(r))
               return doc.error(n, fmt::format("key '{}' = {}: expected fitted, none or a "
                                               "resistance > 0 across each winding (200, 1k)",
                                               p, config::node_text(n)));
             iso->choke_loss = "resistance", iso->choke_loss_r = r;
             return Status::Ok();
           }},
      });
  if (!s.ok()) return s;
  if (node.IsMap() && node["chokes"] && iso->chokes.empty())
    return doc.error(node["chokes"], fmt::format("key '{}.chokes': one or two chokes, found none "
                                                 "(leave the key out for the default choke)",
                                                 path));
  if (iso->chokes.size() > 2 && node["chokes"])
    return doc.error(node["chokes"], fmt::format("key '{}.chokes': one or two chokes, found {}",
                                                 path, iso->chokes.size()));
  const bool has_chokes = iso->type == "capchoke" || iso->type == "transformer_choke";
  for (const char* k : {"chokes", "choke_loss"})
    if (!has_chokes && node.IsMap() && node[k])
      return doc.error(node[k], fmt::format("key '{}.{}': type {} has no chokes (use capchoke or "
                                            "transformer_choke)",
                                            path, k, iso->type));
  // Every key that has no effect is an error: the isolation cap exists only in cap and capchoke.
  const bool has_cap = iso->type == "cap" || iso->type == "capchoke";
  if (!has_cap && node.IsMap() && node["cap"])
    return doc.error(node["cap"],
                     fmt::format("key '{}.cap': only for type cap or capchoke (type is "
                                 "{})",
                                 path, iso->type));
  const bool has_xfmr = iso->type == "transformer" || iso->type == "transformer_choke";
  if (node.IsMap() && node["cable_side_return"] && !(iso->cable_side_c > 0) &&
      !(has_xfmr && iso->cable_side_c < 0))
    return doc.error(node["cable_side_return"],
                     fmt::format("key '{}.cable_side_return': there are no cable-side caps (type "
                                 "{}, cable_side_c {})",
                                 path, iso->type, iso->cable_side_c < 0 ? "not given" : "0"));
  if (!has_xfmr && node.IsMap())
    for (const char* k : {"part", "inductance", "leakage", "dcr", "winding_c", "centre_tap_c"})
      if (node[k])
        return doc.error(node[k], fmt::format("key '{}.{}': only for a transformer (type is {})",
                                              path, k, iso->type));
  return Status::Ok();
}

Status read_end(const YamlDoc& doc, const YAML::Node& node, const std::string& path, EndSpec* end) {
  end->loc = doc.loc(node);
  std::vector<std::string> devices = device_names();
  Status s = read_map(
      doc, node, path,
      {
          {"device", read_choice(doc, devices, &end->device)},
          {"series_r", read_quantity(doc, Unit::kOhm, Rule::kPositive, &end->series_r)},
          {"bypass_c", read_quantity(doc, Unit::kFarad, Rule::kNonNegative, &end->bypass_c)},
          {"termination", read_quantity(doc, Unit::kOhm, Rule::kPositive, &end->termination)},
          {"isolation",
           [&](const YAML::Node& n, const std::string& p) {
             return read_isolation(doc, n, p, &end->isolation);
           }},
          {"x_cap", read_quantity(doc, Unit::kFarad, Rule::kNonNegative, &end->x_cap)},
          {"y_cap", read_quantity(doc, Unit::kFarad, Rule::kNonNegative, &end->y_cap)},
          {"chassis_c", read_quantity(doc, Unit::kFarad, Rule::kPositive, &end->chassis_c)},
          {"chassis_r", read_quantity(doc, Unit::kOhm, Rule::kPositive, &end->chassis_r)},
          {"chassis_l", read_quantity(doc, Unit::kHenry, Rule::kPositive, &end->chassis_l)},
          {"pin_clamps",
           [&](const YAML::Node& n, const std::string& p) {
             end->pin_clamps_loc = doc.loc(n);
             return read_choice(doc, {"none", "rails"}, &end->pin_clamps)(n, p);
           }},
      });
  if (!s.ok()) return s;
  if (node.IsMap() && node["chassis_l"] && !node["chassis_r"])
    return doc.error(node["chassis_l"],
                     fmt::format("key '{}.chassis_l': the bond's inductance needs its resistance "
                                 "'{}.chassis_r' (a strap: chassis_r 1m, chassis_l 20n)",
                                 path, path));
  return Status::Ok();
}

// The measured cable's keys: the file (relative to the spec's folder), its ports, and no key of
// the native model beside it (they would be ignored).
Status read_touchstone_keys(const YamlDoc& doc, const YAML::Node& node,
                            const std::vector<std::string>& ports, CableSpec* cable) {
  if (cable->touchstone.empty()) {
    for (const char* k : {"ports", "tolerance", "uniform_line"})
      if (node.IsMap() && node[k])
        return doc.error(node[k], fmt::format("key 'cable.{}' needs cable.touchstone", k));
    return Status::Ok();
  }
  for (const char* k : {"material", "gauge", "temperature", "r", "l", "c", "g", "segments",
                        "chassis_c", "skin_effect", "dielectric_loss"})
    if (node[k])
      return doc.error(node[k], fmt::format("key 'cable.{}' does not apply to a measured cable "
                                            "(cable.touchstone): the file is the cable",
                                            k));
  for (const std::string& p : ports) {
    if (p.size() != 1 || p[0] < '1' || p[0] > '4')
      return doc.error(node["ports"], fmt::format("key 'cable.ports': '{}' is not a port 1..4", p));
    cable->ports.push_back(p[0] - '0');
  }
  if (!ports.empty() && ports.size() != 4)
    return doc.error(node["ports"], "key 'cable.ports' names 4 file ports: tx P, tx N, rx P, rx N");
  const std::string& dir = doc.path();
  if (cable->touchstone[0] != '/' && dir.find('/') != std::string::npos)
    cable->touchstone = dir.substr(0, dir.rfind('/') + 1) + cable->touchstone;
  if (auto fit = touchstone_cable(*cable); !fit) return fit.status();
  return Status::Ok();
}

Status read_cable(const YamlDoc& doc, const YAML::Node& node, CableSpec* cable) {
  std::vector<std::string> ports;
  Status s = read_map(
      doc, node, "cable",
      {
          {"length", read_quantity(doc, Unit::kMetre, Rule::kPositive, &cable->length)},
          {"material", read_choice(doc, {"pp", "pvc"}, &cable->material)},
          {"gauge", read_int(doc, 18, 30, &cable->gauge)},
          {"temperature", read_quantity(doc, Unit::kCelsius, Rule::kAny, &cable->temperature)},
          {"r", read_quantity(doc, Unit::kOhm, Rule::kNonNegative, &cable->r)},
          {"l", read_quantity(doc, Unit::kHenry, Rule::kPositive, &cable->l)},
          {"c", read_quantity(doc, Unit::kFarad, Rule::kPositive, &cable->c)},
          {"g", read_quantity(doc, Unit::kSiemens, Rule::kNonNegative, &cable->g)},
          {"segments", read_int(doc, 1, 1000, &cable->segments)},
          {"chassis_c", read_quantity(doc, Unit::kFarad, Rule::kPositive, &cable->chassis_c)},
          {"skin_effect", read_bool(doc, &cable->skin_effect)},
          {"dielectric_loss", read_bool(doc, &cable->dielectric_loss)},
          {"touchstone", read_text(doc, &cable->touchstone)},
          {"ports", read_text_list(doc, &ports)},
          {"tolerance", read_quantity(doc, Unit::kNone, Rule::kPositive, &cable->fit_tolerance)},
          {"uniform_line", read_bool(doc, &cable->uniform_line)},
      });
  if (!s.ok()) return s;
  if (Status t = read_touchstone_keys(doc, node, ports, cable); !t.ok()) return t;
  if (cable->temperature < -55 || cable->temperature > 150)
    return doc.error(node["temperature"],
                     fmt::format("key 'cable.temperature' = {:g}: must be in -55..150 degC",
                                 cable->temperature));
  if (Status v = cable->validate(); !v.ok()) return doc.error(node, v.message());
  return Status::Ok();
}

Status read_stimulus(const YamlDoc& doc, const YAML::Node& node, StimulusSpec* st) {
  st->loc = doc.loc(node);
  std::string direction = "both";
  std::vector<std::string> gaps;
  Status s = read_map(doc, node, "stimulus",
                      {
                          {"frames", read_text_list(doc, &st->frames)},
                          {"gaps", read_text_list(doc, &gaps)},
                          {"tones", read_text_list(doc, &st->tones)},
                          {"patterns", read_text_list(doc, &st->patterns)},
                          {"script", read_text(doc, &st->script)},
                          {"direction", read_choice(doc, {"down", "up", "both"}, &direction)},
                      });
  if (!s.ok()) return s;
  if (!gaps.empty()) {
    const YAML::Node& at = node["gaps"];
    if (gaps.size() != st->frames.size())
      return doc.error(at, fmt::format("key 'stimulus.gaps': {} gaps for {} frames: give one gap "
                                       "(the idle before it) per frame",
                                       gaps.size(), st->frames.size()));
    for (const std::string& g : gaps) {
      StatusOr<double> t = traffic::parse_time(g);
      if (!t || !(*t >= 0))
        return doc.error(at, fmt::format("key 'stimulus.gaps': '{}' {}", g,
                                         t ? "must be a time >= 0" : t.status().message()));
      st->gaps.push_back(*t);
    }
  }
  if (direction == "down") st->directions = {Direction::kDown};
  if (direction == "up") st->directions = {Direction::kUp};
  return Status::Ok();
}

// `noise.band: [f_lo, f_hi]`: two frequencies, lo < hi, inside what the lumped model means.
Status read_band(const YamlDoc& doc, const YAML::Node& n, const std::string& path,
                 std::optional<std::pair<double, double>>* band) {
  constexpr double kLowest = 1e3, kHighest = 1e9;
  if (!n.IsSequence() || n.size() != 2)
    return doc.error(n, fmt::format("key '{}': expected [f_lo, f_hi] (e.g. [1meg, 400meg]), "
                                    "found {}",
                                    path, config::node_kind(n)));
  double lo = 0, hi = 0;
  for (auto [i, out] : {std::pair{0, &lo}, std::pair{1, &hi}}) {
    const std::string key = fmt::format("{}[{}]", path, i);
    if (Status s = read_quantity(doc, Unit::kHertz, Rule::kPositive, out)(n[i], key); !s.ok())
      return s;
    if (*out < kLowest || *out > kHighest)
      return doc.error(n[i], fmt::format("key '{}' = {}: must be from 1 kHz to 1 GHz (below, the "
                                         "floating ties and the cable's bleed resistors set the "
                                         "answer; above, the boards' traces, which are not "
                                         "modelled)",
                                         key, n[i].Scalar()));
  }
  if (!(lo < hi))
    return doc.error(n, fmt::format("key '{}' = [{}, {}]: f_lo must be below f_hi", path,
                                    n[0].Scalar(), n[1].Scalar()));
  *band = std::pair{lo, hi};
  return Status::Ok();
}

Status read_noise(const YamlDoc& doc, const YAML::Node& node, NoiseSpec* ns) {
  ns->loc = doc.loc(node);
  std::optional<double> level;
  std::optional<std::pair<double, double>> band;
  NoiseTolerances& t = ns->tolerance;
  Status s = read_map(
      doc, node, "noise",
      {
          {"injection", read_choice(doc, {"bci", "ground_shift", "dm"}, &ns->injection)},
          {"level",
           [&](const YAML::Node& n, const std::string& p) -> Status {
             // The unit follows the injection, which may come later in the map: read it after.
             if (!n.IsScalar()) return doc.error(n, fmt::format("key '{}': expected a value", p));
             level = 0;
             return Status::Ok();
           }},
          {"position", read_quantity(doc, Unit::kNone, Rule::kNonNegative, &ns->position)},
          {"modulation", read_choice(doc, {"cw", "am"}, &ns->modulation)},
          {"band",
           [&](const YAML::Node& n, const std::string& p) { return read_band(doc, n, p, &band); }},
          {"points_per_decade", read_int(doc, 1, 200, &ns->points_per_decade)},
          {"pin_limit", read_quantity(doc, Unit::kVolt, Rule::kPositive, &ns->pin_limit)},
          {"calibration_r", read_quantity(doc, Unit::kOhm, Rule::kPositive, &ns->calibration_r)},
          {"clamp_r", read_quantity(doc, Unit::kOhm, Rule::kNonNegative, &ns->clamp_r)},
          {"time_domain", read_bool(doc, &ns->time_domain)},
          {"samples", read_int(doc, 200, 100000, &ns->samples)},
          {"seed", read_int(doc, 0, 2147483647, &ns->seed)},
          {"verdict_on", read_choice(doc, {"corner", "statistical"}, &ns->verdict_on)},
          {"tolerance",
           [&](const YAML::Node& n, const std::string& p) {
             using config::read_percent;
             return read_map(doc, n, p,
                             {
                                 {"isolation_cap", read_percent(doc, 50, &t.isolation_cap)},
                                 {"series_r", read_percent(doc, 50, &t.series_r)},
                                 {"bypass_c", read_percent(doc, 50, &t.bypass_c)},
                                 {"y_cap", read_percent(doc, 50, &t.y_cap)},
                                 {"esd", read_percent(doc, 50, &t.esd)},
                                 {"winding_c", read_percent(doc, 50, &t.winding_c)},
                                 {"choke_imbalance", read_percent(doc, 50, &t.choke_imbalance)},
                                 {"cable_chassis_c", read_percent(doc, 50, &t.cable_chassis_c)},
                                 {"rx_pin", read_percent(doc, 50, &t.rx_pin)},
                             });
           }},
      });
  if (!s.ok()) return s;
  if (level) {
    const YAML::Node n = node["level"];
    const Unit unit = ns->injection == "ground_shift" ? Unit::kVolt : Unit::kAmpere;
    if (Status r = read_quantity(doc, unit, Rule::kPositive, &ns->level)(n, "noise.level"); !r.ok())
      return r;
  } else if (ns->injection == "ground_shift") {
    ns->level = 1.0;  // V RMS
  }
  if (ns->position > 1)
    return doc.error(node["position"],
                     fmt::format("key 'noise.position' = {:g}: must be in 0..1 (a fraction of the "
                                 "cable length from the tx end)",
                                 ns->position));
  if (band) {
    ns->f_start = band->first, ns->f_stop = band->second;
  } else if (ns->injection == "ground_shift") {
    ns->f_start = 100e3;  // ground shift (inverter noise) starts at the switching harmonics
  }
  return Status::Ok();
}

// Scenario kinds isolink stress runs (analysis/stress.h).
const std::vector<std::string>& stress_kinds_list() {
  static const std::vector<std::string> kinds{"cm_step", "cm_wave", "esd", "hot_plug", "wire"};
  return kinds;
}

// The bounds of the hot_plug, cm_wave and wire levels, each at its value.
Status check_stress_levels(const YamlDoc& doc, const YAML::Node& node, const StressSpec& st) {
  struct Bound {
    const char* key;
    double value, lo, hi;
    const char* rule;
  };
  const Bound bounds[] = {
      {"hot_plug_v", st.hot_plug_v, 0, 2e3, "must be at most 2 kV (a module's stack voltage)"},
      {"hot_plug_gap", st.hot_plug_gap, 1e-9, 1e-3,
       "must be from 1 ns to 1 ms (the scenario simulates the gap and 5 us after it)"},
      {"wave_v", st.wave_v, 0, 2e3, "must be at most 2 kV (an inverter's DC link)"},
      {"wave_f", st.wave_f, 1e3, 1e6,
       "must be from 1 kHz to 1 MHz (the record holds two periods of it)"},
      {"wave_dvdt", st.wave_dvdt, 1e-3, 100,
       "must be from 0.001 to 100 V/ns (SiC switch nodes reach 10-50 V/ns)"},
      {"leak_ohms", st.leak_ohms, 1, 1e9, "must be from 1 ohm to 1 Gohm"},
  };
  for (const Bound& b : bounds)
    if (b.value < b.lo || b.value > b.hi)
      return doc.error(node[b.key],
                       fmt::format("key 'stress.{}' = {:g}: {}", b.key, b.value, b.rule));
  // The square's edges (wave_v / wave_dvdt) must fit in its half period.
  const double edge = st.wave_v / (st.wave_dvdt * 1e9);
  if (st.wave_shape == "square" && edge >= 0.25 / st.wave_f)
    return doc.error(node["wave_dvdt"] ? node["wave_dvdt"] : node["wave_v"],
                     fmt::format("key 'stress.wave_dvdt' = {:g} V/ns: the square's edge, "
                                 "wave_v / wave_dvdt = {:g} s, must be shorter than a quarter "
                                 "period of wave_f ({:g} s)",
                                 st.wave_dvdt, edge, 0.25 / st.wave_f));
  return Status::Ok();
}

Status read_stress(const YamlDoc& doc, const YAML::Node& node, StressSpec* st) {
  st->loc = doc.loc(node);
  st->given = true;
  Status s = read_map(
      doc, node, "stress",
      {
          {"esd", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->esd_v)},
          {"ground_step", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->step_v)},
          {"ground_rise", read_quantity(doc, Unit::kSecond, Rule::kPositive, &st->step_rise)},
          {"pin_abs_max", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->pin_abs_max)},
          {"pin_cm_limit", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->pin_cm_limit)},
          {"cap_rating", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->cap_rating)},
          {"hot_plug_v", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->hot_plug_v)},
          {"hot_plug_gap", read_quantity(doc, Unit::kSecond, Rule::kPositive, &st->hot_plug_gap)},
          {"wave_v", read_quantity(doc, Unit::kVolt, Rule::kPositive, &st->wave_v)},
          {"wave_f", read_quantity(doc, Unit::kHertz, Rule::kPositive, &st->wave_f)},
          {"wave_shape", read_choice(doc, {"square", "sine"}, &st->wave_shape)},
          {"wave_dvdt", read_quantity(doc, Unit::kNone, Rule::kPositive, &st->wave_dvdt)},
          {"leak_ohms", read_quantity(doc, Unit::kOhm, Rule::kPositive, &st->leak_ohms)},
          {"only",
           [&](const YAML::Node& n, const std::string& p) -> Status {
             if (Status r = read_text_list(doc, &st->only)(n, p); !r.ok()) return r;
             for (size_t i = 0; i < st->only.size(); ++i) {
               const std::vector<std::string>& kinds = stress_kinds_list();
               if (std::find(kinds.begin(), kinds.end(), st->only[i]) == kinds.end())
                 return doc.error(n.IsSequence() ? n[i] : n,
                                  fmt::format("key '{}' = '{}': not a stress scenario (one of "
                                              "cm_step, cm_wave, esd, hot_plug, wire)",
                                              p, st->only[i]));
             }
             return Status::Ok();
           }},
      });
  if (!s.ok()) return s;
  // Bounds that keep the scenarios meaningful and their runs short.
  if (st->esd_v > 30e3)
    return doc.error(node["esd"], fmt::format("key 'stress.esd' = {:g} V: must be at most 30 kV "
                                              "(IEC 61000-4-2 contact discharge tops out at "
                                              "level 4, 8 kV; 30 kV is the highest part rating)",
                                              st->esd_v));
  if (st->step_rise < 1e-9 || st->step_rise > 100e-6)
    return doc.error(node["ground_rise"],
                     fmt::format("key 'stress.ground_rise' = {:g} s: must be from 1 ns to 100 us "
                                 "(the scenario simulates a window of a few rise times)",
                                 st->step_rise));
  if (st->step_v > 2e3)
    return doc.error(node["ground_step"],
                     fmt::format("key 'stress.ground_step' = {:g} V: must be at most 2 kV (a "
                                 "module's stack voltage)",
                                 st->step_v));
  return check_stress_levels(doc, node, *st);
}

}  // namespace

const std::vector<std::string>& stress_kinds() {
  return stress_kinds_list();
}

StatusOr<LinkSpec> read_link_spec(const YamlDoc& doc) {
  LinkSpec spec;
  spec.source = doc.path();
  spec.tx.device = "bq79600";
  spec.stimulus.frames = {"stack-write reg=0x0100 data=02B778BC"};
  const YAML::Node& root = doc.root();
  if (!root.IsMap())
    return doc.error(root, "a link spec is a YAML map with keys name, tx, rx, cable, stimulus");
  bool stimulus_given = false;
  Status s = read_map(
      doc, root, "",
      {
          {"name", read_text(doc, &spec.name)},
          {"tx", [&](const YAML::Node& n,
                     const std::string& p) { return read_end(doc, n, p, &spec.tx); }},
          {"rx", [&](const YAML::Node& n,
                     const std::string& p) { return read_end(doc, n, p, &spec.rx); }},
          {"cable",
           [&](const YAML::Node& n, const std::string&) {
             spec.cable_loc = doc.loc(n);
             return read_cable(doc, n, &spec.cable);
           }},
          {"stimulus",
           [&](const YAML::Node& n, const std::string&) {
             stimulus_given = true;
             spec.stimulus.frames.clear();
             return read_stimulus(doc, n, &spec.stimulus);
           }},
          {"noise", [&](const YAML::Node& n,
                        const std::string&) { return read_noise(doc, n, &spec.noise); }},
          {"stress", [&](const YAML::Node& n,
                         const std::string&) { return read_stress(doc, n, &spec.stress); }},
          {"sim",
           [&](const YAML::Node& n, const std::string& p) {
             Status st = read_map(
                 doc, n, p,
                 {
                     {"tstep", read_quantity(doc, Unit::kSecond, Rule::kPositive, &spec.sim.tstep)},
                     {"tmax", read_quantity(doc, Unit::kSecond, Rule::kPositive, &spec.sim.tmax)},
                     {"method", read_choice(doc, {"trap", "gear"}, &spec.sim.method)},
                     {"reltol", read_quantity(doc, Unit::kNone, Rule::kPositive, &spec.sim.reltol)},
                 });
             if (!st.ok()) return st;
             // The solver's own checks come too late to point at the file: check here.
             if (const std::optional<double> rt = spec.sim.reltol;
                 rt && !(*rt >= 1e-9 && *rt <= 0.1))
               return doc.error(n["reltol"], fmt::format("key 'sim.reltol' = {:g}: must be from "
                                                         "1e-9 to 0.1",
                                                         *rt));
             return Status::Ok();
           }},
      });
  if (!s.ok()) return s;
  if (spec.name.empty() || spec.name.find_first_of("/\\") != std::string::npos)
    return doc.error(root["name"], fmt::format("key 'name' = '{}': must be a non-empty name "
                                               "without '/' (it names the report folder)",
                                               spec.name));
  if (stimulus_given && spec.stimulus.to_script().empty())
    return doc.error(root["stimulus"],
                     "key 'stimulus': give at least one of frames, tones, patterns or script");
  return spec;
}

StatusOr<LinkSpec> read_link_spec_file(const std::string& path) {
  StatusOr<YamlDoc> doc = YamlDoc::load_file(path);
  if (!doc) return doc.status();
  return read_link_spec(*doc);
}

StatusOr<LinkSpec> read_link_spec_text(const std::string& text, const std::string& name) {
  StatusOr<YamlDoc> doc = YamlDoc::from_text(text, name);
  if (!doc) return doc.status();
  return read_link_spec(*doc);
}

}  // namespace isolink::link
