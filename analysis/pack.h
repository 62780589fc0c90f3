// The whole pack: every hop of a pack spec simulated and scored, the ring's single-break cases,
// and command timing along the chain.
//
//   StatusOr<PackSpec> pack = read_pack_spec_file(path);
//   StatusOr<PackResult> r = run_pack(*pack, parts, {.jobs = 0});
//   r->pass, r->weakest, r->hops[k].run (a LinkRun per hop), r->breaks, r->timing
//
// Each hop is expanded in each direction it must carry; the expanded circuits are compared as
// SPICE text (title left out) together with the receiver's rule set and the bytes expected, and
// each distinct one is simulated and scored once (oneTBB across them); hops with the same
// circuit share the result. With ring: true every hop is run in both directions: in the
// reversed ring a hop carries commands in its link spec's "up" direction.
//
// With PackOptions::worst set, each distinct circuit and direction also gets the worst case over
// all legal traffic (analysis/worst.h: worst_case of the hop's link spec in that direction, the
// same figures as `isolink worst` on the hop alone), beside the spec traffic's result: its own
// verdict per hop (HopResult::worst_pass) and for the pack (PackResult::worst_pass). The spec
// traffic's verdict (PackResult::pass) stays the pack's verdict, as in `isolink run`. Both kinds
// of job (a circuit's spec-traffic run, a circuit's worst case) share one oneTBB loop.
//
// Contract:
// - Units: SI (s for timing, V and s for margins); hops and devices numbered from 1.
// - Ownership: a PackResult owns its hop runs and worst cases; the pack spec and the part library
//   are read, not kept. PackOptions' runners and on_job_done are called from oneTBB threads
//   (on_job_done under a lock) and must be thread-safe.
// - Errors: a Status, never thrown, naming the hop ("hop 3: ..."): a hop that does not expand, a
//   run or worst case that fails, a cable model that cannot be made. Failing hops are results.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "analysis/pack_spec.h"
#include "analysis/worst.h"
#include "base/status.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

// The hook for a direction's simulation and scoring with the spec's traffic: run_direction by
// default (tests count calls through it).
using DirectionRunner =
    std::function<StatusOr<DirectionRun>(link::ExpandedLink, const RunOptions&)>;

// The hook for a direction's worst case: worst_case(spec with only that direction) by default.
using WorstRunner = std::function<StatusOr<DirectionWorst>(const link::LinkSpec&, link::Direction,
                                                           const WorstOptions&)>;

struct PackOptions {
  int jobs = 0;  // threads across distinct circuits (0: all cores)
  RunOptions run;
  DirectionRunner runner;             // empty: run_direction
  std::optional<WorstOptions> worst;  // set: the worst case over all traffic too
  WorstRunner worst_runner;           // empty: worst_case
  // Called (from the worker threads, one at a time) after each distinct simulation or worst case
  // finishes: how many are done of how many (a progress line; may be empty).
  std::function<void(size_t done, size_t total)> on_job_done;
};

struct HopResult {
  int index = 0;  // HopSpec::index
  LinkRun run;    // the hop's directions (shared with hops of the same circuit)
  bool pass = false;
  double worst_rel = std::numeric_limits<double>::quiet_NaN();  // smallest margin / |limit|
  std::string worst_metric;     // vstart | vend | width | edge | none
  std::string worst_direction;  // down | up
  int same_as = 0;              // the first hop with the same circuits (its own index if none)
  std::vector<int> runs;        // per direction, the distinct simulation it took
  // The worst case over all traffic (PackOptions::worst), per direction as run.directions.
  std::vector<DirectionWorst> worst;
  bool worst_pass = true;
  double worst_case_rel = std::numeric_limits<double>::quiet_NaN();  // smallest margin / |limit|
  std::string worst_case_metric;     // vstart | vend | width_min | width_max | edge
  std::string worst_case_direction;  // down | up
};

// The chain after one cable break (or none).
struct BreakCase {
  int broken = 0;                 // the hop whose cable is broken; 0: none
  std::vector<int> normal_side;   // devices reached up the chain from the bridge
  std::vector<int> reverse_side;  // devices reached through the ring's return hop, top first
  std::vector<int> unreached;     // devices no command reaches
  struct Use {
    int hop = 0;
    bool reversed = false;  // commands go rx -> tx (the link spec's "up")
  };
  std::vector<Use> carried;  // the hops that still carry traffic, in path order
};
// Every case for n stack devices: no break, then a break of each hop 1..n (and the return hop
// n + 1 with a ring).
std::vector<BreakCase> ring_breaks(int n, bool ring);

// When commands arrive and responses return (README section "Packs" has the model).
struct CommandTiming {
  std::string command;
  bool read = false;
  bool reversed = false;        // sent the other way round the ring (through the return hop)
  std::vector<double> arrival;  // s per device 1..n (index 0 = device 1): command complete
  std::vector<int> responders;  // reads: devices that answer
  double response_done = std::numeric_limits<double>::quiet_NaN();  // s, last byte at the host
  bool late = false;                                                // response_done > timeout
  std::string note;  // why a read gets no answer, e.g. "device 20 not in pack"
};
struct PackTiming {
  std::vector<double> cable_delay;  // s per hop (PackSpec::hops order)
  std::vector<CommandTiming> commands;
};
// From the pack's cable models and the traffic of hop 1 (what the host sends).
StatusOr<PackTiming> pack_timing(const PackSpec& pack);

struct BreakResult {
  BreakCase c;
  bool pass = false;                 // every carried hop passes in the directions it carries
  std::vector<std::string> failing;  // "hop 3 reversed (up)"
  // The same over all traffic (PackOptions::worst; true and empty without it).
  bool worst_pass = true;
  std::vector<std::string> worst_failing;
};

struct PackResult {
  std::vector<HopResult> hops;  // PackSpec::hops order
  int expansions = 0;           // hop directions expanded into circuits
  int simulations = 0;          // distinct circuits simulated
  bool pass = false;            // every hop passes
  int weakest = 0;              // index of the hop with the smallest worst_rel
  bool worst_done = false;      // the worst case was computed (PackOptions::worst)
  int worst_cases = 0;          // distinct circuits whose worst case was computed
  bool worst_pass = true;       // every hop passes its worst case (true when not computed)
  int worst_weakest = 0;        // the hop with the smallest worst_case_rel (0: not computed)
  std::vector<BreakResult> breaks;
  PackTiming timing;
  double seconds = 0;
};

// The smallest margin / |limit| over a direction's worst-case metrics (NaN: none); metric gets
// its name.
double worst_rel_of(const DirectionWorst& w, std::string* metric = nullptr);

StatusOr<PackResult> run_pack(const PackSpec& pack, const link::PartLibrary& parts,
                              const PackOptions& opt = {});

}  // namespace isolink::analysis
