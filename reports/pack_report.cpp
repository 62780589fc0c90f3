#include "reports/pack_report.h"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <limits>

#include "analysis/sweep_run.h"
#include "base/file_io.h"
#include "reports/html_report.h"
#include "reports/pack_png.h"
#include "reports/run_images.h"
#include "reports/run_report.h"
#include "reports/worst_report.h"

namespace isolink::reports {

namespace {

using nlohmann::ordered_json;

ordered_json finite(double v) {
  return std::isfinite(v) ? ordered_json(v) : ordered_json(nullptr);
}

std::string devices_text(const std::vector<int>& d) {
  if (d.empty()) return "-";
  // Runs of consecutive devices as a-b.
  std::string s;
  for (size_t i = 0; i < d.size();) {
    size_t j = i;
    const int step = d.size() > i + 1 && d[i + 1] < d[i] ? -1 : 1;
    while (j + 1 < d.size() && d[j + 1] == d[j] + step) ++j;
    s += (s.empty() ? "" : ", ") +
         (j == i ? fmt::format("{}", d[i]) : fmt::format("{}-{}", d[i], d[j]));
    i = j + 1;
  }
  return s;
}

std::string device_name(const PackSpec& pack, int k) {
  return k == 0 ? pack.bridge + " bridge" : fmt::format("device {}", k);
}

std::string hop_devices(const PackSpec& pack, const HopSpec& h) {
  return h.ring_return
             ? fmt::format("{} -> {} (ring return)", device_name(pack, 0), device_name(pack, h.to))
             : fmt::format("{} -> {}", device_name(pack, h.from), device_name(pack, h.to));
}

std::string margin_text(double v, double scale, const char* unit) {
  return std::isfinite(v) ? fmt::format("{:+.3g} {}", v * scale, unit) : "-";
}

// "pass" | "fail", or null when the worst case was not computed (--no-worst).
ordered_json worst_verdict(const PackResult& r, bool pass) {
  return r.worst_done ? ordered_json(pass ? "pass" : "fail") : ordered_json(nullptr);
}

// Per metric (vstart, vend, width, edge as sweep::kMetrics) the smallest worst-case margin over
// a hop's directions, in SI units; width is the smaller of width_min and width_max.
std::array<double, 4> worst_case_margins(const HopResult& h) {
  std::array<double, 4> out;
  out.fill(std::numeric_limits<double>::quiet_NaN());
  for (const analysis::DirectionWorst& d : h.worst)
    for (const analysis::WorstMetric& m : d.metrics) {
      const size_t k = m.name == "vstart" ? 0 : m.name == "vend" ? 1 : m.name == "edge" ? 3 : 2;
      if (std::isnan(out[k]) || m.margin < out[k]) out[k] = m.margin;
    }
  return out;
}

}  // namespace

std::string isolation_short(const link::IsolationSpec& iso) {
  if (iso.type == "capchoke") return iso.chokes.size() > 1 ? "cap+2 chokes" : "cap+choke";
  if (iso.type == "transformer") return "xfmr";
  if (iso.type == "transformer_choke") return "xfmr+choke";
  return iso.type;
}

nlohmann::ordered_json pack_report_json(const PackSpec& pack, const PackResult& r) {
  ordered_json hops = ordered_json::array();
  for (size_t i = 0; i < r.hops.size(); ++i) {
    const HopResult& h = r.hops[i];
    const HopSpec& s = pack.hops[i];
    ordered_json run = run_report_json(s.spec, h.run);
    // The worst case over all traffic beside each direction, as `isolink worst --json` has it.
    for (size_t k = 0; k < h.worst.size() && k < run["directions"].size(); ++k) {
      analysis::WorstResult one;
      one.directions = {h.worst[k]};
      one.pass = h.worst[k].pass;
      const ordered_json wj = worst_json(one)["directions"][0];
      run["directions"][k]["worst_verdict"] = wj["verdict"];
      run["directions"][k]["worst_reasons"] = wj["reasons"];
      run["directions"][k]["worst"] = wj["worst"];
    }
    hops.push_back(ordered_json{{"index", h.index},
                                {"from", s.from},
                                {"to", s.to},
                                {"ring_return", s.ring_return},
                                {"spec", s.file.empty() ? pack.source : s.file},
                                {"verdict", h.pass ? "pass" : "fail"},
                                {"worst_margin_rel", finite(h.worst_rel)},
                                {"worst_metric", h.worst_metric},
                                {"worst_direction", h.worst_direction},
                                {"worst_case_verdict", worst_verdict(r, h.worst_pass)},
                                {"worst_case_margin_rel", finite(h.worst_case_rel)},
                                {"worst_case_metric", h.worst_case_metric},
                                {"worst_case_direction", h.worst_case_direction},
                                {"same_circuit_as", h.same_as},
                                {"cable_delay_s", finite(r.timing.cable_delay[i])},
                                {"directions", run["directions"]},
                                {"link", run["spec"]}});
  }
  ordered_json breaks = ordered_json::array();
  for (const BreakResult& b : r.breaks) {
    ordered_json carried = ordered_json::array();
    for (const BreakCase::Use& u : b.c.carried)
      carried.push_back({{"hop", u.hop}, {"reversed", u.reversed}});
    breaks.push_back(ordered_json{{"broken_hop", b.c.broken},
                                  {"normal_side", b.c.normal_side},
                                  {"reverse_side", b.c.reverse_side},
                                  {"unreached", b.c.unreached},
                                  {"carried", carried},
                                  {"verdict", b.pass ? "pass" : "fail"},
                                  {"failing", b.failing},
                                  {"worst_verdict", worst_verdict(r, b.worst_pass)},
                                  {"worst_failing", b.worst_failing}});
  }
  ordered_json commands = ordered_json::array();
  for (const CommandTiming& c : r.timing.commands) {
    ordered_json arrival = ordered_json::array();
    for (double a : c.arrival) arrival.push_back(finite(a));
    commands.push_back(ordered_json{{"command", c.command},
                                    {"route", c.reversed ? "reversed" : "normal"},
                                    {"arrival_s", arrival},
                                    {"read", c.read},
                                    {"responders", c.responders},
                                    {"response_done_s", finite(c.response_done)},
                                    {"late", c.late},
                                    {"note", c.note}});
  }
  const TimingSpec& t = pack.timing;
  ordered_json timing{{"bridge_delay_s", t.bridge_delay},
                      {"device_delay_s", t.device_delay},
                      {"uart_byte_s", t.uart_byte},
                      {"chain_byte_s", t.chain_byte},
                      {"response_delay_s", t.response_delay},
                      {"timeout_s", t.timeout ? ordered_json(*t.timeout) : ordered_json(nullptr)},
                      {"commands", commands}};
  return ordered_json{
      {"verdict", r.pass ? "pass" : "fail"},
      {"worst_verdict", worst_verdict(r, r.worst_pass)},
      {"name", pack.name},
      {"source", pack.source},
      {"bridge", pack.bridge},
      {"stack", pack.stack},
      {"devices", pack.devices()},
      {"ring", pack.ring},
      {"weakest_hop", r.weakest},
      {"worst_weakest_hop", r.worst_done ? ordered_json(r.worst_weakest) : ordered_json(nullptr)},
      {"worst_cases", r.worst_cases},
      {"run_time_s", r.seconds},
      {"expansions", r.expansions},
      {"simulations", r.simulations},
      {"hops", hops},
      {"ring_breaks", breaks},
      {"timing", timing}};
}

namespace {

// The title, the verdicts (spec traffic and worst case), the weakest hops and the diagram.
std::string verdict_markdown(const PackSpec& pack, const PackResult& r,
                             const std::string& diagram) {
  std::string md;
  md += fmt::format("# isolink pack report: {}\n\n", pack.name);
  int failing = 0;
  for (const HopResult& h : r.hops) failing += h.pass ? 0 : 1;
  md += fmt::format("**Verdict: {}**", r.pass ? "PASS" : "FAIL");
  md += fmt::format(
      " ({} of {} hops pass; {} bridge, {} x {}{}; spec `{}`; {} distinct circuits "
      "simulated for {} hop directions in {:.2f} s)\n\n",
      r.hops.size() - failing, r.hops.size(), pack.bridge, pack.devices(), pack.stack,
      pack.ring ? ", ring" : "", pack.source, r.simulations, r.expansions, r.seconds);
  if (r.worst_done) {
    int worst_failing = 0;
    for (const HopResult& h : r.hops) worst_failing += h.worst_pass ? 0 : 1;
    md += fmt::format(
        "**Worst case over all traffic: {}** ({} of {} hops pass; {} worst cases computed, one "
        "per distinct circuit and direction).\n\n",
        r.worst_pass ? "PASS" : "FAIL", r.hops.size() - worst_failing, r.hops.size(),
        r.worst_cases);
  }
  if (r.weakest > 0)
    md += fmt::format("Weakest hop: **hop {}** ({}).\n\n", r.weakest,
                      hop_devices(pack, pack.hops[r.weakest - 1]));
  if (r.worst_done && r.worst_weakest > 0)
    md += fmt::format("Weakest hop over all traffic: **hop {}** ({}).\n\n", r.worst_weakest,
                      hop_devices(pack, pack.hops[r.worst_weakest - 1]));
  if (!diagram.empty()) md += fmt::format("![pack diagram]({})\n\n", diagram);
  return md;
}

// One row of the hops table: hop i's devices, parts, verdict, margins (and worst case), images.
std::string hop_row_markdown(const PackSpec& pack, const PackResult& r,
                             const std::vector<std::string>& hop_dirs, size_t i) {
  std::string md;
  const HopResult& h = r.hops[i];
  const HopSpec& s = pack.hops[i];
  const analysis::sweep::PointResult p = analysis::sweep::score_run(h.run);
  const bool weakest = h.index == r.weakest;
  const std::string b = weakest ? "**" : "";
  std::string worst =
      std::isfinite(h.worst_rel)
          ? fmt::format("{:+.1f} % {} ({})", h.worst_rel * 100, h.worst_metric, h.worst_direction)
          : "-";
  std::string images = i < hop_dirs.size() && !hop_dirs[i].empty()
                           ? fmt::format("[eye]({0}/eye.png), [wave]({0}/wave.png)", hop_dirs[i])
                           : "-";
  if (h.same_as != h.index) images += fmt::format(" (same circuit as hop {})", h.same_as);
  md += fmt::format("| {b}{}{}{b} | {} | {} / {} | {} | {} | {b}{}{b} | {} | {} | {} | {} |",
                    h.index, weakest ? " (weakest)" : "", hop_devices(pack, s),
                    isolation_short(s.spec.tx.isolation), isolation_short(s.spec.rx.isolation),
                    fmt::format("{:g} m {}", s.spec.cable.length, s.spec.cable.material),
                    h.pass ? "pass" : "**FAIL**", worst, margin_text(p.margin[0], 1, "V"),
                    margin_text(p.margin[1], 1, "V"), margin_text(p.margin[2], 1e9, "ns"),
                    margin_text(p.margin[3], 1e9, "ns"), fmt::arg("b", b));
  if (r.worst_done) {
    const std::array<double, 4> wc = worst_case_margins(h);
    const std::string wb = h.index == r.worst_weakest ? "**" : "";
    md += fmt::format(
        " {} | {wb}{}{wb} | {} | {} | {} | {} |", h.worst_pass ? "pass" : "**FAIL**",
        std::isfinite(h.worst_case_rel) ? fmt::format("{:+.1f} % {} ({})", h.worst_case_rel * 100,
                                                      h.worst_case_metric, h.worst_case_direction)
                                        : "-",
        margin_text(wc[0], 1, "V"), margin_text(wc[1], 1, "V"), margin_text(wc[2], 1e9, "ns"),
        margin_text(wc[3], 1e9, "ns"), fmt::arg("wb", wb));
  }
  md += fmt::format(" {} |\n", images);
  return md;
}

// The hops table: its explanation, header and one row per hop.
std::string hops_markdown(const PackSpec& pack, const PackResult& r,
                          const std::vector<std::string>& hop_dirs) {
  std::string md;
  md +=
      "## Hops\n\nMargins are the worst over the hop's directions (positive = inside the "
      "limit); the relative margin is margin / |limit| of the worst metric.\n\n";
  if (r.worst_done)
    md +=
        "The worst-case columns (WC) are the worst over all legal traffic (`isolink worst` on the "
        "hop alone: the lowest VSTART and VEND, the narrowest and widest pulse, the slowest edge "
        "any legal traffic produces); WC width is the smaller of the narrowest and widest pulse's "
        "margins.\n\n";
  md +=
      "| hop | devices | isolation (tx / rx) | cable | verdict | worst (rel) | VSTART | VEND | "
      "width | edge |";
  if (r.worst_done)
    md += " worst case | WC worst (rel) | WC VSTART | WC VEND | WC width | WC edge |";
  md += " images |\n|---|---|---|---|---|---|---|---|---|---|";
  if (r.worst_done) md += "---|---|---|---|---|---|";
  md += "---|\n";
  for (size_t i = 0; i < r.hops.size(); ++i) md += hop_row_markdown(pack, r, hop_dirs, i);
  md += "\n";
  return md;
}

// Why each failing hop fails (spec traffic, then worst case), once per distinct circuit.
std::string hop_failures_markdown(const PackResult& r) {
  std::string md;
  for (size_t i = 0; i < r.hops.size(); ++i) {
    const HopResult& h = r.hops[i];
    if (h.pass || h.same_as != h.index) continue;
    const analysis::sweep::PointResult p = analysis::sweep::score_run(h.run);
    md += fmt::format("Hop {} fails: {}.\n\n", h.index, p.reason);
  }
  for (size_t i = 0; i < r.hops.size(); ++i) {
    const HopResult& h = r.hops[i];
    if (h.worst_pass || h.same_as != h.index) continue;
    std::string why;
    for (const analysis::DirectionWorst& d : h.worst)
      for (const std::string& reason : d.reasons)
        why += fmt::format("{}{}: {}", why.empty() ? "" : "; ", link::direction_name(d.direction),
                           reason);
    md +=
        fmt::format("Hop {} fails its worst case{}{}.\n\n", h.index, why.empty() ? "" : ": ", why);
  }
  return md;
}

// The ring and cable breaks table: who is reached which way, the hops in use, the verdict.
std::string breaks_markdown(const PackSpec& pack, const PackResult& r) {
  std::string md;
  md += "## Ring and cable breaks\n\n";
  md += pack.ring ? "The top device's COMH is wired back to the bridge's COML. After a break the "
                    "host reverses direction for the devices above it and reaches them through the "
                    "return hop; a reversed hop carries commands from its rx end to its tx end.\n\n"
                  : "No ring: a break cuts off every device above it.\n\n";
  md +=
      "| broken hop | reached from the bridge | reached through the ring | unreached | hops "
      "in use | verdict |\n|---|---|---|---|---|---|\n";
  for (const BreakResult& b : r.breaks) {
    std::string used;
    for (const BreakCase::Use& u : b.c.carried)
      used += (used.empty() ? "" : " ") + fmt::format("{}{}", u.hop, u.reversed ? "r" : "");
    std::string verdict = b.pass ? "pass" : "**FAIL**";
    if (!b.failing.empty()) {
      verdict += ": ";
      for (size_t k = 0; k < b.failing.size(); ++k) verdict += (k ? ", " : "") + b.failing[k];
    }
    if (!b.c.unreached.empty()) verdict += b.failing.empty() ? ": devices cut off" : "";
    if (r.worst_done && !b.worst_pass) {
      verdict += "; worst case **FAIL**: ";
      for (size_t k = 0; k < b.worst_failing.size(); ++k)
        verdict += (k ? ", " : "") + b.worst_failing[k];
    }
    md += fmt::format("| {} | {} | {} | {} | {} | {} |\n",
                      b.c.broken == 0 ? "none" : fmt::format("{}", b.c.broken),
                      devices_text(b.c.normal_side), devices_text(b.c.reverse_side),
                      devices_text(b.c.unreached), used.empty() ? "-" : used, verdict);
  }
  md += "\n(`5r`: hop 5 reversed.)\n\n";
  return md;
}

// When each device has a command and the responses are back at the host.
std::string timing_markdown(const PackSpec& pack, const PackResult& r) {
  std::string md;
  md += "## Command timing\n\n";
  const TimingSpec& t = pack.timing;
  md += fmt::format(
      "After the host has sent the last byte: the bridge's byte delay {:g} us, {:g} "
      "us per stack device before the addressed one, and each hop's cable delay "
      "(length / velocity of its cable model). Responses: {:g} us per UART byte "
      "back to the host, {:g} us per chain byte, response delay {:g} us{}.\n\n",
      t.bridge_delay * 1e6, t.device_delay * 1e6, t.uart_byte * 1e6, t.chain_byte * 1e6,
      t.response_delay * 1e6, t.timeout ? fmt::format(", timeout {:g} us", *t.timeout * 1e6) : "");
  for (const CommandTiming& c : r.timing.commands) {
    md += c.reversed
              ? fmt::format(
                    "`{}` sent the other way round the ring: device {} has it after "
                    "{:.2f} us, device 1 last after {:.2f} us",
                    c.command, pack.devices(), c.arrival.back() * 1e6, c.arrival.front() * 1e6)
              : fmt::format("`{}`: the top device (device {}) has it after {:.2f} us", c.command,
                            pack.devices(), c.arrival.back() * 1e6);
    if (c.read)
      md += std::isfinite(c.response_done)
                ? fmt::format(
                      "; the response{} from device{} {} is back at the host after "
                      "{:.2f} us{}",
                      c.responders.size() > 1 ? "s" : "", c.responders.size() > 1 ? "s" : "",
                      devices_text(c.responders), c.response_done * 1e6,
                      c.late ? ": **LATE** (after the timeout)" : "")
                : fmt::format("; {}{}", c.note, c.late ? ": **LATE**" : "");
    md += ".\n\n";
  }
  if (!r.timing.commands.empty()) {
    md += "| device | hop cable delay | command complete |" +
          std::string(pack.ring ? " through the ring |" : "") + "\n|---|---|---|" +
          (pack.ring ? "---|" : "") + "\n";
    const CommandTiming& c = r.timing.commands.front();
    const CommandTiming* rev = nullptr;
    for (const CommandTiming& x : r.timing.commands)
      if (x.reversed && x.command == c.command) rev = &x;
    for (int k = 1; k <= pack.devices(); ++k) {
      md += fmt::format("| {} | {:.2f} ns | {:.2f} us |", k, r.timing.cable_delay[k - 1] * 1e9,
                        c.arrival[k - 1] * 1e6);
      if (pack.ring && rev) md += fmt::format(" {:.2f} us |", rev->arrival[k - 1] * 1e6);
      md += "\n";
    }
    md += fmt::format("\n(for `{}`)\n", c.command);
  }
  return md;
}

}  // namespace

std::string pack_report_markdown(const PackSpec& pack, const PackResult& r,
                                 const std::string& diagram,
                                 const std::vector<std::string>& hop_dirs) {
  return verdict_markdown(pack, r, diagram) + hops_markdown(pack, r, hop_dirs) +
         hop_failures_markdown(r) + breaks_markdown(pack, r) + timing_markdown(pack, r);
}

PackDiagram pack_diagram(const PackSpec& pack, const PackResult& r) {
  PackDiagram d;
  d.title = fmt::format("{}: {} bridge, {} x {}{}", pack.name, pack.bridge, pack.devices(),
                        pack.stack, pack.ring ? ", ring" : "");
  d.verdict = r.pass ? "PASS" : "FAIL";
  d.devices = pack.devices();
  d.ring = pack.ring;
  d.weakest = r.weakest;
  for (size_t i = 0; i < r.hops.size(); ++i) {
    const HopSpec& s = pack.hops[i];
    PackDiagram::Hop h;
    h.index = s.index;
    h.ring_return = s.ring_return;
    h.pass = r.hops[i].pass;
    h.margin = r.hops[i].worst_rel;
    h.length = s.spec.cable.length;
    h.isolation =
        isolation_short(s.spec.tx.isolation) == isolation_short(s.spec.rx.isolation)
            ? isolation_short(s.spec.tx.isolation)
            : isolation_short(s.spec.tx.isolation) + "/" + isolation_short(s.spec.rx.isolation);
    d.hops.push_back(std::move(h));
  }
  return d;
}

namespace {

// report.json for the page: each hop's directions keep their verdicts, reasons and worst margins
// but not the per-pulse lists (16 hops of them made the page megabytes larger).
ordered_json pack_html_json(const PackSpec& pack, const PackResult& r) {
  ordered_json j = pack_report_json(pack, r);
  for (ordered_json& h : j["hops"])
    for (ordered_json& d : h["directions"])
      for (const char* k : {"check", "tones"})
        if (d.contains(k) && d[k].is_object())
          for (const char* drop : {"pulses", "ringing", "idle", "decoded"}) d[k].erase(drop);
  return j;
}

}  // namespace

Status write_pack_bundle(const PackSpec& pack, const PackResult& r, const std::string& dir,
                         bool no_images, std::vector<std::string>* files) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    return Status::Error(fmt::format("{}: error: cannot create the folder: {}", dir, ec.message()));
  std::vector<std::string> hop_dirs(r.hops.size());
  std::string diagram;
  if (!no_images) {
    for (size_t i = 0; i < r.hops.size(); ++i) {
      hop_dirs[i] = fmt::format("hop_{:02}", r.hops[i].index);
      fs::create_directories(dir + "/" + hop_dirs[i], ec);
      if (ec)
        return Status::Error(fmt::format("{}/{}: error: cannot create the folder: {}", dir,
                                         hop_dirs[i], ec.message()));
    }
    // Each distinct circuit's images once, in parallel; then copies for the hops sharing it.
    std::vector<Status> drawn(r.hops.size(), Status::Ok());
    std::vector<std::vector<std::string>> images(r.hops.size());
    tbb::parallel_for(size_t{0}, r.hops.size(), [&](size_t i) {
      if (r.hops[i].same_as == r.hops[i].index)
        drawn[i] = render_run_images(pack.hops[i].spec, r.hops[i].run, dir + "/" + hop_dirs[i],
                                     &images[i]);
    });
    for (const Status& s : drawn)
      if (!s.ok()) return s;
    for (size_t i = 0; i < r.hops.size(); ++i) {
      const HopResult& h = r.hops[i];
      if (h.same_as != h.index) {
        // Same circuits as an earlier hop: its images, copied (through a temporary name).
        const size_t src = static_cast<size_t>(h.same_as - 1);
        for (const std::string& f : images[src]) {
          const std::string to = dir + "/" + hop_dirs[i] + "/" + f;
          fs::copy_file(dir + "/" + hop_dirs[src] + "/" + f, to + ".tmp",
                        fs::copy_options::overwrite_existing, ec);
          if (!ec) fs::rename(to + ".tmp", to, ec);
          if (ec)
            return Status::Error(fmt::format("{}: error: cannot write: {}", to, ec.message()));
          images[i].push_back(f);
        }
      }
      for (const std::string& f : images[i]) files->push_back(hop_dirs[i] + "/" + f);
    }
    diagram = "pack.png";
    if (Status s = draw_pack_png(pack_diagram(pack, r), dir + "/" + diagram); !s.ok()) return s;
    files->push_back(diagram);
  }
  if (Status s = write_file_atomic(dir + "/report.json", pack_report_json(pack, r).dump(2) + "\n");
      !s.ok())
    return s;
  files->push_back("report.json");
  if (Status s =
          write_file_atomic(dir + "/report.md", pack_report_markdown(pack, r, diagram, hop_dirs));
      !s.ok())
    return s;
  files->push_back("report.md");
  std::string png;
  if (!diagram.empty()) {
    StatusOr<std::string> bytes = read_input_file(dir + "/" + diagram);
    if (!bytes) return bytes.status();
    png = std::move(*bytes);
  }
  if (Status s =
          write_file_atomic(dir + "/report.html", pack_report_html(pack_html_json(pack, r), png));
      !s.ok())
    return s;
  files->push_back("report.html");
  return Status::Ok();
}

