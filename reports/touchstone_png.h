// The fit plot of `isolink touchstone FILE --plot PNG`: a measured cable's differential
// transmission and reflection (magnitude in dB, transmission phase) as the file gives them and
// as the fitted rational model (after passivity enforcement: the model the link simulates)
// gives them, and the largest |S_fit - S| over the entries at each frequency.
//
//   StatusOr<std::shared_ptr<const link::TouchstoneCable>> c = link::fit_touchstone_cable(...);
//   TouchstoneCurves k = touchstone_curves(**c);             // the numbers drawn
//   Status s = write_touchstone_png(**c, "fit.png");         // temp file + rename
//
// Differential entries: for a 4-port in the link's port order (tx P, tx N, rx P, rx N, after the
// file's `ports` mapping) the mixed-mode Sdd = M S M^T with M = [1 -1 0 0; 0 0 1 -1] / sqrt(2), so
// Sdd21 is the tx pair to the rx pair and Sdd11 the tx pair's reflection; a 2-port is already
// differential (S21, S11). Reference: the file's.
//
// Contract: pure functions of the fitted cable (read only). Errors: a Status naming the file
// (the image plug-in or its fonts, a write that fails); written through a temporary name.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "base/status.h"
#include "netlists/link/touchstone_cable.h"

namespace isolink::reports {

struct TouchstoneCurves {
  std::vector<double> freqs;                                // Hz, the file's
  std::vector<std::complex<double>> sdd21_file, sdd21_fit;  // transmission
  std::vector<std::complex<double>> sdd11_file, sdd11_fit;  // reflection at the tx end
  std::vector<double> entry_error;                          // max_ij |S_fit - S|_ij
  // Of the model as simulated (after passivity enforcement, which FitResult's figures precede):
  double rms_error = 0;  // RMS of |S_fit - S| over the entries and the file's band
  double max_error = 0;  // the largest, at max_error_hz
  double max_error_hz = 0;
};
TouchstoneCurves touchstone_curves(const link::TouchstoneCable& c);

Status write_touchstone_png(const link::TouchstoneCable& c, const std::string& path);

}  // namespace isolink::reports
