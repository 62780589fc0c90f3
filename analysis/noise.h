// Noise immunity of a link spec: common-mode noise (BCI current into the cable, a ground shift
// between the boards) or a differential source, swept over frequency with the AC analysis, turned
// into differential noise at the receiver pins by the P/N imbalance of the BOM, and compared with
// what the receiver's rules leave over on the link's own waveform (isolink noise).
//
//   StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
//   // per direction: the link's transient and its check (run_link), for the noise budget
//   NoiseDirectionInput in{link::Direction::kDown, &check, &rules, &wave};
//   StatusOr<NoiseResult> r = analyze_noise(spec, *parts, {&in, 1});
//   r->pass, r->directions[0].points[k].immunity, reports::noise_json(*r).dump(2)
//   (reports/noise_report.h)
//
// Model (analysis/README.md has the choices and their sources):
//   - The boards' grounds are kept apart (expand_link with tx_ground "gtx", rx_ground "grx"),
//     each joined to the chassis ("0") by its end's chassis_c; the cable's capacitance to the
//     chassis and the Y caps go to the chassis.
//   - bci: 1/2 A into each wire at the cable node nearest `position` (from the spec's tx end),
//     returning through the chassis; dm: +1/2 A into P and -1/2 A into N there; ground_shift:
//     1 V from the transmitting board's ground to the receiving board's.
//   - Per frequency one factorization: the forward solve gives the pins' voltages (to the
//     receiving board's ground), two transposed solves give their sensitivities to every
//     toleranced part (adjoint: dV = -z^T dA x), from which the worst corner of the tolerance box
//     follows exactly for the linearised response (a phase scan over max_theta
//     Re(e^-j theta H0) + sum |Re(e^-j theta S_i)| t_i).
//   - Immunity at f: the highest level at which the differential noise, at the worst phase and
//     at the modulation's peak, stays inside the receiver budget (NoiseBudget) and every pin
//     stays inside +/- pin_limit.
//
// Contract:
// - Units: SI (Hz, A or V of noise.level, V at the pins); conversion and immunity also in dB
//   re the test level.
// - Ownership: a NoiseResult owns everything it holds; the NoiseDirectionInput pointers (check,
//   rules, wave) are read during the call only and must live until it returns.
// - Errors: a Status, never thrown: a spec that does not expand or whose noise keys do not hold,
//   a bci or dm injection on a cable of one segment, a direction without its check or traffic,
//   a circuit that does not build or solve. A link that fails the test level is pass false.
#pragma once

#include <complex>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "analysis/link_run.h"
#include "base/status.h"
#include "base/waveform.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

// How much differential noise (sine amplitude, V) the receiver takes on this link's waveform
// before a rule breaks, and which rule that is.
struct NoiseBudget {
  double dm_amplitude = 0;  // V: the smallest of the amounts below
  std::string limited_by;   // "vstart", "vend", "width", "edge" or "idle"
  double amplitude = 0;     // V: VSTART / VEND margins (the VEND-dependent VSTART rule)
  double width = 0;         // V: width margin x slope / 2 (both crossings shift)
  double edge = 0;          // V: edge margin x slope / 2
  double idle = 0;          // V: the threshold (noise alone must not cross it)
  double slope = 0;         // V/s at the threshold crossings (2 vth / slowest edge)
  double pin_signal = 0;    // V: the largest |pin| of the link's own waveform
};

// From a check of the link's waveform (every pulse judged) and its rules.
NoiseBudget noise_budget(const eye::CheckResult& check, const eye::Rules& rules, double pin_signal);

// The link's transient per direction (from run_link): check, rules and the waveform with columns
// v(rxp,rxn), v(rxp), v(rxn).
struct NoiseDirectionInput {
  link::Direction direction = link::Direction::kDown;
  const eye::CheckResult* check = nullptr;
  const eye::Rules* rules = nullptr;
  const Waveform* wave = nullptr;
  std::vector<uint8_t> expected;  // the bytes sent (decoding check in the time domain)
};

struct NoisePoint {
  double freq_hz = 0;
  // Per unit of injection (per A or per V), at the receiver pins, to the receiving ground.
  std::complex<double> dm;         // nominal V(rxp) - V(rxn)
  std::complex<double> cm;         // nominal (V(rxp) + V(rxn)) / 2
  double dm_worst = 0;             // |dm| at the worst tolerance corner
  double cm_worst = 0;             // |cm| at its worst corner
  double pin_worst = 0;            // max(|V(rxp)|, |V(rxn)|) at its worst corner
  double cm_to_dm_db = 0;          // 20 log10(dm_worst / |cm|), floored at -400 dB
  double cm_to_dm_nominal_db = 0;  // same with the nominal dm
  // At the spec's level and the modulation's peak: volts at the pins.
  double dm_v = 0;         // differential, worst
  double pin_cm_v = 0;     // common mode, worst
  double immunity = 0;     // highest level (spec's unit) meeting every rule
  std::string limited_by;  // "dm" (receiver rules) or "pins" (+/- pin_limit)
};

