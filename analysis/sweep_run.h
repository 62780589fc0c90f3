// Running a sweep: each point through run_link (analysis/link_run.h), scored to one row of
// results.csv; the points in parallel on all cores (oneTBB) or across MPI ranks (sweep_mpi.h).
// summary.json and the charts are written from the outcome by reports/sweep_report.h.
//
//   StatusOr<SweepSpec> s = read_sweep_file(path);
//   StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
//   SweepOptions opt{.out_dir = "out", .jobs = 0};
//   StatusOr<SweepOutcome> r = run_sweep(*s, *parts, opt);   // r->fail + r->error == 0: all pass
//   reports::write_sweep_report(*s, &*r, opt.out_dir, true);   // summary.json, the charts
//
// Errors (StatusOr, never thrown): a folder that cannot be created, a results.csv that cannot be
// read (--resume) or written; a point that fails is a row with verdict "error", not an error.
//
// results.csv: one row per point, appended (and flushed) as points finish, so rows are in
// completion order; `point` is the point's index (sort by it). Columns:
//   point, <one per swept key, named by its dotted path>, [sample, mc.<key>...], verdict
//   (pass | fail | error), worst_metric, worst_margin_rel, margin_vstart_V, margin_vend_V,
//   margin_width_ns, margin_edge_ns, decoded_ok, fail_reason, seconds, error, path
// path says how the point's waveforms were obtained: "edges" (the fast path, run_link_from_edges:
// each direction's traffic superposed from its edge response on the response's 1 ns grid; the
// same verdicts and margins as a simulation within 1 mV and 25 ps, analysis/README.md) or
// "simulated: <why>" (--engine transient, waveform files asked at a sim.tstep off that grid, a
// drive level change off it, an edge response that cannot be computed, a pack point).
// Margins are each metric's worst (smallest) margin over the directions and over the data and
// tone checks, in the metric's unit: distance to the limit, positive = inside (eye/metrics.h).
// worst_margin_rel is the smallest of margin / |limit| over the four metrics (the fraction by which
// the value could move before reaching its limit) and worst_metric names it; on a failing point on
// which no pulse was judged at all (nothing crossed the threshold) it is -1 and worst_metric is
// "none". fail_reason lists what failed, in short: the metrics of failing pulses (dip, width, edge,
// vstart, vend), "decode: <fault>" for frames that do not decode, "bytes differ", "no signal" (no
// pulse at all); a point can fail with every margin positive (a dip, a frame that does not decode).
// With `outputs: [noise]` in the sweep file, each point also runs the noise analysis on its spec
// (analyze_noise_of_run on the point's own run: what `isolink noise` gives for that spec) and
// these columns follow fail_reason:
//   noise.verdict                 pass | fail: the spec's noise test level against the immunity
//   noise.immunity_min_db         the lowest immunity over the directions and the band, in dB re
//                                 the test level (noise.level): 20 log10(immunity / level), > 0
//                                 passes, -400 when the link has no noise budget at all
//   noise.<dir>.immunity_min      per direction (down, up): the lowest immunity over the band, in
//                                 the unit of noise.level (A for bci and dm, V for ground_shift)
//   noise.<dir>.immunity_min_db   the same in dB re the test level
//   noise.<dir>.freq_hz           the frequency of that minimum
// Empty where a direction was not run or the point is an error. `verdict` stays the link's own.
// With `outputs: [worst]`, each point also runs the worst case over all legal traffic on its spec
// (worst_case with the default WorstOptions: what `isolink worst` and `isolink run` give for that
// spec) and these columns follow (after the noise columns when both are asked for):
//   worst.verdict                 pass | fail: WorstResult::pass (every direction's worst traffic
//                                 passes its receiver's rules)
//   worst.worst_metric            the metric with the smallest margin / |limit| below (vstart,
//                                 vend, width_min, width_max, edge)
//   worst.margin_rel              that smallest margin / |limit| over the directions and metrics
//                                 (as worst_margin_rel is for the spec's traffic); both empty
//                                 when the search found no pulse at all (worst.verdict fail)
//   worst.<dir>.<metric>_margin_<unit>  per direction (down, up) and metric, the worst traffic's
//                                 margin: vstart_margin_V, vend_margin_V, width_min_margin_ns,
//                                 width_max_margin_ns, edge_margin_ns (the units of the margin_*
//                                 columns)
// Empty where a direction was not run or the point is an error. `verdict` stays the spec
// traffic's, so the two can be compared point by point. A worst case that cannot be computed
// makes the point an error ("worst: ..."), as a noise analysis that fails does.
// With `outputs: [stress]`, each point also runs isolink stress on its spec (run_stress with the
// default StressOptions: the spec's stress: levels and `only`, both directions, one scenario at
// a time: the points already fill the cores) and these columns follow (after the worst ones):
//   stress.verdict                pass | fail: pass when no scenario breaks a limit or a rule
//   stress.scenarios              the scenarios run
//   stress.breaking               those that break something (StressScenario::broken)
//   stress.max_pin_V              the largest |peak| of a COM pin against its device's ground
//   stress.max_cm_V               the largest |common mode| of either device's pins
//   stress.max_diode_A            the largest peak current of a TVS part or pin clamp
//   stress.first_broken           "<scenario id>: <what>", the first scenario that breaks
//                                 something and its first limit or rule, in words
// Stress levels and parts are sweep keys as any spec key (stress.esd, stress.ground_step,
// ends.esd: a TVS part number); a stress run that fails makes the point an error ("stress:").
// A point whose spec is invalid or whose simulation fails has verdict "error", the message's
// first line in `error` (CSV-quoted) and empty margins; the sweep goes on. Numbers are written with
// 6 significant digits and every total (summary.json, plots) is computed from the rows as written,
// so a resumed or MPI run gives the same files as one threaded run.
//
// A pack sweep (the base is a pack spec) runs each point through run_pack (spec traffic; the
// worst case over all traffic is `isolink pack`'s, not the sweep's). The columns above describe
// the pack: verdict is the pack's (every hop passes), worst_metric .. margin_edge_ns are the
// weakest hop's (PackResult::weakest), decoded_ok covers every hop, fail_reason names each
// failing hop ("hop 3: width; hop 9: vstart"); after error and path come weakest_hop (its index),
// failing_hops (their indices, space-separated) and hop_<K>_margin_rel per hop K (its smallest
// margin / |limit| over its directions, the ring's return hop included). --keep-waves writes
// point_NNNNN_hop_KK.csv per hop.
#pragma once

