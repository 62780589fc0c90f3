// Synthetic scope captures with a known truth, for isolink compare's tests and the README's
// worked example (tools: tests/analysis/make_capture.cpp): a link spec (with keys replaced, the
// "truth"), simulated by the transient engine (not the LTI model compare fits with), then what a
// scope does to it: a one-pole bandwidth limit, resampling on the scope's clock, Gaussian noise
// (fixed seed), quantisation of each channel to `bits` over +/-range, a trigger offset; written in
// a real scope layout that eye::read_capture reads.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "analysis/sweep_spec.h"
#include "base/status.h"
#include "netlists/link/link_spec.h"

namespace isolink::testing {

struct ScopeModel {
  double sample_rate = 2.5e9;  // Hz
  double bandwidth = 300e6;    // Hz, one-pole -3 dB
  double noise_v = 10e-3;      // rms per channel
  int bits = 8;
  double range_v = 5.0;     // full scale +/-range
  double trigger = 3.3e-6;  // capture time of the simulation's t = 0 (s)
  uint64_t seed = 1;
  // keysight: "x-axis,1" with a units row, one differential channel (a differential probe);
  // rigol: DS1000Z "X,CH1,CH2,Start,Increment," with P and N single-ended (--p CH1 --n CH2);
  // picoscope: "Time,Channel A,Channel B" over a units row "(us),(V),(V)" and a blank line, P and
  // N (--p "Channel A" --n "Channel B"); saleae: Logic 2 analog "Time [s],Channel 0,Channel 1",
  // P and N (--p "Channel 0" --n "Channel 1").
  std::string layout = "keysight";
  bool up = false;  // the receiver probed: false the rx end (direction down), true the tx end
};

// Simulates spec_text (named name) with `truth` applied, in the scope's direction, its own
// stimulus, and writes the capture to path.
Status write_synthetic_capture(const std::string& spec_text, const std::string& name,
                               const std::vector<analysis::sweep::Assignment>& truth,
                               const ScopeModel& scope, const std::string& path);

}  // namespace isolink::testing
