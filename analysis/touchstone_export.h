// A cable's S-parameters from isolink's AC analysis, as a Touchstone file would hold them: the
// ground truth the measured-cable path (netlists/link/touchstone_cable.h) is checked against, and
// `isolink export-touchstone`.
//
//   TouchstoneExportOptions o;   // 10 kHz - 500 MHz, 500 points, linear as a VNA sweeps
//   StatusOr<Touchstone> t = cable_touchstone(spec.cable, o);
//   write_file_atomic("cable.s4p", write_touchstone(*t, "isolink export-touchstone"));
//
// The cable alone, built by add_cable between four ports single-ended to the chassis (1 = tx P,
// 2 = tx N, 3 = rx P, 4 = rx N): each port driven in turn by a 1 V source, the others shorted by
// theirs, Y(:, j) the currents into the ports; S = (I - z0 Y)(I + z0 Y)^-1.
#pragma once

#include <string>

#include "base/status.h"
#include "netlists/link/cable.h"
#include "netlists/touchstone.h"

namespace isolink::analysis {

struct TouchstoneExportOptions {
  double f_start = 10e3;  // Hz, > 0
  double f_stop = 500e6;  // Hz, > f_start
  int points = 500;       // 2 .. 100000
  bool log_spacing = false;
  double z0 = 50;            // ohm
  double edge_time = 10e-9;  // s: sets the native cable's segment count as `run` does
};

StatusOr<Touchstone> cable_touchstone(const link::CableSpec& cable,
                                      const TouchstoneExportOptions& opt);

}  // namespace isolink::analysis
