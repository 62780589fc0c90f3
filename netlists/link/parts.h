// Part library: the isolation parts of a daisy-chain link (common-mode chokes, pulse
// transformers, isolation capacitors) as data with a source for every figure, and the circuit
// builders that turn a part's model into ordinary R, L, C, K Cards.
//
//   StatusOr<PartLibrary> lib = PartLibrary::load({"my_parts"});  // built-in, then user folders
//   if (!lib) return lib.status();            // "my_parts/x.yaml:7:8: error: key 'dcr' ..."
//   const Part* p = lib->find("act45b-510-2p-tl003");             // case-insensitive
//   std::vector<Card> cards;
//   add_choke(cards, "lc1", "ap", "an", "bp", "bn", p->choke);
//
// Data: netlists/parts/*.yaml, embedded into the library at build time (the binary needs no data
// path). Schema, units and the model of each kind: netlists/link/README.md, "Part library".
// Models (all linear):
//   choke        two windings L coupled by k; per winding the DCR in series with L, and the
//                winding capacitance and a parallel loss resistor across the whole winding, so
//                the common-mode impedance peaks at self-resonance and falls past it.
//                Common mode (equal currents) sees L(1+k) per line, differential L(1-k).
//   transformer  1:1, primary (device side) and secondary (cable side) of OCL L each, coupled by
//                k = sqrt(1 - Lleak / L) (Lleak measured with the other winding shorted), DCR per
//                winding, the inter-winding capacitance split in two (a_p-b_p, a_n-b_n); with a
//                centre tap the secondary is two coupled halves and the tap goes to ground ("0")
//                through centre_tap_c.
//   capacitor    capacitance, tolerance and voltage rating (the link builder places it).
//   tvs          (nonlinear) an ESD / TVS diode per line to ground as SPICE level-1 diodes:
//                unidirectional one junction (cathode at the line), bidirectional two in
//                anti-series through an internal node. Breakdown voltage and series resistance
//                are solved so the model meets the data sheet's VBR at its test current and its
//                clamping voltage at IPP exactly; the capacitance at 0 V is the data sheet's.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/source_loc.h"
#include "base/status.h"
#include "solver/card.h"

namespace isolink::link {

enum class PartKind { Choke, Transformer, Capacitor, Tvs };
// "choke" | "transformer" | "capacitor" | "tvs"
const char* part_kind_name(PartKind kind);

// A common-mode choke: two coupled windings.
struct ChokeModel {
  double inductance = 0;  // H, self inductance of each winding
  double k = 0;           // coupling, 0 < k < 1
  double dcr = 0;         // ohm per winding, >= 0 (0: none)
  double winding_c = 0;   // F across each winding, >= 0 (0: none)
  double loss_r = 0;      // ohm across each winding, > 0, or 0 for none

  // Names the field, its value and the rule: "choke.k = 1: must satisfy 0 < k < 1".
  Status validate() const;
};

// A 1:1 pulse transformer.
struct TransformerModel {
  double inductance = 0;    // H, OCL: magnetizing inductance of each winding
  double leakage = 0;       // H, measured on one winding with the other shorted: L (1 - k^2)
  double dcr = 0;           // ohm per winding, >= 0
  double winding_c = 0;     // F, inter-winding (primary to secondary) capacitance, >= 0
  double centre_tap_c = 0;  // F, secondary centre tap to ground; 0 = no centre tap

  double k() const;         // sqrt(1 - leakage / inductance)
  Status validate() const;  // 0 < leakage < inductance, the rest >= 0
};

// A TVS / ESD protection diode on one line, as its data sheet gives it, and the SPICE level-1
// junction parameters derived from those figures (derive()).
struct TvsModel {
  bool bidirectional = true;        // two junctions in anti-series (else one, cathode at the line)
  double standoff = 0;              // V, VRWM: the largest working voltage
  double breakdown = 0;             // V, VBR at breakdown_current (the whole part, line to ground)
  double breakdown_current = 1e-3;  // A, the test current of VBR
  double clamp = 0;                 // V, VCL at clamp_current (8/20 us)
  double clamp_current = 0;         // A, the IPP of VCL
  double capacitance = 0;           // F, line to ground at 0 V
  double grading = 0.3;             // M: C(V) = C0 / (1 + V/VJ)^M per junction
  double vj = 0.7;                  // V, junction potential
  double peak_current = 0;          // A, rated IPP (8/20 us), 0: not given
  double peak_power = 0;            // W, rated PPP (8/20 us), 0: not given
  double esd_contact = 0;           // V, IEC 61000-4-2 contact discharge rating, 0: not given
  // Per junction, filled by derive(): saturation current (ngspice's default), emission 1,
  // breakdown BV at IBV = breakdown_current, series RS, zero-bias capacitance CJO.
  double is = 1e-14, bv = 0, ibv = 0, rs = 0, cjo = 0;

