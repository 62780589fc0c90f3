// Stress of a link spec: what a disturbance in the field does to the pins, the protection parts
// and the traffic (isolink stress, issue 42). Each scenario is the link's circuit with the pins'
// clamp diodes on, the spec's TVS parts, and the disturbance as a source, simulated by the exact
// nonlinear transient; its peaks are checked against the limits of the spec's `stress:` block.
//
//   StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
//   StatusOr<StressResult> r = run_stress(spec, *parts, {});
//   for (const StressScenario& s : r->scenarios) ... s.survives, s.first_broken, s.peak_pin_v ...
//   reports::stress_json(*r) (reports/stress_report.h)
//
// Scenarios (docs/stress.md has what each injects and what is not modelled):
//   cm_step  the transmitting module's ground steps stress.ground_step V in stress.ground_rise
//            (a PWL source from its board ground "gtx" to the chassis "0"; the receiving board
//            stays on the chassis) during traffic: the spec's stimulus sent twice, the step
//            starting a third of the way into the first data frame. One per end (the end that
//            transmits and steps: tx is the down direction, rx the up one).
//   esd      IEC 61000-4-2 contact discharge (esd_current, scaled by stress.esd kV) as a PWL
//            current source from the chassis into one connector line of one end, both boards on
//            the chassis, the link idle: per end, line and polarity (8 scenarios).
//   cm_wave  the inverter's square (edges at stress.wave_dvdt) or sine, 0 to stress.wave_v at
//            stress.wave_f, on the transmitting module's ground during traffic (a PULSE / SIN
//            source where cm_step has its PWL): one per direction.
//   hot_plug the module at one end, stress.hot_plug_v above the chassis, plugged onto the cable
//            (whose other end is on its module, on the chassis): its connector's two contacts
//            are switches (S, solver/elements/switch.cpp) closing stress.hot_plug_gap apart,
//            P first or N first; the link idle. Per end and order (4 scenarios).
//   wire     a fault at the spec's rx end's connector for the whole record (in the DC point
//            too), its module stress.hot_plug_v above the chassis, during the spec's traffic
//            sent once: open P / N, P-N short, P / N to the module's ground, P / N to the
//            chassis, the rx device's pin P / N leaking to its ground through stress.leak_ohms.
//            Per fault and direction (18 scenarios).
// Pins are measured against their own device's ground (the node the end's board is on), named
// as in the scenario's netlist: txp, txn (the transmitting device of that netlist), rxp, rxn.
// Scenarios with traffic (cm_step, cm_wave, wire) score the receiver's v(rxp, rxn) with the
// checker.
//
// Contract:
// - Units: SI (V, A, s, J); ESD levels in V (8e3 = 8 kV).
// - Ownership: a StressResult owns its scenarios (netlists, waveform summaries); the spec and
//   the part library are read during the call only.
// - Errors: a Status, never thrown: a spec that does not expand (the key's file:line:col), an
//   unknown kind in `only`, a simulation that fails (the scenario's id leads the message). A
//   scenario that breaks a limit is a result (survives false), not an error.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/simulate.h"
#include "base/status.h"
#include "eye/check.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"

