// The text parts of the `isolink pack` bundle: report.json and report.md. The diagram (pack.png)
// comes from pack_png.h, the per-hop images from run_images.h.
//
//   nlohmann::ordered_json j = pack_report_json(pack, result);
//   std::string md = pack_report_markdown(pack, result, "pack.png", hop_dirs);
//
// Contract: pure functions of their arguments, which they only read: no I/O, no errors. Units
// are SI, named in the JSON keys (`_s`, `_V`, `_ns`) and the Markdown text.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/pack.h"
#include "analysis/pack_spec.h"

namespace isolink::reports {

using analysis::BreakCase;
using analysis::BreakResult;
using analysis::CommandTiming;
using analysis::HopResult;
using analysis::HopSpec;
using analysis::PackResult;
using analysis::PackSpec;
using analysis::TimingSpec;

// verdict, weakest_hop, hops[] {index, verdict, directions[] as in `isolink run`'s report.json},
// ring_breaks[], timing.
nlohmann::ordered_json pack_report_json(const PackSpec& pack, const PackResult& r);
// One row per hop (the weakest in bold), the ring's break cases, command timing, the diagram.
// hop_dirs: per hop (PackSpec::hops order) its image folder relative to the report ("" for none).
std::string pack_report_markdown(const PackSpec& pack, const PackResult& r,
                                 const std::string& diagram,
                                 const std::vector<std::string>& hop_dirs);
// Writes the bundle to dir (created): report.json, report.md, pack.png (unless no_images), and
// per hop hop_NN/ with eye.png and wave.png (drawn once per distinct circuit, copied for the
// hops that share it). files gets the paths written, relative to dir.
Status write_pack_bundle(const PackSpec& pack, const PackResult& r, const std::string& dir,
                         bool no_images, std::vector<std::string>* files);
// Terminal lines: the verdict, the weakest hop, failing hops and break cases.
std::string pack_summary_text(const PackSpec& pack, const PackResult& r);
// "cap", "xfmr", "cap+choke" ...: an end's isolation in a few letters (tables, the diagram).
std::string isolation_short(const link::IsolationSpec& iso);

}  // namespace isolink::reports
