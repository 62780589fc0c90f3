// Reduced model: a linear circuit's transfer from its time-varying sources to its probes as poles
// and residues, H_kp(s) = D_kp + sum_i out_pi in_ki / (s - p_i), built by Krylov projection and
// checked against the full circuit's exact AC solution. The LTI engine (solver/lti.h) evaluates
// it in closed form instead of marching the circuit.
//
//   StatusOr<ReducedModel> m = reduce_circuit(circuit, excitations, dc_solutions, probes, {});
//   m->stats.error, m->stats.order ...   // the check it passed
//
// Method (PRIMA-style moment matching, e.g. Odabasioglu, Celik and Pileggi, IEEE TCAD 1998):
// 1. The circuit is C x' + G x = sum_k e_k u_k, probes y_p = l_p . x. A real orthonormal basis V
//    gathers, for every source k: its DC solution G^-1 e_k (so the model's DC gain is exact), and
//    at each expansion point s0 = j 2 pi f the Krylov vectors A^-1 e_k, (A^-1 C) A^-1 e_k, ...
//    (`moments` of them; A = G + s0 C), real and imaginary parts added separately so that the
//    moments at s0 and its conjugate both match. Vectors already in the span are dropped
//    (orthogonalised one by one against all before them; `Basis` in the .cpp says how).
// 2. The projected system Gr = V'GV, Cr = V'CV, br = V'e, lr = l V is diagonalised through
//    M = (Gr + sigma Cr)^-1 Cr = W diag(lambda) W^-1 (sigma real, where Gr + sigma Cr is
//    regular, so singular G or C are fine): a mode with lambda = 0 is instantaneous and joins the
//    direct term D, every other is a pole p = sigma - 1/lambda.
// 3. The check: at `check_points` log-spaced frequencies from f_min to f_max, the model's
//    H_kp(j w) is compared with the full circuit's (one sparse LU per frequency, exact). The error
//    is max |H_r - H| over the peak |H| of that source and probe (DC gain included). Expansion
//    points are added greedily at the check frequency with the largest error (the next-worst
//    when its vectors are already in the basis), with up to `batch` - 1 more at the next-worst
//    local maxima of the error over the grid (the other resonances the model still misses: one
//    model built per step rather than per point), until the error is at most `tol`. Then the
//    grid is refined as adaptive quadrature does: the model must also pass at the geometric
//    midpoint of every check interval (a resonance can hide between check points); an interval
//    whose midpoint fails joins the grid as two halves, tested again at their own midpoints
//    once the search has fixed the model there (up to max_check_points). The step after a
//    refinement that failed takes up to `refine_batch` points where that is set. Accepted:
//    every check point passes and every interval's midpoint passed. The models of the search are
//    measured without their eigenvectors, through the Hessenberg form of M
//    (solver/hessenberg_transfer.h: O(q^2) a frequency instead of the O(q^3) eigendecomposition a
//    step); only the one that passes is diagonalised and measured again over the whole grid.
//    Should its modal form fail where the projection passed (step 4's dropped poles), the search
//    goes on with the modal form at every step. On the corpus's 72 m transformer link (order 658,
//    26 steps) this took the model from 30 s to 10 s, with the same expansion points and the same
//    output. A model likely to pass is diagonalised at once instead (small ones, whose grid
//    evaluation would cost more, and one after a refinement that failed at one or two midpoints,
//    usually the last: four of five on the corpus's 44-100 m links). Every modal form is taken
//    from the Hessenberg form (the Schur form of T: M is not reduced twice, nor Q formed).
// 4. A pole in the right half plane is a projection artefact (the circuits here are passive). It
//    is kept when it is so slow that it cannot grow over `horizon` (Re p horizon < 1e-3), and
//    dropped otherwise, before the check: a model that needed it fails the check there, and the
//    greedy search expands at that frequency.
//
// What the check guarantees in the time domain. An input edge of amplitude A rising linearly over
// tr has the spectrum A sinc(pi f tr) / (j 2 pi f), so the model's error on the response to it is
// at most e(t) <= (A / pi) integral |dH(f)| |sinc(pi f tr)| d(ln f) (the inverse transform's
// triangle inequality, both half-axes). |sinc(x)| <= min(1, 1/x): with the error weighted by
// W(f) = min(1, 1 / (pi f tr)) held under tol at every frequency of the band, the step
// response's error is at most A tol ln(f_max / f_min) / pi = 9.5e-5 A for the default band
// (2e-5, 1 kHz - 3 GHz): under 0.5 mV for a 5 V edge, whatever the edge time. The weighting
// costs nothing in that bound (an unweighted check gives the same one) but spares the model the
// resonances of a long cable above 1 / (pi tr) (32 MHz for 10 ns edges), which the drive hardly
// excites. `edge_time` must therefore be no longer than the inputs' fastest edge.
//
// What the check covers: the frequency band f_min..f_max (default 1 kHz - 3 GHz). Edges faster
// than 1 / (2 pi f_max) (50 ps) excite what lies above it, and responses slower than
// 1 / (2 pi f_min) rest on the exact DC gain and the 1 kHz expansion.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "base/status.h"
#include "solver/circuit.h"
#include "solver/probe.h"

