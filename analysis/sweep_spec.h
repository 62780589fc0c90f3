// Sweep files (`isolink sweep SWEEP.yaml`): a base link spec, the keys to vary and how, and the
// points that makes; each point is the base spec with some keys replaced.
//
//   StatusOr<SweepSpec> s = read_sweep_file("netlists/examples/sweep_cap_length.yaml");
//   if (!s) return s.status();               // "sweep.yaml:4:3: error: key 'cable.lenght': ..."
//   for (size_t i = 0; i < s->size(); ++i) {
//     StatusOr<PointSpec> p = point_spec(*s, i);   // the spec of point i (or why it is invalid)
//     ... run_link(p->spec, parts) ...
//   }
//
// The file:
//   base: link.yaml                   # a link spec file (relative to the sweep file), or inline
//   name: cap-vs-length               # optional: titles and the default output folder
//   sweep:                            # keys by dotted path; the first key is the plots' x axis
//     cable.length: [1, 2, 5, 10]     # a list of values (each as the spec would take it)
//     rx.isolation.cap: {from: 1n, to: 5.6n, steps: 5, scale: log}    # lin (default) or log
//     ends.isolation.cap: [1n, 2.2n]  # ends.X sets tx.X and rx.X to the same value
//     isolation:                      # named variants: each sets several keys at once
//       cap: {ends.isolation: {type: cap, cap: 2.2n}}
//       transformer: {ends.isolation: {type: transformer, part: HMU1228NL}}
//   mode: grid                        # grid: every combination | zip: the i-th values together
//   outputs: [noise, worst]           # more result columns per point (sweep_run.h): noise = the
//                                     # point's noise immunity (isolink noise on its spec); worst =
//                                     # the worst case over all legal traffic (isolink worst on
//                                     # it); stress = what breaks it in the field (isolink stress
//                                     # on it: stress.esd, stress.ground_step... and
//                                     # ends.isolation.esd, the TVS part, as keys)
// A pack base (base: pack.yaml, a pack spec file): keys are hops.<K>.<key> (hop K, 1..N, N + 1
// the ring's return hop) or hops.*.<key> (every hop), e.g. hops.9.cable.length: [1, 5, 10];
// each point is a pack run (PointSpec::pack); no Monte Carlo, no outputs.
//   monte_carlo:
//     samples: 500
//     seed: 1
//     tolerances:
//       tx.isolation.cap: 10%                     # uniform within +/-10 % of the nominal value
//       rx.isolation.cap: {normal: 10%}           # normal, sigma = 10 % / 3 (+/-10 % = 3 sigma)
//       cable.temperature: {normal: [25, 20]}     # normal, mean 25, sigma 20 (absolute)
//       tx.isolation.inductance: {uniform: [150u, 370u]}   # uniform over [lo, hi] (absolute)
// Points: grid = the cartesian product in row-major order (the last key varies fastest); zip =
// the i-th value of every key (all lists of one length). With Monte Carlo every grid point is run
// `samples` times: point index = grid index * samples + sample. Sample s draws its values from
// std::mt19937_64 seeded with seed + s, the tolerances in file order, so results do not depend on
// threads or ranks, and sample s has the same relative deviations at every grid point (common
// random numbers: differences between grid points are not noise). Relative tolerances scale the
// point's nominal value (the grid value, else the base spec's, else the spec default); a key that
// has none (a transformer's inductance taken from its part) needs an absolute distribution.
// Values are written into the spec's YAML tree as text ("2.2n", generated numbers as "%.6g"), so
// the spec reader applies each key's own unit rules. Every key and every listed value is checked
// against the base spec when the file is read: unknown keys and bad values are errors at the sweep
// file's line; combinations can still be invalid, which makes that point an error at run time.
//
// Contract:
// - Units: values as the spec keys take them (SI, the config/ suffixes); AxisValue::number in SI.
// - Ownership: a SweepSpec owns the base spec's text and every value; point specs are made from it
//   on demand and owned by the caller.
// - Errors: a Status, never thrown, at the file, line and column of the key (an invalid point's
//   spec is reported by make_point, not at reading, when only that point is invalid).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/pack_spec.h"
#include "base/status.h"
#include "config/yaml_reader.h"
#include "netlists/link/link_spec.h"

