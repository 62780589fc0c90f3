#include "analysis/pack_stress.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "netlists/spice_writer.h"

namespace isolink::analysis {

namespace {

// A scenario's circuit as text, its title left out: equal texts are the same simulation.
std::string circuit_key(const StressScenario& s) {
  Netlist n = s.link.netlist;
  n.title.clear();
  return s.id + "\n" + write_spice(n);
}

std::string device_list(const std::vector<int>& d) {
  std::string s;
  for (int k : d) s += (s.empty() ? "" : ", ") + std::to_string(k);
  return s;
}

}  // namespace

HopFault reroute_of(const PackSpec& pack, const PackTiming& timing, int hop) {
  HopFault f;
  f.hop = hop;
  f.breaks_hop = true;
  const std::vector<BreakCase> cases = ring_breaks(pack.chain_hops(), pack.ring);
  if (hop >= 0 && hop < static_cast<int>(cases.size())) f.reroute = cases[hop];
  f.unreached = f.reroute.unreached;
  for (const CommandTiming& r : timing.commands) {
    if (!r.reversed) continue;
    for (const CommandTiming& n : timing.commands) {
      if (n.reversed || n.command != r.command) continue;
      for (int k : f.reroute.reverse_side)
        if (k >= 1 && k <= static_cast<int>(std::min(r.arrival.size(), n.arrival.size())))
          f.reroute_delay_s = std::max(f.reroute_delay_s, r.arrival[k - 1] - n.arrival[k - 1]);
    }
  }
  return f;
}

StatusOr<PackStressResult> run_pack_stress(const PackSpec& pack, const link::PartLibrary& parts,
                                           const StressOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  PackStressResult out;
  out.devices = pack.devices();
  out.ring = pack.ring;
  StressOptions so = opt;
  if (so.only.empty()) so.only = {"wire"};
  if (std::find(so.only.begin(), so.only.end(), "wire") == so.only.end())
    return Status::Error(fmt::format(
        "isolink stress on a pack runs wire faults per hop: --only must include 'wire' (got {})",
        fmt::join(so.only, ",")));
  so.only = {"wire"};
  so.results_only = true;
  StatusOr<PackTiming> timing = pack_timing(pack);
  if (!timing) return timing.status();
  // Every hop's scenarios built; identical circuits (the same spec on several hops) run once.
  std::map<std::string, size_t> first;  // circuit -> its index in `distinct`
  std::vector<StressScenario> distinct;
  std::vector<const link::LinkSpec*> specs;
  std::vector<std::pair<int, size_t>> uses;  // (hop, index in distinct), in hop order
  for (const HopSpec& h : pack.hops) {
    StatusOr<std::vector<StressScenario>> built = build_stress_scenarios(h.spec, parts, so);
    if (!built) return built.status().with_context(fmt::format("hop {}", h.index));
    for (StressScenario& s : *built) {
      auto [it, fresh] = first.emplace(circuit_key(s), distinct.size());
      if (fresh) {
        s.id = fmt::format("hop{}_{}", h.index, s.id);  // the progress line says whose it is
        distinct.push_back(std::move(s));
        specs.push_back(&h.spec);
      }
      uses.emplace_back(h.index, it->second);
    }
  }
  if (Status st = run_stress_scenarios(distinct, specs, parts, so); !st.ok()) return st;
  out.simulations = static_cast<int>(distinct.size());
  std::vector<std::pair<int, StressScenario>> runs;
  for (auto [hop, k] : uses) {
    StressScenario s = distinct[k];
    s.id = s.id.substr(s.id.find('_') + 1);  // its own id, as on a link
    runs.emplace_back(hop, std::move(s));
  }
  for (auto& [hop, s] : runs) {
    HopFault f;
    const bool breaks = s.communicates.has_value() && !*s.communicates;
    if (breaks) f = reroute_of(pack, *timing, hop);
    f.hop = hop;
    f.breaks_hop = breaks;
    f.scenario = std::move(s);
    out.survives = out.survives && f.scenario.survives;
    out.all_reached = out.all_reached && f.unreached.empty();
    out.faults.push_back(std::move(f));
  }
  const HopFault* worst = nullptr;
  for (const HopFault& f : out.faults)
    if (!f.unreached.empty() && (worst == nullptr || f.unreached.size() > worst->unreached.size()))
      worst = &f;
  int broke = 0;
  for (const HopFault& f : out.faults) broke += f.breaks_hop ? 1 : 0;
  out.verdict =
      worst != nullptr ? fmt::format(
                             "{} of {} hop faults stop a hop; worst: hop {} {} leaves devices {} "
                             "unreached",
                             broke, out.faults.size(), worst->hop, worst->scenario.id,
                             device_list(worst->unreached))
      : broke > 0
          ? fmt::format(
                "{} of {} hop faults stop a hop; the ring reaches every device "
                "round the other way",
                broke, out.faults.size())
          : fmt::format("every hop communicates through each of its {} faults", out.faults.size());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace isolink::analysis