struct TimeDomainCheck {
  bool done = false;
  std::string skipped;  // why not, when !done
  double freq_hz = 0;
  double dm_amplitude = 0;            // V, the noise superposed (worst corner, peak)
  int phases = 0;                     // phases tried
  int phases_pass = 0;                // ... of which the checker passed
  int phases_decoded = 0;             // ... of which every byte decoded as sent
  bool predicted_pass = false;        // level <= immunity at that frequency
  std::vector<std::string> failures;  // first reason per failing phase
};

// Monte Carlo over the tolerances: `samples` boards, each part uniform within its tolerance
// (independently), on the same linearised response as the worst corner. A board's immunity is its
// minimum over the band; `immunity_min` is the level that 99 % of the boards reach (the
// (samples - ceil(0.99 samples) + 1)-th lowest), at that board's weakest frequency.
struct StatisticalImmunity {
  int samples = 0;
  double percentile = 1;  // %: immunity_min is this percentile of the boards' minima
  uint64_t seed = 0;
  double immunity_min = 0;
  double immunity_min_freq = 0;
  double median = 0;  // the median board's minimum, for scale
  bool pass = false;  // level <= immunity_min
};

// A toleranced part's share of the worst-corner differential voltage beyond the nominal:
// |Re(e^-j theta S_i)| / sum_j |Re(e^-j theta S_j)| at the worst corner's angle theta (exact for
// the linearised corner, whose |V| is Re(e^-j theta V0) + that sum). Shares add up to 1.
struct Contributor {
  std::string element;  // the group's name ("crxisop", "cable chassis C, P")
  std::string kind;     // its noise.tolerance key
  double share = 0;
};

struct NoiseDirection {
  link::Direction direction = link::Direction::kDown;
  std::string description;  // "down: bq79600 -> bq7961x"
  NoiseBudget budget;
  std::vector<NoisePoint> points;
  double immunity_min = 0;       // worst corner, over the band
  double immunity_min_freq = 0;  // its frequency
  bool pass_corner = false;      // level <= immunity_min
  StatisticalImmunity statistical;
  bool pass = false;  // the verdict: pass_corner, or statistical.pass (noise.verdict_on)
  // At immunity_min_freq, sorted by share, largest first.
  std::vector<Contributor> contributors;
  TimeDomainCheck time_domain;
  int unknowns = 0;
  std::vector<std::string> tolerances;  // "name +/-10 %" per toleranced group
};

struct NoiseResult {
  link::NoiseSpec spec;
  double peak_factor = 0;  // peak of the injected waveform / level
  std::vector<NoiseDirection> directions;
  bool pass = false;
  double seconds = 0;
  int factorizations = 0;
};

struct NoiseOptions {
  link::ExpandOptions expand;  // tx_ground / rx_ground are set by the analysis
};

// A part (or a set of them: the cable's conductor) the worst case moves by +/- tol: the cards'
// first value scaled by (1 +/- tol).
struct ToleranceGroup {
  std::string name;           // the element, or "cable chassis C, P"
  std::string kind;           // its key in noise.tolerance
  std::vector<size_t> cards;  // indices into the card list
  double tol = 0;
};
// The toleranced parts of a link's cards (names as expand_link gives them): every P and N part on
// its own, the cable's chassis capacitance per conductor; groups with tol 0 are left out.
std::vector<ToleranceGroup> tolerance_groups(const std::vector<Card>& cards,
                                             const link::NoiseTolerances& t);

// The pins' response of any circuit to its sources at one frequency, nominal and worst corner.
struct ConversionPoint {
  double freq_hz = 0;
  std::complex<double> vp, vn;  // V(p) - V(ref), V(n) - V(ref), nominal, per unit source
  double dm_worst = 0;          // max |vp - vn| over the tolerance box (linearised)
  double dm_theta = 0;          // the angle of dm's worst corner (WorstCorner::theta)
  double cm_worst = 0;          // max |(vp + vn) / 2|
  double pin_worst = 0;         // max of max |vp|, max |vn|
  // d vp, d vn per group moved by its full +tolerance (adjoint), in the groups' order.
  std::vector<std::complex<double>> sp, sn;
};

