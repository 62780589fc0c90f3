// Runs ngspice in batch mode on a netlist and reads back the probed vectors (tests only).
//
//   StatusOr<Waveform> ng = run_ngspice("rlc.cir", {"v(out)"}, "/tmp/work", ".options
//   reltol=1e-5");
#pragma once

#include <string>
#include <vector>

#include "base/waveform.h"

namespace isolink::testing {

// Copies the netlist without its .end, appends `extra` cards and a .control block that runs it
// and writes the probes with wrdata; returns the waveform (time + one column per probe).
// A non-empty `tran` (e.g. ".tran 1n 20u") replaces the netlist's .tran card(s).
StatusOr<Waveform> run_ngspice(const std::string& netlist, const std::vector<std::string>& probes,
                               const std::string& work_dir, const std::string& extra = "",
                               const std::string& tran = "");

// The options the comparisons use for the ngspice reference run.
inline constexpr const char* kNgspiceTight =
    ".options reltol=1e-6 abstol=1e-12 vntol=1e-9 rshunt=1e12";

// Largest |a - b| over b's time grid (a interpolated linearly), for column k of each, skipping
// times before t_from.
double max_abs_difference(const Waveform& a, size_t ka, const Waveform& b, size_t kb,
                          double t_from = 0.0);

}  // namespace isolink::testing
