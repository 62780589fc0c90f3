// Stress of a pack (isolink stress PACK.yaml, issue 42 item 3): every hop's wire faults (open P,
// open N, P-N short, a line to its module's ground or to the chassis, a leaking pin; the `wire`
// scenarios of analysis/stress.h, in both directions) simulated on the hop's own link spec, and
// for each fault that stops the hop communicating, the chain as if that hop's cable were broken:
// which devices the ring still reaches (the other way round, through the return hop) and which
// none, and what the re-route costs in command timing.
//
//   StatusOr<PackStressResult> r = run_pack_stress(pack, parts, {});
//   for (const HopFault& f : r->faults) ... f.hop, f.scenario.id, f.breaks_hop, f.unreached ...
//
// A hop that stops communicating in either direction counts as broken: commands go down and the
// responses come up the same cable. Identical scenarios (the same circuit, e.g. the hops of one
// link spec) are simulated once and shared.
//
// Contract:
// - Units: SI (s, V, A); hops and devices numbered from 1 as in the pack.
// - Ownership: the result owns its scenarios; the pack and parts are read during the call only.
// - Errors: a Status naming the hop ("hop 3: ..."): a spec whose scenarios do not build or a
//   simulation that fails. A fault that breaks a hop is a result.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "analysis/pack.h"
#include "analysis/pack_spec.h"
#include "analysis/stress.h"

namespace isolink::analysis {

struct HopFault {
  int hop = 0;              // 1..N, N + 1 for the ring's return hop
  StressScenario scenario;  // the wire scenario on the hop's link spec (its results)
  bool breaks_hop = false;  // the hop no longer communicates (scenario.communicates false)
  // When it breaks the hop: the chain with that hop's cable broken (ring_breaks).
  BreakCase reroute;
  // Devices reached the other way round the ring, and the largest delay that adds to a command's
  // arrival at one of them (s; 0 when none is re-routed).
  double reroute_delay_s = 0;
  std::vector<int> unreached;  // devices no command reaches (no ring, or the return hop broken)
};

struct PackStressResult {
  int devices = 0;
  bool ring = false;
  std::vector<HopFault> faults;  // hop order, then the scenario order of analysis/stress.h
  int simulations = 0;           // distinct scenario circuits simulated
  bool survives = true;          // no fault exceeds a pin or part limit
  bool all_reached = true;       // every device stays reachable after any one fault
  std::string verdict;           // one line
  double seconds = 0;
};

// Scenarios a pack stress runs per hop: the options' `only` when given (it must name `wire`
// alone or with others: only wire scenarios apply to a pack), else `wire`.
StatusOr<PackStressResult> run_pack_stress(const PackSpec& pack, const link::PartLibrary& parts,
                                           const StressOptions& opt = {});

// The chain after a fault that breaks hop `hop`: the break case and the re-route's timing cost
// (pure; from ring_breaks and pack_timing).
HopFault reroute_of(const PackSpec& pack, const PackTiming& timing, int hop);

}  // namespace isolink::analysis
