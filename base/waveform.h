// Waveform: sampled signals on one shared, strictly increasing time axis.
//
// The solver produces it, the eye checker scores it, reports plot it, CSV files round-trip it.
//   Waveform w;
//   w.time = {...};
//   w.add_column("v(rxp,rxn)", values);
//   const std::vector<double>* v = w.column("v(rxp,rxn)");
//   Status s = write_waveform_csv(w, "wave.csv");  // header "time,v(rxp,rxn)"
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink {

struct Waveform {
  std::vector<double> time;                  // seconds, strictly increasing
  std::vector<std::string> names;            // one per column, e.g. "v(rxp,rxn)"
  std::vector<std::vector<double>> columns;  // columns[k][i] is signal k at time[i]

  size_t samples() const { return time.size(); }
  void add_column(std::string name, std::vector<double> values);
  // nullptr when no column has that name (exact match).
  const std::vector<double>* column(std::string_view name) const;
  // Linear interpolation of column k at time t (clamped to the ends).
  double value_at(size_t k, double t) const;
  // Resamples every column onto t0, t0+dt, ... <= time.back() by linear interpolation.
  Waveform resampled(double dt) const;
};

// Writes "time,<names...>" then one row per sample, %.9g, through base/file_io.h's OutputFile
// (temp file + rename, never half-written; "-" is stdout; devices and FIFOs written in place).
Status write_waveform_csv(const Waveform& w, const std::string& path);

}  // namespace isolink
