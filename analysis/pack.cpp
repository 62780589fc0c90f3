#include "analysis/pack.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>

#include "analysis/sweep_run.h"
#include "netlists/link/cable.h"
#include "netlists/link/expand.h"
#include "netlists/traffic/command.h"
#include "netlists/traffic/sequences.h"

namespace isolink::analysis {

namespace {

std::vector<int> range(int a, int b, int step) {  // a, a + step, ... through b
  std::vector<int> out;
  for (int k = a; step > 0 ? k <= b : k >= b; k += step) out.push_back(k);
  return out;
}

// Whether a hop's traffic asks for responses (reads), so that it carries both directions.
bool has_reads(const link::LinkSpec& spec) {
  for (const std::string& f : spec.stimulus.frames) {
    StatusOr<traffic::Command> c = traffic::parse_command(f);
    if (c && traffic::is_read(c->kind)) return true;
  }
  return false;
}

}  // namespace

double worst_rel_of(const DirectionWorst& w, std::string* metric) {
  double rel = std::numeric_limits<double>::quiet_NaN();
  for (const WorstMetric& m : w.metrics) {
    if (m.limit == 0 || !std::isfinite(m.margin)) continue;
    const double r = m.margin / std::abs(m.limit);
    if (std::isnan(rel) || r < rel) {
      rel = r;
      if (metric) *metric = m.name;
    }
  }
  return rel;
}

std::vector<BreakCase> ring_breaks(int n, bool ring) {
  std::vector<BreakCase> out;
  const int last = ring ? n + 1 : n;
  for (int b = 0; b <= last; ++b) {
    BreakCase c;
    c.broken = b;
    const int top_normal = b == 0 || b == n + 1 ? n : b - 1;  // devices 1..top_normal
    c.normal_side = range(1, top_normal, 1);
    for (int h = 1; h <= top_normal; ++h) c.carried.push_back({h, false});
    if (b >= 1 && b <= n) {
      if (ring) {
        c.reverse_side = range(n, b, -1);
        c.carried.push_back({n + 1, false});
        for (int h = n; h >= b + 1; --h) c.carried.push_back({h, true});
      } else {
        c.unreached = range(b, n, 1);
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}

namespace {

// The commands the host sends, in order: each frame text, an `auto-address` item as its commands
// (netlists/traffic/sequences.h, the stimulus expands it the same way); a `responses` item is
// what devices send back, not a command of the host's: left out.
StatusOr<std::vector<std::string>> host_commands(const std::vector<std::string>& frames) {
  std::vector<std::string> out;
  for (const std::string& text : frames) {
    const std::vector<std::string_view> tok = traffic::split_ws(text);
    if (!tok.empty() && tok[0] == "responses") continue;
    if (!tok.empty() && tok[0] == "auto-address") {
      StatusOr<std::vector<std::string>> cmds =
          traffic::auto_address_item({tok.begin() + 1, tok.end()});
      if (!cmds) return cmds.status();
      out.insert(out.end(), cmds->begin(), cmds->end());
      continue;
    }
    out.push_back(text);
  }
  return out;
}

}  // namespace

StatusOr<PackTiming> pack_timing(const PackSpec& pack) {
  PackTiming t;
  const TimingSpec& ts = pack.timing;
  const int n = pack.chain_hops();
  for (const HopSpec& h : pack.hops) {
    StatusOr<link::CableModel> m = link::cable_model(h.spec.cable);
    if (!m) return m.status().with_context(fmt::format("hop {}", h.index));
    t.cable_delay.push_back(h.spec.cable.length / m->velocity());
  }
  if (pack.hops.empty()) return t;
  // Cable delay from the bridge to device k (k = 0..n), either way round the ring.
  std::vector<double> up(n + 1, 0.0), down(n + 2, 0.0);
  for (int k = 1; k <= n; ++k) up[k] = up[k - 1] + t.cable_delay[k - 1];
  const bool ring = pack.ring && static_cast<int>(t.cable_delay.size()) > n;
  if (ring) {
    down[n] = t.cable_delay[n];  // the return hop
    for (int k = n - 1; k >= 1; --k) down[k] = down[k + 1] + t.cable_delay[k];
  }
  StatusOr<std::vector<std::string>> commands =
      host_commands(pack.hops.front().spec.stimulus.frames);
  if (!commands) return commands.status().with_context("stimulus");
  for (bool reversed : {false, true}) {
    if (reversed && !ring) break;
    // Device k has the whole command after the bridge's byte delay, the re-clock of every stack
    // device before it and the cables on the way.
    auto cable = [&](int k) { return reversed ? down[k] : up[k]; };
    auto before = [&](int k) { return reversed ? n - k : k - 1; };
    for (const std::string& text : *commands) {
      CommandTiming c;
      c.command = text;
      c.reversed = reversed;
      for (int k = 1; k <= n; ++k)
        c.arrival.push_back(ts.bridge_delay + ts.device_delay * before(k) + cable(k));
      StatusOr<traffic::Command> cmd = traffic::parse_command(text);
      if (cmd && traffic::is_read(cmd->kind)) {
        c.read = true;
        if (cmd->kind == traffic::CommandKind::kSingleRead) {
          if (cmd->device >= 1 && cmd->device <= n)
            c.responders = {cmd->device};
          else
            c.note =
                fmt::format("device {} is not in the stack (1..{}): no response", cmd->device, n);
        } else {
          c.responders = range(1, n, 1);
        }
        // Each response (read_bytes + 6 bytes: header, device, register, data, CRC) leaves its
        // device response_delay after the command is complete; its first byte reaches the bridge
        // one chain byte later plus the re-clock and cables on the way down. The UART back to
        // the host (uart_byte per byte) is slower than the chain, so the bridge sends each
        // response as one UART burst from its first byte on, one response after another.
        const int bytes = cmd->read_bytes + 6;
        std::vector<double> first;
        for (int k : c.responders)
          first.push_back(c.arrival[k - 1] + ts.response_delay + ts.chain_byte +
                          ts.device_delay * before(k) + cable(k));
        std::sort(first.begin(), first.end());
        double end = 0;
        for (double a : first) end = std::max(end, a) + bytes * ts.uart_byte;
        if (!first.empty()) c.response_done = end;
        c.late = ts.timeout && (first.empty() || end > *ts.timeout);
      }
      t.commands.push_back(std::move(c));
    }
  }
  return t;
}

namespace {

// One distinct circuit of the pack: the first hop and direction that has it, and its runs.
struct Distinct {
  link::ExpandedLink link;
  const link::LinkSpec* spec = nullptr;  // the first hop's spec with this circuit
  link::Direction direction = link::Direction::kDown;
  StatusOr<DirectionRun> run = Status::Error("not run");
  StatusOr<DirectionWorst> worst = Status::Error("not run");
};

// The pack's circuits: per hop and direction its own expansion (names and BOM), and the
// distinct circuits the runs are made on.
struct PackCircuits {
  std::vector<std::vector<link::ExpandedLink>> own;  // per hop and direction
  std::vector<Distinct> distinct;
};

// Expands every hop in every direction it carries and keeps one run per distinct circuit
// (out->hops get their indices and runs); errors name the hop.
Status expand_hops(const PackSpec& pack, const link::PartLibrary& parts, const PackOptions& opt,
                   PackResult* out, PackCircuits* c) {
  c->own.resize(pack.hops.size());
  std::map<std::string, int> by_key;
  for (const HopSpec& h : pack.hops) {
    HopResult hr;
    hr.index = h.index;
    std::vector<link::Direction> dirs = h.spec.stimulus.directions;
    if (pack.ring) dirs = {link::Direction::kDown, link::Direction::kUp};
    for (link::Direction d : dirs) {
      StatusOr<link::ExpandedLink> ex = link::expand_link(h.spec, parts, d, opt.run.expand);
      if (!ex) return ex.status().with_context(fmt::format("hop {}", h.index));
      ++out->expansions;
      // A symmetric hop's up direction is the same circuit as its down (node names follow the
      // roles), so it dedupes too.
      const std::string key = link::circuit_key(*ex);
      auto [it, added] = by_key.emplace(key, static_cast<int>(c->distinct.size()));
      if (added)
        c->distinct.push_back({*ex, &h.spec, d, Status::Error("not run"), Status::Error("")});
      hr.runs.push_back(it->second);
      c->own[out->hops.size()].push_back(std::move(*ex));
    }
    out->hops.push_back(std::move(hr));
  }
  out->simulations = static_cast<int>(c->distinct.size());
  return Status::Ok();
}

// Runs every distinct circuit's traffic (and worst case) on opt.jobs threads; the first error.
Status run_distinct(const link::PartLibrary& parts, const PackOptions& opt,
                    std::vector<Distinct>& distinct) {
  const DirectionRunner runner =
      opt.runner ? opt.runner : DirectionRunner([](link::ExpandedLink x, const RunOptions& o) {
        return run_direction(std::move(x), o);
      });
  const WorstRunner worst_runner =
      opt.worst_runner ? opt.worst_runner
                       : WorstRunner([&parts](const link::LinkSpec& spec, link::Direction d,
                                              const WorstOptions& o) -> StatusOr<DirectionWorst> {
                           link::LinkSpec one = spec;
                           one.stimulus.directions = {d};
                           StatusOr<WorstResult> w = worst_case(one, parts, o);
                           if (!w) return w.status();
                           return std::move(w->directions.front());
                         });
  // Jobs 0..n-1: the spec traffic's runs; n..2n-1: the worst cases (the longer jobs, first).
  const size_t n = distinct.size();
  const size_t jobs = opt.worst ? 2 * n : n;
  tbb::task_arena arena(opt.jobs > 0 ? opt.jobs : tbb::task_arena::automatic);
  std::mutex done_mu;
  size_t done = 0;
  arena.execute([&] {
    tbb::parallel_for(size_t{0}, jobs, [&](size_t j) {
      const size_t i = j < n ? j : j - n;
      Distinct& d = distinct[i];
      if (opt.worst && j < n)
        d.worst = worst_runner(*d.spec, d.direction, *opt.worst);
      else
        d.run = runner(d.link, opt.run);
      if (opt.on_job_done) {
        std::lock_guard<std::mutex> lock(done_mu);
        opt.on_job_done(++done, jobs);
      }
    });
  });
  for (const Distinct& d : distinct) {
    if (!d.run) return d.run.status();
    if (opt.worst && !d.worst)
      return d.worst.status().with_context(d.link.description + ", worst case");
  }
  return Status::Ok();
}

// Hop i's spec-traffic result: its directions, verdict, the hop it repeats, its worst margin.
void score_hop(const PackCircuits& c, size_t i, PackResult* out) {
  HopResult& hr = out->hops[i];
  hr.run.pass = true;
  for (size_t k = 0; k < hr.runs.size(); ++k) {
    const int r = hr.runs[k];
    hr.run.directions.push_back(*c.distinct[r].run);
    hr.run.directions.back().link = c.own[i][k];  // this hop's direction, names and BOM
    hr.run.pass = hr.run.pass && c.distinct[r].run->pass;
    hr.run.seconds += c.distinct[r].run->sim.seconds;
  }
  hr.pass = hr.run.pass;
  out->pass = out->pass && hr.pass;
  hr.same_as = hr.index;
  for (size_t j = 0; j < i; ++j)
    if (out->hops[j].runs == hr.runs) {
      hr.same_as = out->hops[j].index;
      break;
    }
  for (const DirectionRun& d : hr.run.directions) {
    LinkRun one;
    one.pass = d.pass;
    one.directions.push_back(d);
    const sweep::PointResult s = sweep::score_run(one);
    if (std::isnan(hr.worst_rel) || s.worst_rel < hr.worst_rel) {
      hr.worst_rel = s.worst_rel;
      hr.worst_metric = s.worst_metric;
      hr.worst_direction = link::direction_name(d.link.direction);
    }
  }
}

// Hop i's worst cases, named for this hop's own directions, and its weakest worst-case margin.
void score_hop_worst(const PackCircuits& c, size_t i, PackResult* out) {
  HopResult& hr = out->hops[i];
  for (size_t k = 0; k < hr.runs.size(); ++k) {
    DirectionWorst w = *c.distinct[hr.runs[k]].worst;
    w.direction = c.own[i][k].direction;      // a symmetric hop's up shares its down's circuit
    w.description = c.own[i][k].description;  // this hop's direction, its device names
    w.receiver = c.own[i][k].receiver;
    hr.worst_pass = hr.worst_pass && w.pass;
    std::string metric;
    const double rel = worst_rel_of(w, &metric);
    if (!std::isnan(rel) && (std::isnan(hr.worst_case_rel) || rel < hr.worst_case_rel)) {
      hr.worst_case_rel = rel;
      hr.worst_case_metric = metric;
      hr.worst_case_direction = link::direction_name(w.direction);
    }
    hr.worst.push_back(std::move(w));
  }
  out->worst_pass = out->worst_pass && hr.worst_pass;
}

// Per hop: its directions, verdict and worst margin; the weakest hop (a failing hop is weaker
// than any passing one), for the spec traffic and for the worst case.
void score_hops(const PackCircuits& c, bool worst, PackResult* out) {
  out->pass = true;
  double weakest_rel = std::numeric_limits<double>::infinity();
  double rank_worst = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < out->hops.size(); ++i) {
    score_hop(c, i, out);
    const HopResult& hr = out->hops[i];
    const double rank = (hr.pass ? 0.0 : -1e9) + (std::isnan(hr.worst_rel) ? -1.0 : hr.worst_rel);
    if (rank < weakest_rel) weakest_rel = rank, out->weakest = hr.index;
    if (!worst) continue;
    score_hop_worst(c, i, out);
    const double wrank =
        (hr.worst_pass ? 0.0 : -1e9) + (std::isnan(hr.worst_case_rel) ? -1.0 : hr.worst_case_rel);
    if (rank_worst > wrank || out->worst_weakest == 0)
      rank_worst = wrank, out->worst_weakest = hr.index;
  }
}

// A ring break: every hop still carrying traffic must pass in the directions it now carries.
BreakResult judge_break(const PackSpec& pack, const PackResult& out, const BreakCase& c) {
  BreakResult b;
  b.c = c;
  b.pass = true;
  for (const BreakCase::Use& u : c.carried) {
    const HopSpec& h = pack.hops[u.hop - 1];
    const HopResult& hr = out.hops[u.hop - 1];
    const link::Direction command = u.reversed ? link::Direction::kUp : link::Direction::kDown;
    const link::Direction reply = u.reversed ? link::Direction::kDown : link::Direction::kUp;
    for (size_t k = 0; k < hr.run.directions.size(); ++k) {
      const DirectionRun& d = hr.run.directions[k];
      const bool needed =
          d.link.direction == command || (d.link.direction == reply && has_reads(h.spec));
      if (!needed) continue;
      const std::string what =
          fmt::format("hop {} {} ({})", u.hop, u.reversed ? "reversed" : "normal",
                      link::direction_name(d.link.direction));
      if (!d.pass) {
        b.pass = false;
        b.failing.push_back(what);
      }
      if (k < hr.worst.size() && !hr.worst[k].pass) {
        b.worst_pass = false;
        b.worst_failing.push_back(what);
      }
    }
  }
  return b;
}

}  // namespace

StatusOr<PackResult> run_pack(const PackSpec& pack, const link::PartLibrary& parts,
                              const PackOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  PackResult out;
  PackCircuits circuits;
  if (Status s = expand_hops(pack, parts, opt, &out, &circuits); !s.ok()) return s;
  if (Status s = run_distinct(parts, opt, circuits.distinct); !s.ok()) return s;
  out.worst_done = opt.worst.has_value();
  out.worst_cases = opt.worst ? static_cast<int>(circuits.distinct.size()) : 0;
  score_hops(circuits, opt.worst.has_value(), &out);
  for (const BreakCase& c : ring_breaks(pack.chain_hops(), pack.ring))
    out.breaks.push_back(judge_break(pack, out, c));
  StatusOr<PackTiming> timing = pack_timing(pack);
  if (!timing) return timing.status();
  out.timing = std::move(*timing);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace isolink::analysis