namespace isolink::analysis::sweep {

// A sweep has at most this many points (grid x Monte Carlo samples); more is refused when the
// file is read, with the count (counted with overflow checks).
inline constexpr size_t kMaxSweepPoints = 10'000'000;

// One replacement: the dotted spec path and the value as YAML text.
struct Assignment {
  std::string path;  // "cable.length" (never "ends.": expanded to tx. and rx.)
  std::string yaml;  // a scalar's text, or the YAML of a list / map (loaded when applied)
  bool scalar = true;
};

struct AxisValue {
  std::string label;               // the CSV cell: a number as %.6g in SI units, else the text
  std::optional<double> number;    // SI value for numeric keys (exact for ranges)
  std::vector<Assignment> assign;  // what the value sets
  int line = 0;                    // where it is in the sweep file (0 for generated values)
};

struct Axis {
  std::string key;        // the column name: dotted path, "ends.x" or a variant set's name
  bool variants = false;  // named variants (values are names)
  bool log = false;       // a log range (plots use a log axis)
  config::Unit unit = config::Unit::kNone;  // of the key (kNone when not a known quantity)
  std::vector<AxisValue> values;
  int line = 0;
};

enum class Dist {
  kRelUniform,  // "10%": nominal * (1 + u), u uniform in [-a, a]
  kRelNormal,   // {normal: 10%}: nominal * (1 + z * a / 3)
  kNormal,      // {normal: [mean, sigma]}
  kUniform,     // {uniform: [lo, hi]}
};

struct Tolerance {
  std::string key;                 // as written (column "mc.<key>")
  std::vector<std::string> paths;  // spec paths it sets (two for "ends.")
  config::Unit unit = config::Unit::kNone;
  bool integer = false;  // gauge, segments: rounded
  Dist dist = Dist::kRelUniform;
  double a = 0, b = 0;  // fraction (relative), or mean / sigma, or lo / hi
  int line = 0;
};

struct MonteCarlo {
  int samples = 0;  // 0: no Monte Carlo
  uint64_t seed = 1;
  std::vector<Tolerance> tolerances;
};

enum class Mode { kGrid, kZip };

struct SweepSpec {
  std::string path;       // the sweep file
  std::string name;       // name: key, else the file's stem
  std::string base_path;  // the base spec's file (the sweep file for an inline base)
  std::string base_text;  // its text
  bool base_inline = false;
  // The base is a pack spec (analysis/pack_spec.h): each point is a pack run, keys are
  // hops.<K>.<key> or hops.*.<key>, no Monte Carlo.
  bool pack = false;
  int pack_hops = 0;  // its hops, the ring's return hop included (index pack_hops)
  bool pack_ring = false;
  Mode mode = Mode::kGrid;
  std::vector<Axis> axes;
  MonteCarlo mc;
  // `outputs: [noise]`: every point also runs the noise analysis (analysis/noise.h) on its spec,
  // and results.csv gets the noise columns (sweep_run.h).
  bool noise_outputs = false;
  // `outputs: [worst]`: every point also runs the worst case over all legal traffic
  // (analysis/worst.h, default WorstOptions) on its spec, and results.csv gets the worst.* columns.
  bool worst_outputs = false;
  // `outputs: [stress]`: every point also runs isolink stress (analysis/stress.h) on its spec
  // (the spec's stress: block, its `only` included), and results.csv gets the stress.* columns.
  bool stress_outputs = false;

  size_t grid_size() const;  // points before Monte Carlo (1 without axes)
  size_t samples() const { return mc.samples > 0 ? static_cast<size_t>(mc.samples) : 1; }
  size_t size() const { return grid_size() * samples(); }
  // The value index per axis of grid point g.
  std::vector<size_t> grid_indices(size_t g) const;
  // The CSV columns that describe a point: the axes' keys, then "sample" and "mc.<key>" per
  // tolerance when there is Monte Carlo.
  std::vector<std::string> point_columns() const;
};

StatusOr<SweepSpec> read_sweep_file(const std::string& path);
// The text of a sweep file named name (a relative base path is taken from name's folder).
StatusOr<SweepSpec> read_sweep_text(const std::string& text, const std::string& name);

// One point: where it is in the sweep and the spec it runs.
struct PointSpec {
  size_t index = 0;
  size_t grid = 0;                 // grid point
  int sample = -1;                 // Monte Carlo sample, -1 without
  std::vector<size_t> axis;        // value index per axis
  std::vector<std::string> cells;  // point_columns() values
  std::vector<double> mc_values;   // per tolerance, the value drawn (SI)
  link::LinkSpec spec;             // a link sweep's point
  std::optional<PackSpec> pack;    // a pack sweep's point (spec unused)
};

// The point's description (cells) even when its spec is invalid; spec is read only when ok.
struct PointOutcome {
  PointSpec point;
  Status status;  // why the spec could not be made (point error)
};
PointOutcome make_point(const SweepSpec& s, size_t index);

// The Monte Carlo values of sample `sample` for the given nominal values (NaN where none):
// exposed for tests.
std::vector<double> draw_sample(const MonteCarlo& mc, size_t sample,
                                const std::vector<double>& nominal);

// The range generator: n values from..to, linear or geometric (exposed for tests).
std::vector<double> range_values(double from, double to, int steps, bool log);

// The unit of a spec key by its last component (cap -> F, length -> m); kNone when unknown.
config::Unit key_unit(const std::string& path);
// The SI number of a key's value text ("2.2n" for a cap, "12" for a length); nullopt when the
// text is not a number in that key's unit.
std::optional<double> key_number(const std::string& path, const std::string& text);
// The spec's numeric value at a dotted path (defaults included); nullopt when the key is not
// numeric or is not set (e.g. an inductance taken from the part).
std::optional<double> spec_number(const link::LinkSpec& spec, const std::string& path);
// The link spec of a file's text (`name` for diagnostics) with `assign` set in its YAML tree
// first, each value as the spec reader takes it: the key-path setter of every sweep point, for a
// caller that varies keys itself (isolink compare's fit).
StatusOr<link::LinkSpec> spec_with(const std::string& text, const std::string& name,
                                   const std::vector<Assignment>& assign);

}  // namespace isolink::analysis::sweep
