// Touchstone reader and writer: an N-port's measured (or computed) network data, .sNp files.
//
//   StatusOr<Touchstone> t = read_touchstone_file("harness.s4p");
//   if (!t) return t.status();   // "harness.s4p:12:7: error: 8 values for 4-port data, ..."
//   t->s[i]                      // the S matrix (reference t->z0) at t->freqs[i] Hz
//
// Versions and keys taken:
// - 1.x: the option line `# [HZ|KHZ|MHZ|GHZ] [S|Y|Z] [DB|MA|RI] [R n]` (defaults GHZ S MA R 50),
//   the port count from the name's extension (.s1p ... .s9p, .sNNp), data in rows: 2-port points
//   on one line in the order 11 21 12 22, other counts row by row over as many lines as needed,
//   each point starting on a new line; a 2-port's noise block (a frequency that does not rise,
//   five values on its line) ends the network data and is skipped.
// - 2.0: [Version] 2.0, [Number of Ports], [Two-Port Data Order] 12_21 | 21_12,
//   [Number of Frequencies], [Number of Noise Frequencies], [Reference] (per port),
//   [Matrix Format] Full | Lower | Upper, [Network Data], [Noise Data] (skipped),
//   [Begin Information] .. [End Information] (skipped), [End]. [Mixed-Mode Order] is refused
//   (the cable needs single-ended ports), as is any other keyword, naming it.
// - `!` comments anywhere; keywords and options in any case.
// Refused with file:line:col: H and G parameters, a frequency that does not rise, a value that
// is not a finite number, a wrong count of values, a reference that is not > 0, more than
// kMaxTouchstonePorts ports; the file size is bounded by base/file_io.h.
// Y and Z data are converted to S at the reference; every port has one reference z0 after reading
// (per-port references in [Reference] are converted to a common one, the first port's).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "base/status.h"

namespace isolink {

inline constexpr int kMaxTouchstonePorts = 16;

struct Touchstone {
  std::string source;  // the path (or name) it was read from
  int version = 1;     // 1 or 2
  int ports = 0;
  double z0 = 50;                   // ohm, the reference of every port
  std::vector<double> freqs;        // Hz, strictly increasing
  std::vector<Eigen::MatrixXcd> s;  // one N x N scattering matrix per frequency
  std::string parameter = "S";      // as written in the file (S, Y, Z)
  std::string format = "MA";        // as written (DB, MA, RI)
  int noise_lines_skipped = 0;
};

StatusOr<Touchstone> read_touchstone_file(const std::string& path);
// text with a name for diagnostics; the port count from the name's extension when version 1.
StatusOr<Touchstone> read_touchstone_text(const std::string& text, const std::string& name);

// Version 1.1 text: `# HZ S RI R z0`, one point per frequency (a 2-port in 11 21 12 22 order,
// others row by row, four values pairs a line), values to 12 significant digits.
std::string write_touchstone(const Touchstone& t, const std::string& comment);

}  // namespace isolink
