// Eye diagram accumulation: a 2-D histogram (time x voltage) of a differential waveform folded on
// the pulse period T and anchored on each frame's preamble edge.
//
// Usage:
//   StatusOr<CheckResult> r = check_samples(t, v, rules);
//   EyeHistogram eye(EyeGrid::for_rules(rules, /*nx=*/1200, /*ny=*/640, /*v_lo=*/-3, /*v_hi=*/3));
//   size_t folds = eye.accumulate(t, v, *r);     // one window per T of every frame
//   uint32_t c = eye.count(ix, iy);              // iy = 0 is the lowest voltage row
//   int row = eye.row_of(1.2);                   // where +1.2 V lands
// The fold rule: for frame f the anchor is f.start (its preamble's +Vth crossing `a`); windows
// start at origins anchor + k*T for k = 0, 1, ... while the origin is before the frame's last pulse
// end b, and each window shows [origin + t_lo, origin + t_hi] (default -0.25T .. 2.25T), so single
// and double pulses both appear. No noise is added: a clean simulation gives thin traces.
// Interpolation: consecutive samples are joined by straight segments, and each window's trace is
// cut into steps of unit Chebyshev length in pixel units (max(|dx|, |dy|) = 1), one hit at each
// step's midpoint, the step phase carried across samples: a trace of length L gives round(L) hits.
// Counts are thus independent of the solver's (adaptive) sample spacing, and the trace has no
// holes: consecutive hits are at most one cell apart in x and in y (enforced against rounding), so
// every column and row between a trace's ends is hit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "eye/check.h"
#include "eye/rules.h"

namespace isolink::eye {

// The histogram's extent and resolution.
struct EyeGrid {
  double t_lo = -62.5e-9;  // window start relative to the fold origin (s)
  double t_hi = 562.5e-9;  // window end relative to the fold origin (s)
  double v_lo = -3.0;      // lowest voltage (V), bottom edge of row 0
  double v_hi = 3.0;       // highest voltage (V), top edge of row ny - 1
  double period = 250e-9;  // fold period T (s)
  int nx = 1000;           // columns
  int ny = 600;            // rows

  // -0.25T .. 2.25T with T = r.pulse_time (250 ns data, 1 us tone).
  static EyeGrid for_rules(const Rules& r, int nx, int ny, double v_lo, double v_hi);
  double dt_per_px() const { return (t_hi - t_lo) / nx; }  // seconds per column
  double dv_per_px() const { return (v_hi - v_lo) / ny; }  // volts per row
};

// Owns its counts; the samples passed in are read during the call and not kept. nx and ny below 1
// are taken as 1; nothing here returns an error (samples outside the voltage range count as
// outside()). Not thread-safe: one histogram per thread, or add under a lock.
class EyeHistogram {
 public:
  explicit EyeHistogram(const EyeGrid& grid);

  const EyeGrid& grid() const { return grid_; }
  // Adds the samples in [origin + t_lo, origin + t_hi] (clipped by interpolation at the window
  // edges), at times relative to origin. t strictly increasing, same size as v.
  void add_window(std::span<const double> t, std::span<const double> v, double origin);
  // Adds one window per fold origin of r (fold_origins); returns the number of windows.
  size_t accumulate(std::span<const double> t, std::span<const double> v, const CheckResult& r);
  // Adds the straight segment (t0, v0) -> (t1, v1), times relative to the fold origin, continuing
  // the step phase of the previous segment when `continues` (a new trace starts half a step in).
  void add_segment(double t0, double v0, double t1, double v1, bool continues);

  uint32_t count(int ix, int iy) const { return counts_[static_cast<size_t>(iy) * grid_.nx + ix]; }
  uint64_t total() const { return total_; }      // hits inside the grid
  uint64_t outside() const { return outside_; }  // hits above / below the voltage range
  uint32_t max_count() const;                    // the largest count (0 when empty)
  size_t windows() const { return windows_; }    // windows added
  int column_of(double t_rel) const;             // column of a relative time (may be outside)
  int row_of(double v) const;                    // row of a voltage (may be outside)
  double x_of(double t_rel) const;               // fractional column coordinate
  double y_of(double v) const;                   // fractional row coordinate (0 = v_lo)
  const std::vector<uint32_t>& counts() const { return counts_; }  // row-major, row 0 = v_lo

 private:
  void hit(double x, double y);
  EyeGrid grid_;
  std::vector<uint32_t> counts_;
  uint64_t total_ = 0, outside_ = 0;
  size_t windows_ = 0;
  double phase_ = 0.5;              // Chebyshev length (px) still to go to the next hit
  bool have_prev_ = false;          // a hit of this trace came before
  double prev_x_ = 0, prev_y_ = 0;  // its cell
};

// The fold origins of r: for each frame, f.start + k*T while < the frame's last pulse end b.
std::vector<double> fold_origins(const CheckResult& r, double period);

}  // namespace isolink::eye