namespace isolink::analysis {

// IEC 61000-4-2 (2008) Annex B, eq. (B.1): the contact discharge current of the standard's
// generator as the sum of two Heidler functions, at 4 kV I1 16.6 A, tau1 1.1 ns, tau2 2 ns,
// I2 9.3 A, tau3 12 ns, tau4 37 ns, n 1.8, scaled linearly by the level (volts, signed).
// Gives the standard's table 3 figures: first peak 3.73 A/kV at 1.46 ns (10-90 % rise 0.81 ns),
// 2 A/kV at 30 ns, 1 A/kV at 60 ns (tests/analysis/stress_test.cpp checks them).
double esd_current(double t, double level_v);
// esd_current starting at t0, as PWL points (t, i, t, i, ...) from 0 to t0 + span: fine steps
// (20 ps) through the rise, coarser (0.25 ns, then 2 ns) along the tail; within 0.5 % of the
// peak between points.
std::vector<double> esd_pwl(double level_v, double t0, double span);

// The scenarios' transient tolerance (analysis/stress.cpp says why one run at it).
inline constexpr double kStressReltol = 1e-4;

// One limit checked, with its value and where it comes from.
struct StressLimit {
  std::string key;     // "pin_abs_max_V", "pin_cm_limit_V", "cap_rating_V"
  double value = 0;    // in the key's unit
  std::string source;  // "docs/physics.md 2: ...", "assumed: ...", "stress.pin_abs_max (spec)"
};

struct PinPeak {
  double max = 0, min = 0;  // V, to the pin's device ground
};

// A diode's current through its ammeter (a 0 V source "v<diode>am" at its line / pin terminal).
struct DiodePeak {
  std::string diode;    // the diode card ("dtxesdpa", "drxhp")
  std::string what;     // "TVS PESD2CAN at the tx end, line P", "rx pin P clamp to CVDD"
  std::string ammeter;  // the 0 V source in the netlist
  double peak_a = 0;    // largest |i|
  double energy_j = 0;  // integral of |v i| dt (TVS: v across the part), 0 for clamps
  double rating_a = 0;  // IPP (TVS), 0 when none
  std::string rating_source;
};

// A hot-plug contact's current (its ammeter "vcontact<p|n>am", positive from the cable into the
// plugged module).
struct ContactPeak {
  std::string contact;  // the switch card ("scontactp")
  std::string ammeter;  // the 0 V source in series
  // The inrush: the largest |mean i| over any 1 ns (the contact's closing time; the
  // instantaneous peak of an ideal contact is the time step's, not the circuit's).
  double peak_1ns_a = 0;
  double charge_c = 0;  // integral of i dt over the record: the charge moved into the module
};

struct CapPeak {
  std::string cap;    // "ctxisop"
  double peak_v = 0;  // largest |v| across it
};

// The traffic's check through a scenario with traffic.
struct StressTraffic {
  int bytes_sent = 0, bytes_decoded = 0;     // data bytes; decoded in order as sent
  int bytes_during = 0, decoded_during = 0;  // those starting in [step start - 10 us, step end]
  bool pass = false;                         // the check's verdict over the whole record
  std::vector<eye::WorstMargin> worst;       // per metric, the smallest margin
  std::string first_failure;                 // the check's first reason, "" when it passes
  // Time from the end of the disturbance until the last failing pulse ends (0: none failed
  // after it); nullopt when pulses still fail at the end of the record.
  std::optional<double> recovery_s;
};

struct StressScenario {
  std::string id;    // "cm_step_tx", "esd_rx_n_neg", "hot_plug_rx_p_first", "wire_open_p_down"
  std::string kind;  // "cm_step" | "cm_wave" | "esd" | "hot_plug" | "wire"
  std::string end;   // the spec end disturbed (plugged, faulted): "tx" | "rx"
  std::string line;  // "p" | "n" (esd; hot_plug: the first contact; wire: the line faulted), ""
  std::string direction;      // traffic scenarios: "down" | "up" (which end transmits), else ""
  std::string tx_end = "tx";  // the spec end the netlist's tx side is
  std::vector<std::pair<std::string, double>> level;  // {"step_V", 60}, {"rise_s", 1e-6}
  std::string description;                            // in words
  link::ExpandedLink link;        // its circuit (netlist with the disturbance and the ammeters)
  double t_start = 0, t_end = 0;  // s: the disturbance's start and end (peak window)
  std::map<std::string, std::string> pin_ground;  // pin node -> its device ground node
  std::map<std::string, PinPeak> peak_pin_v;      // pin node -> max / min
  double peak_cm_v = 0;                           // largest |common mode| of either device
  std::string peak_cm_device;                     // "rx" / "tx" (nodes' prefix)
  std::vector<DiodePeak> diodes;
  std::vector<CapPeak> caps;
  std::vector<ContactPeak> contacts;          // hot_plug: its two contacts, first one first
  std::optional<StressTraffic> traffic;       // scenarios with traffic
  std::string receiver_p, receiver_n, rules;  // with traffic: the receiving pins and rule set
  bool survives = true;
  std::optional<bool> communicates;
  std::string first_broken;         // "" when nothing broke
  std::vector<std::string> broken;  // every limit broken, in words
  std::string engine;               // the engine that ran it, and why
  double seconds = 0;
  Waveform pins;  // v(pin, ground) per pin (columns in peak_pin_v's order), for plots
};

struct StressResult {
  std::vector<StressLimit> limits;
  std::vector<StressScenario> scenarios;
  bool survives = true, communicates = true;
  std::string verdict;  // one line
  double seconds = 0;
};

struct StressOptions {
  // Scenario kinds to run (empty: the spec's stress.only, else all).
  std::vector<std::string> only;
  // Which end transmits in the traffic scenarios (cm_step, cm_wave, wire): empty: both.
  std::vector<link::Direction> directions;
  // Scenarios run at once (oneTBB; 0: all cores).
  int jobs = 1;
  // Drop each scenario's circuit (link) and pin waveforms (pins) once it has run: a pack's
  // hundreds of scenarios are reported by their figures alone (with them, the 16-module example
  // pack's stress took 4.6 GB).
  bool results_only = false;
  // Progress for a display: the scenario's id and the fraction done (0-1).
  std::function<void(const std::string& what, double fraction)> progress;
};

// The limits the spec's stress block sets, with their sources.
std::vector<StressLimit> stress_limits(const link::LinkSpec& spec);
// Each scenario's circuit, not yet run (export-spice; run_stress simulates these).
StatusOr<std::vector<StressScenario>> build_stress_scenarios(const link::LinkSpec& spec,
                                                             const link::PartLibrary& parts,
                                                             const StressOptions& opt = {});
// Simulates one built scenario and judges it against the limits.
Status run_stress_scenario(StressScenario& s, const link::LinkSpec& spec,
                           const link::PartLibrary& parts);
// Simulates and judges built scenarios side by side (opt.jobs threads; opt.progress under a
// lock), scenario i against specs[i]; the first failure in scenario order is the error.
Status run_stress_scenarios(std::vector<StressScenario>& scenarios,
                            const std::vector<const link::LinkSpec*>& specs,
                            const link::PartLibrary& parts, const StressOptions& opt);
StatusOr<StressResult> run_stress(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                  const StressOptions& opt = {});

}  // namespace isolink::analysis
