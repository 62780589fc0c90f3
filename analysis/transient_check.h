// auto's transient fallback checks its own convergence (issue 28: `auto` never trades accuracy
// silently). When `auto` cannot use the LTI engine (`.ic`, `uic`, a source it cannot take) the
// transient runs at the netlist's reltol (1e-3 by default), which on long links was 10-56 mV
// from a converged reference. converge_transient repeats the run at a tenth of the reltol and
// half the largest step (the step limit, TSTEP or TMAX, binds as often as the tolerance: a
// ringing RLC at TSTEP 1 ns was 9.6 mV off at reltol 1e-3 and at 1e-4 alike), again and again,
// until two successive runs agree within TransientConvergence::kAgreementV at every
// probe and every time point of the finer run (the coarser one interpolated linearly), or the
// reltol reaches kReltolFloor; the finer run is the answer.
//
// What that promises: the kept run is within the agreement of the coarser one. When the error
// shrinks at least twofold per round (second-order steps: 4x per halving of the step), the kept
// run's own error is at most that agreement, 5 mV, inside the 10 mV. The statistics say
// which reltol was kept and how far the last two runs were. The port model (nonlinear circuits)
// checks itself the same way at 3 mV (kPortAgreementV): at its default reltol 1e-4 a TVS link
// of the random corpus was 3.9 mV from the converged full transient, at 1e-5 0.5 mV.
#pragma once

#include <functional>
#include <vector>

#include "base/status.h"
#include "base/waveform.h"
#include "solver/circuit.h"
#include "solver/probe.h"
#include "solver/transient.h"

namespace isolink::analysis {

struct TransientConvergence {
  // Two successive runs within max(kAgreementV, kAgreementRel x the probe's peak |value|) at
  // every probe: converged (the relative part keeps kV circuits and current probes in reach).
  static constexpr double kAgreementV = 5e-3;
  // The port model's runs (nonlinear circuits, whose bound is 3 mV): 3 mV or the same 0.1 %.
  static constexpr double kPortAgreementV = 3e-3;
  static constexpr double kAgreementRel = 1e-3;
  static constexpr double kReltolFloor = 1e-7;
  std::vector<double> reltols;     // every run's reltol, the first the netlist's
  std::vector<double> tmaxes;      // s, every run's largest step
  std::vector<double> deviations;  // max |run k+1 - run k| of the probe nearest its allowance
  std::vector<double> allowed;     // that probe's allowance (same unit)
  bool agreed = false;             // the last two runs agree within kAgreementV
};

// Max |a - b| over every time of `fine` in column k (the same columns in the same order),
// `coarse` interpolated linearly; 0 for empty waveforms.
double max_deviation(const Waveform& coarse, const Waveform& fine, size_t k = 0);

// One run of a time-stepping engine at the given options (the caller keeps its statistics when
// it succeeds: the last run to succeed is the one kept).
using CheckedRun = std::function<StatusOr<Waveform>(const TransientOptions&)>;
// What each tighter run changes: the reltol (a tenth) and, for the transient, the largest step
// (half); the port model's modes are exact between its steps, its largest step no accuracy knob.
enum class Tighten { ReltolAndTmax, Reltol };

// The tightening for any time-stepping engine: `first` is the run at opt.reltol. Runs `run` at
// a tenth of the reltol and half the largest step, again and again, until two successive runs
// agree within max(agreement_v, kAgreementRel x the probe's peak) at every probe, or the reltol
// reaches kReltolFloor; returns the last run, *out records every run. Never an error: a tighter
// run that fails (max_steps, the memory limit) ends the tightening with the run before it kept
// and out->agreed false.
Waveform converge_runs(TransientOptions opt, Waveform first, const CheckedRun& run,
                       double agreement_v, TransientConvergence* out,
                       Tighten how = Tighten::ReltolAndTmax);

// The first run and the tighter one converge_runs would ask next, on two threads at once (oneTBB:
// inside an arena of one they run one after the other), then converge_runs from there: the same
// runs and the same answer as run(opt) followed by converge_runs, in about the time of the
// tighter run alone. `run` must be safe to call from two threads at once (the port model's
// runs only read the circuit and the model). Errors: the first run's.
StatusOr<Waveform> converge_runs_two_at_once(const TransientOptions& opt, const CheckedRun& run,
                                             double agreement_v, TransientConvergence* out,
                                             Tighten how = Tighten::ReltolAndTmax);

// converge_runs on the transient, at kAgreementV; *stats becomes the kept run's.
StatusOr<Waveform> converge_transient(Circuit& circuit, TransientOptions opt,
                                      const std::vector<Probe>& probes, Waveform first,
                                      TransientStats* stats, TransientConvergence* out);

}  // namespace isolink::analysis