namespace isolink {

struct ReducedModelOptions {
  double tol = 2e-5;   // relative error allowed at every check frequency
  double f_min = 1e3;  // Hz, check band
  double f_max = 3e9;  // Hz
  // Log-spaced over the band, then refined (step 3). A resonance narrower than their spacing can
  // hide between them: 96 points (15 a decade) and no refinement missed a 40-section LC
  // ladder's modes near its cutoff by 0.47 of the peak (tests/solver/reduced_model_test.cpp).
  int check_points = 128;
  int max_check_points = 4096;  // refinement stops here (accepted: spacing 0.4 % by then)
  int moments = 3;              // Krylov vectors per source and expansion point
  // Expansion points before giving up. 40 left 3 of 64 directions of the random corpus
  // (tools/link_corpus.py, seed 1) at 2.3-3.4e-5 after order 440-460: 68 m and 100 m links.
  int max_points = 64;
  // Expansion points per step of the greedy search (step 3). On the 12 m transformer link, at
  // 8 lengths from 11 to 13 m: 1 -> 10 points and 69 ms per model, 2 -> 59.5 ms, 3 -> 58.5 ms
  // (10-11 points), 4 -> 60 ms (11 points: more vectors than the model needs).
  int batch = 3;
  // Expansion points in the step after a refinement that failed (0: `batch`). Its failing
  // midpoints are resonances between passing points, which one expansion point seldom fixes for
  // another: the port model takes 10 (twice its batch; on the corpus's 44-100 m nonlinear links
  // 8-11 % off their models, one O(q^3) build fewer per refinement round, orders within 1 %;
  // every failing midpoint at once gained no more). Not the default: a fitted Touchstone cable's
  // LTI search (tests/analysis/touchstone_export_test.cpp, Capchoke5m) then stalled at 3.6e-5,
  // its error growing as the points went in, as it did when the search measured first where the
  // last model failed.
  int refine_batch = 0;
  // Basis size before giving up; lower on large circuits, where the basis (three dense
  // unknowns x order arrays, grown by doubling) would pass 384 MB (32,000 unknowns: order 524).
  int max_order = 1200;
  // A circuit of at most this many unknowns starts from the full basis (every unknown's unit
  // vector): the model is the circuit itself in modal form, still checked as any other. The
  // port model (solver/port_model.h) sets it: with one input per port, the Krylov search of a
  // small link reached full order anyway, after 6-7 expansion points and their checks.
  int full_order_at_most = 0;
  double horizon = 0.0;  // s, the longest time the model is evaluated over (step 4); > 0
  // s; > 0: the inputs' fastest edge (their shortest linear piece), and the check's error at f is
  // weighted by that edge's spectrum envelope, W(f) = min(1, 1 / (pi f edge_time)) (below).
  // 0: no weighting (every frequency counts fully, as for a step input).
  double edge_time = 0.0;
  // Hz: expansion points to start from besides f_min and f_max / 10, e.g. a neighbouring
  // circuit's (ReducedModelStats::points: the same link with one part a few percent off). The
  // search and its check are unchanged, so the model passes the same check; it just usually
  // needs fewer builds (isolink compare's fit on a 15 m cap link: 0.28 s of CPU per model
  // against 0.54 s; tests/solver/reduced_model_test.cpp). Points outside the band are ignored.
  std::vector<double> start_points;
  // A probe v(a, b) measured against the larger of its own peak and its nodes' (the peak of
  // max(|H_ka|, |H_kb|)): a source that moves both nodes together (a module ground's step seen
  // at a balanced receiver) has a difference near 0, which the model reproduces only to the
  // rounding of what its nodes carry. The check then holds the error of v(a, b) within tol of
  // the nodes' peak. Off: within tol of the difference's own peak (and 1e-6 of the strongest
  // source's). The port model sets it: on a 15 m link's ground-step circuit the search stalled
  // at 3.4e-5 on a transfer of 5e-11 (a difference of node transfers near 1).
  bool difference_scale = false;
  // 0: off. Otherwise, when the search can add no direction (every expansion point's vectors
  // are in the basis to rounding) or has used max_points / max_order with the error at most
  // stall_tol, the check's tolerance becomes stall_tol (ReducedModelStats::tol and relaxed say
  // so) and the model is accepted once it passes that, refinement included. The port model
  // sets 1e-4 (an edge's response then within 4.7e-4 of its amplitude times the pair's gain,
  // reported with the result): on the stress circuits of a 15 m link (1,100 unknowns, 13
  // probes) the Krylov search stalled at 2e-6 .. 7e-5 with no new direction.
  double stall_tol = 0.0;
  Status validate() const;  // names the field, its value and the rule
  // The bound the check guarantees (above) on the step response's error, per unit of edge
  // amplitude: tol ln(f_max / f_min) / pi (9.5e-5 with the defaults).
  double edge_error_bound() const;
  // The same bound for a model whose check's error is `error`.
  double edge_error_bound(double error) const;
};

struct ReducedModelStats {
  int order = 0;              // basis size
  int poles = 0;              // modes kept
  int direct_modes = 0;       // modes with lambda = 0
  int dropped = 0;            // right-half-plane poles dropped (step 4)
  double dropped_weight = 0;  // the largest of their weights |out in / p| over the peak
  int expansion_points = 0;
  int steps = 0;               // models built and checked
  double error = 0.0;          // the check's error (relative)
  double error_frequency = 0;  // Hz, where it is largest
  int factorizations = 0;      // complex sparse LUs (expansion points and check)
  int check_points = 0;        // frequencies checked, refinement included
  std::vector<double> points;  // Hz, the expansion points used (start_points of a neighbour)
  double tol = 0.0;            // the tolerance it passed: options.tol, or stall_tol if relaxed
  bool relaxed = false;
};

// A complex pole stands for itself and its conjugate (`paired`): its output is doubled, so that
// in the time domain a mode's share of a probe is always Re(out_pi x_i), x_i' = p_i x_i + in_ki
// u_k.
struct ReducedModel {
  std::vector<std::complex<double>> poles;                // [i], 1/s
  std::vector<bool> paired;                               // [i]: carries conj(p_i) too
  std::vector<std::vector<std::complex<double>>> input;   // [k][i]: in_ki
  std::vector<std::vector<std::complex<double>>> output;  // [p][i]: out_pi (doubled if paired)
  std::vector<std::vector<double>> direct;                // [k][p]: D_kp
  ReducedModelStats stats;

  // H_kp(s).
  std::complex<double> transfer(size_t k, size_t p, std::complex<double> s) const;
};

// excitations: per source, its unit excitation indexed by unknown ([0] ground, ignored).
// dc_solutions: per source, G^-1 e_k (same indexing), from the caller's DC solve.
// The circuit is read during the call only; the model owns its numbers (poles in 1/s, inputs
// and outputs per unit of source: V or A; direct terms V/V or A/V).
// Errors: the check not met within max_points / max_order (with the error reached), a growing
// mode, a singular projection.
StatusOr<ReducedModel> reduce_circuit(const Circuit& circuit,
                                      const std::vector<std::vector<double>>& excitations,
                                      const std::vector<std::vector<double>>& dc_solutions,
                                      const std::vector<Probe>& probes,
                                      const ReducedModelOptions& options);

}  // namespace isolink