#include <array>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/link_run.h"
#include "analysis/noise.h"
#include "analysis/pack.h"
#include "analysis/stress.h"
#include "analysis/sweep_spec.h"
#include "analysis/worst.h"
#include "base/csv.h"
#include "base/progress.h"
#include "base/status.h"
#include "netlists/link/parts.h"

namespace isolink::analysis::sweep {

inline constexpr std::array<const char*, 4> kMetrics = {"vstart", "vend", "width", "edge"};
// The worst case's metrics (WorstMetric::name), in the order of the worst.* columns.
inline constexpr std::array<const char*, 5> kWorstMetrics = {"vstart", "vend", "width_min",
                                                             "width_max", "edge"};

// A point's noise columns (PointResult::noise). At namespace scope, not nested: clang cannot
// default-construct a nested struct with member initializers before its enclosing class is
// complete.
struct PointNoise {
  std::string verdict;                                                // pass | fail | ""
  double immunity_min_db = std::numeric_limits<double>::quiet_NaN();  // over the directions
  std::array<double, 2> immunity_min = {std::numeric_limits<double>::quiet_NaN(),
                                        std::numeric_limits<double>::quiet_NaN()};
  std::array<double, 2> immunity_min_db_dir = {std::numeric_limits<double>::quiet_NaN(),
                                               std::numeric_limits<double>::quiet_NaN()};
  std::array<double, 2> freq_hz = {std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN()};
};

// A point's worst-case columns (PointResult::worst); at namespace scope like PointNoise.
struct PointWorst {
  std::string verdict;       // pass | fail | ""
  std::string worst_metric;  // one of kWorstMetrics, or ""
  double margin_rel = std::numeric_limits<double>::quiet_NaN();
  // [direction (down, up)][kWorstMetrics entry]: the margin in SI units (V or s); NaN when the
  // direction was not run or the metric not found.
  std::array<std::array<double, 5>, 2> margin;
  PointWorst() {
    for (auto& d : margin) d.fill(std::numeric_limits<double>::quiet_NaN());
  }
};

// A point's stress columns (PointResult::stress); at namespace scope like PointNoise.
struct PointStress {
  std::string verdict;  // pass | fail | "": pass when no scenario breaks a limit or rule
  int scenarios = 0, breaking = 0;  // run, and those that break something
  // The largest |peak| over the scenarios: a COM pin against its own ground, a device's common
  // mode, a TVS or clamp diode's current.
  double max_pin_v = std::numeric_limits<double>::quiet_NaN();
  double max_cm_v = std::numeric_limits<double>::quiet_NaN();
  double max_diode_a = std::numeric_limits<double>::quiet_NaN();
  std::string first_broken;  // "<scenario id>: <the first limit or rule it breaks>", or ""
};

struct PointResult {
  size_t index = 0;
  std::vector<std::string> cells;  // SweepSpec::point_columns()
  std::string verdict;             // pass | fail | error
  std::string worst_metric;        // one of kMetrics, "none", or "" (error)
  double worst_rel = std::numeric_limits<double>::quiet_NaN();
  // Per kMetrics entry, the worst margin in SI units (V, V, s, s); NaN when not judged.
  std::array<double, 4> margin = {
      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  std::optional<bool> decoded_ok;  // every data frame decoded to the bytes sent; none: no data
  std::string reason;              // fail_reason: why a failing point fails ("dip; decode: sync")
  double seconds = 0;              // wall time of the point
  std::string error;
  // How the waveform was obtained: "edges" (the fast path: superposed from each direction's edge
  // response, run_link_from_edges) or "simulated: why" (the transient or the LTI engine's own
  // run: --engine transient, waveform files off the 1 ns grid, traffic off it, a pack...); empty
  // on error rows.
  std::string path;
  // The noise columns (`outputs: [noise]`); present (maybe empty) exactly when the sweep has them.
  using Noise = PointNoise;
  std::optional<Noise> noise;  // indexed by link::Direction (down, up)
  // The worst-case columns (`outputs: [worst]`); present (maybe empty) exactly when the sweep has
  // them.
  using Worst = PointWorst;
  std::optional<Worst> worst;
  // The stress columns (`outputs: [stress]`); present (maybe empty) exactly when the sweep has
  // them.
  using Stress = PointStress;
  std::optional<Stress> stress;
  // A pack sweep's extra cells (pack_columns()): weakest_hop, failing_hops, hop_<K>_margin_rel.
  std::vector<std::string> extra;
};

// The columns a pack sweep adds after `path` (none for a link sweep).
std::vector<std::string> pack_columns(const SweepSpec& s);
// Scores a pack run: the pack's verdict; worst_metric, worst_margin_rel and the margins of the
// weakest hop; decoded_ok over every hop; fail_reason per failing hop ("hop 3: width"); extra.
PointResult score_pack(const PackResult& r);

// The results.csv header for a sweep.
std::vector<std::string> results_header(const SweepSpec& s);
// What a results.csv row of a sweep holds: the point's cells, the optional families, the pack's
// columns after `path`.
struct RowShape {
  size_t cells = 0;        // point_columns().size()
  bool noise = false;      // the noise columns
  bool worst = false;      // the worst.* columns
  bool stress = false;     // the stress.* columns
  size_t extra = 0;        // pack_columns().size()
  size_t columns() const;  // results_header().size()
};
RowShape row_shape(const SweepSpec& s);
// One CSV line (with '\n').
std::string results_row(const PointResult& r);
// Parses a line written by results_row for a sweep of that shape (fields after `path` go to
// extra).
StatusOr<PointResult> parse_results_row(std::string_view line, const RowShape& shape);
// The result as the CSV stores it (numbers rounded to what is written).
PointResult round_trip(const PointResult& r, const RowShape& shape);
// One CSV line back into its fields (base/csv.h; results.csv has no newlines inside fields).
using isolink::split_csv_line;

// Scores a finished run: verdict, margins, decoded_ok.
PointResult score_run(const LinkRun& run);
// The noise columns of a noise result (analysis/noise.h).
PointResult::Noise noise_cells(const NoiseResult& r);
// The worst-case columns of a worst-case result (analysis/worst.h).
PointResult::Worst worst_cells(const WorstResult& r);
// The stress columns of a stress result (analysis/stress.h).
PointResult::Stress stress_cells(const StressResult& r);

struct PointOptions {
  RunOptions run;
  std::string waves_dir;  // non-empty: write each point's waveforms there (--keep-waves)
  bool simulate = false;  // every point through run_link, off the fast path (--simulate)
  // Hz, per direction: the expansion points that start every point's reduced model
  // (WorstOptions::reduced_start_points_by_direction). run_sweep fills them in from point 0's
  // edge responses before the first point, so they are the same for any thread count, across
  // machines and on resume; each point's model still passes its full check.
  std::map<link::Direction, std::vector<double>> start_points;
};
// PointOptions::start_points for a sweep: the expansion points of point 0's edge responses per
// direction (empty where point 0 is a pack, an error, or off the fast path).
std::map<link::Direction, std::vector<double>> sweep_start_points(const SweepSpec& s,
                                                                  const link::PartLibrary& parts,
                                                                  const PointOptions& opt);
// Makes, runs and scores point `index`; never fails (errors become verdict "error").
PointResult run_point(const SweepSpec& s, const link::PartLibrary& parts, size_t index,
                      const PointOptions& opt);

struct SweepOptions {
  std::string out_dir;      // results.csv (created; summary.json and the charts: reports/)
  int jobs = 0;             // threads (0: all cores)
  bool resume = false;      // skip points already in results.csv
  bool keep_waves = false;  // out_dir/waves/point_NNNNN.csv per point
  bool quiet = false;       // no progress
  PointOptions point;       // waves_dir is filled in from keep_waves
  // Called once, when the thread pool is up and before the first point: the moment to start
  // background work (cli/ loads the charts' image plug-in there). Not before: the pool's first
  // start loads libraries, and a dlopen on another thread would hold it up for as long as its
  // own loading takes (0.3-0.6 s of OpenImageIO's plug-ins, with both cores waiting).
  std::function<void()> on_pool_ready;
};

struct SweepOutcome {
  size_t points = 0, pass = 0, fail = 0, error = 0;
  size_t skipped = 0;              // already in results.csv (--resume)
  double seconds = 0;              // wall time of this run
  std::vector<std::string> files;  // written, relative to out_dir (reports/ adds its own)
  // Every point's result by point index (the rows kept by --resume included): what results.csv
  // holds, for front ends that want the rows without reading the file back (python/).
  std::vector<PointResult> results;
};

// results.csv while a sweep runs: the rows kept from an earlier run (--resume), then each new
// row appended and flushed under a lock; progress on stderr.
class ResultLog {
 public:
  static StatusOr<std::unique_ptr<ResultLog>> open(const SweepSpec& s, const SweepOptions& opt);
  ~ResultLog();
  ResultLog(const ResultLog&) = delete;
  ResultLog& operator=(const ResultLog&) = delete;