// max |h0 + sum s_i d_i| over d_i in [-1, 1] (a linear complex function's worst corner): the
// maximum over theta of Re(e^-j theta h0) + sum |Re(e^-j theta s_i)|, and that theta.
struct WorstCorner {
  double value = 0;
  double theta = 0;
};
WorstCorner worst_corner(std::complex<double> h0, const std::vector<std::complex<double>>& s);

// The shares of the groups in the worst corner at angle theta (Contributor), sorted descending;
// empty when no group moves the response.
std::vector<Contributor> contributors_at(const std::vector<ToleranceGroup>& groups,
                                         const std::vector<std::complex<double>>& s_dm,
                                         double theta);
struct ConversionRequest {
  std::vector<std::pair<std::string, double>> sources;  // driven together, with amplitudes
  std::string p = "rxp", n = "rxn", ref = "0";          // the pins and their reference node
  std::vector<ToleranceGroup> groups;
  std::vector<double> frequencies;
};
// One factorization per frequency: a forward solve and two transposed solves (the pins'
// sensitivities to every group).
StatusOr<std::vector<ConversionPoint>> conversion_sweep(const std::vector<Card>& cards,
                                                        const ConversionRequest& req,
                                                        int* factorizations = nullptr,
                                                        int* unknowns = nullptr);

// The Monte Carlo of StatisticalImmunity on a conversion sweep (its sp / sn per group): ns.samples
// boards, each group uniform in [-1, 1] of its tolerance, drawn from `seed` (splitmix64, serial:
// the same on every machine and thread count); a board's immunity at f is min(budget /
// (|vp - vn| peak), pin_room / (max(|vp|, |vn|) peak)), its figure the minimum over the sweep.
StatisticalImmunity monte_carlo_immunity(const std::vector<ConversionPoint>& conv, size_t groups,
                                         const link::NoiseSpec& ns, uint64_t seed, double budget,
                                         double pin_room, double peak);

// ISO 11452-4 CW: sqrt(2) (RMS level); AM 80 %: 1.8 sqrt(2).
double noise_peak_factor(const link::NoiseSpec& n);
// The analysis frequencies: noise.band (f_start..f_stop), points_per_decade log-spaced, both ends
// included.
std::vector<double> noise_frequencies(const link::NoiseSpec& n);

// The circuit of one direction with its grounds apart and the injection source(s) (DC 0): what
// analyze_noise solves and what `noise_spice` writes. sources: names with their AC amplitude.
struct NoiseCircuit {
  link::ExpandedLink link;
  std::vector<std::pair<std::string, double>> sources;
  std::string tx_ground = "gtx", rx_ground = "grx";
};
// A measured cable (cable.touchstone) has no node inside it: bci and dm inject at its ends only,
// the clamp between the module's connector and the cable's port (noise.position 0: the spec's tx
// end, 1: its rx end), and ground_shift as on any cable.
StatusOr<NoiseCircuit> build_noise_circuit(const link::LinkSpec& spec,
                                           const link::PartLibrary& parts, link::Direction d,
                                           const NoiseOptions& opt = {});
// Whether the spec's injection can be placed on its cable: an error naming the position and what
// to set instead for bci / dm between the ends of a measured cable (checked before any run).
Status measured_cable_injection(const link::LinkSpec& spec);
// ngspice text of the noise circuit with the sources' AC amplitudes, `.options rshunt=1e12`
// and `.ac dec N f_start f_stop`, for comparison runs.
std::string noise_spice(const NoiseCircuit& c, const link::NoiseSpec& n);

// Conversion and immunity per direction given in `inputs`.
StatusOr<NoiseResult> analyze_noise(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                    std::span<const NoiseDirectionInput> inputs,
                                    const NoiseOptions& opt = {});

// analyze_noise on a link already simulated and scored per direction (run_link on the same
// spec): each direction's data check (else its tone check), rules and waveform.
StatusOr<NoiseResult> analyze_noise_of_run(const link::LinkSpec& spec,
                                           const link::PartLibrary& parts, const LinkRun& run);

// The link simulated and scored per direction (run_link), then analyze_noise on it: the work of
// `isolink noise`.
struct NoiseRun {
  LinkRun run;
  NoiseResult noise;
};
StatusOr<NoiseRun> run_noise(const link::LinkSpec& spec, const link::PartLibrary& parts);

// The immunity the verdict uses (noise.verdict_on): the worst corner's or the statistical one.
struct VerdictImmunity {
  double value = 0;
  double freq_hz = 0;
};
VerdictImmunity verdict_immunity(const NoiseDirection& d, const link::NoiseSpec& n);
// Worst immunity over the directions in dB relative to the level (20 log10(immunity / level)),
// for sweeps: > 0 passes. The immunity the verdict uses (noise.verdict_on).
double noise_immunity_min_db(const NoiseResult& r);

}  // namespace isolink::analysis