std::string pack_summary_text(const PackSpec& pack, const PackResult& r) {
  std::string s = fmt::format("{}: {} ({} hops, {} circuits simulated, {:.2f} s)\n", pack.name,
                              r.pass ? "pass" : "FAIL", r.hops.size(), r.simulations, r.seconds);
  if (r.worst_done)
    s += fmt::format("  worst case over all traffic: {} ({} computed)\n",
                     r.worst_pass ? "pass" : "FAIL", r.worst_cases);
  for (const HopResult& h : r.hops)
    if (!h.pass || !h.worst_pass)
      s += fmt::format("  hop {}: {}\n", h.index,
                       !h.pass && !h.worst_pass ? "FAIL (spec traffic and worst case)"
                       : !h.pass                ? "FAIL (spec traffic)"
                                                : "FAIL (worst case)");
  if (r.weakest > 0) {
    const HopResult& w = r.hops[r.weakest - 1];
    s += fmt::format(
        "  weakest: hop {} ({}), worst margin {} ({}, {})\n", w.index,
        hop_devices(pack, pack.hops[w.index - 1]),
        std::isfinite(w.worst_rel) ? fmt::format("{:+.1f} %", w.worst_rel * 100) : "none judged",
        w.worst_metric, w.worst_direction);
  }
  for (const BreakResult& b : r.breaks)
    if (!b.pass && b.c.broken > 0 && pack.ring)
      s += fmt::format("  break at hop {}: FAIL\n", b.c.broken);
  for (const CommandTiming& c : r.timing.commands)
    if (c.late)
      s += fmt::format("  late response: {} ({} route)\n", c.command,
                       c.reversed ? "reversed" : "normal");
  return s;
}

}  // namespace isolink::reports