  // Names the field, its value and the rule: "tvs.clamp = 20: must be above the breakdown ...".
  Status validate() const;
  // Solves bv and rs so that the part's DC voltage at breakdown_current is `breakdown` and at
  // clamp_current is `clamp`; cjo from the capacitance (twice it per junction in anti-series).
  Status derive();
  // The model card's parameters ("is=1e-14 n=1 bv=... ibv=... rs=... cjo=... vj=... m=...").
  std::vector<std::pair<std::string, double>> spice_params() const;
};

struct CapacitorModel {
  double capacitance = 0;     // F
  double voltage_rating = 0;  // V (0: not given)
  double tolerance = 0;       // relative (0.1 = +/-10 %), 0: not given
};

// One figure of a part as the YAML file gives it: the nominal value used in simulation, the
// range kept for sweeps, and where it comes from.
struct Figure {
  std::string key;                  // "inductance", "rating.current", ...
  double value = 0;                 // SI units
  std::optional<double> min, max;   // range (from min/max or tolerance)
  std::optional<double> tolerance;  // relative (0.1 = +/-10 %), when given as a tolerance
  std::optional<double> frequency;  // Hz: the frequency a cm_impedance is rated at
  std::optional<double> current;    // A: the current a TVS voltage (breakdown, clamp) is given at
  std::string measured;             // leakage: "shorted" | "differential"
  bool fitted = false;              // loss_r: derived from cm_impedance ("fit")
  std::string source;               // "data sheet: ...", "assumed: ...", "fitted: ..."
  SourceLoc loc;                    // where it is written
};

struct Part {
  std::string number;  // as written in the file ("ACT45B-510-2P-TL003")
  std::string maker;
  PartKind kind = PartKind::Choke;
  std::string description;                           // optional one-liner
  std::string datasheet;                             // optional: the document the figures come from
  std::string dielectric;                            // capacitors: "X7R", ...
  SourceLoc loc;                                     // the part's map in its file
  std::vector<Figure> figures;                       // in file order
  ChokeModel choke;                                  // kind == Choke
  TransformerModel transformer;                      // kind == Transformer
  CapacitorModel capacitor;                          // kind == Capacitor
  TvsModel tvs;                                      // kind == Tvs
  std::optional<double> cm_impedance, cm_frequency;  // ohm at Hz: the data sheet's rating
  std::optional<double> rated_current;               // A
  std::optional<double> rated_voltage;               // V, working / rated
  std::optional<double> isolation_voltage;           // V, hi-pot test voltage
  std::string overrides;  // non-empty when this part replaced an earlier one: where that was

  const Figure* figure(std::string_view key) const;  // nullptr when not given
};

// Parses one part file (a map = one part, a list = several). path names it in diagnostics.
StatusOr<std::vector<Part>> read_parts_text(const std::string& text, const std::string& path);
StatusOr<std::vector<Part>> read_parts_file(const std::string& path);

class PartLibrary {
 public:
  // The built-in parts first, then every *.yaml / *.yml file of each folder in order (a plain
  // file path is taken as one file). A later part with the same number (case-insensitive)
  // replaces the earlier one; notes() says so. Errors: an unreadable folder, a bad file.
  static StatusOr<PartLibrary> load(const std::vector<std::string>& dirs);
  // Where the built-in parts come from: "netlists/parts" (source tree, embedded at build time;
  // diagnostics name the files "netlists/parts/NAME.yaml").
  static std::string builtin_dir();
  // The built-in files' names ("netlists/parts/tdk_act45b.yaml", ...), sorted.
  static std::vector<std::string> builtin_files();

  const Part* find(std::string_view number) const;  // case-insensitive; nullptr if absent
  const std::vector<Part>& parts() const { return parts_; }
  // One line per override: "user/x.yaml:1:1: note: part ACT45B-510-2P-TL003 overrides ...".
  const std::vector<std::string>& notes() const { return notes_; }

  // Adds parts (later wins, with a note).
  void add(std::vector<Part> parts);

 private:
  std::vector<Part> parts_;
  std::vector<std::string> notes_;
};

// Appends Cards for a common-mode choke between (a_p, a_n) and (b_p, b_n); dots on the a side.
// Names (prefix "lc1"): lc1.lp, lc1.ln (windings), lc1.kpn (coupling), lc1.rdp/rdn (DCR, before
// b through internal nodes lc1.mp/mn), lc1.cwp/cwn (winding C), lc1.rlp/rln (loss R).
Status add_choke(std::vector<Card>& cards, const std::string& prefix, const std::string& a_p,
                 const std::string& a_n, const std::string& b_p, const std::string& b_n,
                 const ChokeModel& m);

// Appends Cards for a TVS from `line` to `ground`: diodes "<prefix>a" (and "<prefix>b" with
// the internal node "<prefix>.mid" when bidirectional) sharing one .model named model_name.
Status add_tvs(std::vector<Card>& cards, const std::string& prefix, const std::string& line,
               const std::string& ground, const std::string& model_name, const TvsModel& m);

// Appends Cards for a 1:1 transformer, primary (a_p, a_n) (device side), secondary (b_p, b_n)
// (cable side), dots on a_p and b_p. Names (prefix "t1"): t1.lpri, t1.rpri; without centre tap
// t1.lsec, t1.rsec, t1.kps; with one t1.ls1, t1.ls2 (halves), t1.rs1, t1.rs2, t1.kp1, t1.kp2,
// t1.k12, centre node t1.ct and t1.cct to "0"; t1.cip, t1.cin (inter-winding C / 2 each).
Status add_transformer(std::vector<Card>& cards, const std::string& prefix, const std::string& a_p,
                       const std::string& a_n, const std::string& b_p, const std::string& b_n,
                       const TransformerModel& m);

}  // namespace isolink::link