  // Point indices still to run, ascending.
  std::vector<size_t> todo() const;
  size_t skipped() const { return skipped_; }
  // Records a result (thread-safe): appends its row (checked), prints progress. After a failed
  // write nothing more is recorded and status() says why.
  void add(const PointResult& r);
  Status status() const {
    std::lock_guard<std::mutex> lock(mu_);
    return write_error_;
  }
  // Every result so far, by point index.
  std::vector<PointResult> results() const;
  const std::string& path() const { return path_; }

 private:
  ResultLog() = default;
  void progress(const PointResult& r);
  const SweepSpec* spec_ = nullptr;
  std::string path_;
  std::FILE* file_ = nullptr;
  RowShape shape_;
  size_t total_ = 0, skipped_ = 0, done_now_ = 0, todo_count_ = 0;
  size_t pass_ = 0, fail_ = 0, error_ = 0;
  std::unique_ptr<ProgressLine> line_;  // stderr: redrawn on a terminal, every 5 s on a pipe
  std::vector<PointResult> results_;
  std::vector<bool> have_;
  Status write_error_;
  mutable std::mutex mu_;
};

// The outcome of the results (sorted by point): the counts, results.csv among out->files, the
// results kept in out->results.
void finish_sweep(const SweepSpec& s, std::vector<PointResult> results, SweepOutcome* out);

// The whole sweep on this machine's cores.
StatusOr<SweepOutcome> run_sweep(const SweepSpec& s, const link::PartLibrary& parts,
                                 const SweepOptions& opt);

// The axes with more than one value (the fixed keys are not axes of a chart).
std::vector<size_t> varying_axes(const SweepSpec& s);

}  // namespace isolink::analysis::sweep
