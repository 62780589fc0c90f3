// The edge response (edge_response.h): one driver edge through the link, sampled from the LTI
// engine's reduced model (or tight transients) until it settles, and the superposition that turns
// it into the receiver's waveform of a whole drive.
#include "analysis/edge_response.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "solver/circuit.h"
#include "solver/lti.h"
#include "solver/probe.h"
#include "solver/transient.h"

namespace isolink::analysis {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEdgeTmaxSamples = 16;  // the edge response's largest step, in grid samples
constexpr double kLead = 1e-6;           // idle before the edge (the drive's default lead)

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

long to_samples(double t, double dt) {
  return std::lround(t / dt);
}

// Whether time t falls on a grid of step dt (within 1e-6 of a step).
bool on_sample(double t, double dt) {
  const double n = t / dt;
  return std::abs(n - std::round(n)) <= 1e-6;
}

}  // namespace

// v[i] += sum dL E(origin + i - n_edge) for i in [0, v.size()): the record of E (resp, its corner
// at resp[pre]) where it overlaps, its last value after it (a running sum, so long records cost
// what E's length does).
void add_response(const std::vector<double>& resp, long pre,
                  const std::vector<std::pair<long, int>>& edges, long origin,
                  std::vector<double>& v) {
  const long n = static_cast<long>(v.size());
  std::vector<double> step(static_cast<size_t>(n) + 1, 0.0);
  for (const auto& [at, dl] : edges) {
    const long zero = at - origin - pre;  // window sample of e[0]; E is 0 before it
    const long first = std::max(0L, zero);
    const long body_end = std::min(n, zero + static_cast<long>(resp.size()));
    step[static_cast<size_t>(std::min(n, std::max(first, body_end)))] += resp.back() * dl;
  }
  // The bodies block by block of v (4096 samples, in the first-level cache), every edge's part
  // of each: a long record with hundreds of edges otherwise streams all of v once per edge.
  constexpr long kBlock = 4096;
  for (long b0 = 0; b0 < n; b0 += kBlock) {
    const long b1 = std::min(n, b0 + kBlock);
    for (const auto& [at, dl] : edges) {
      const long zero = at - origin - pre;
      const long lo = std::max(b0, zero);
      const long hi = std::min(b1, zero + static_cast<long>(resp.size()));
      if (lo >= hi) continue;
      const double w = dl;
      double* out = v.data() + lo;
      const double* body = resp.data() + (lo - zero);
      for (long i = 0; i < hi - lo; ++i) out[i] += w * body[i];
    }
  }
  double level = 0;
  for (long i = 0; i < n; ++i) {
    level += step[static_cast<size_t>(i)];
    v[static_cast<size_t>(i)] += level;
  }
}

namespace {

// e.settle and e.drift over the last 10 % of the record (half: a half bit in samples).
void measure_settling(EdgeResponse& e, long half) {
  const long n = static_cast<long>(e.e.size());
  e.settle = 0;
  e.drift = 0;
  for (long i = n - n / 10; i < n; ++i) {
    e.settle = std::max(e.settle, std::abs(e.e[static_cast<size_t>(i)] - e.e.back()));
    e.drift = std::max(e.drift,
                       std::abs(e.e[static_cast<size_t>(i)] - e.e[static_cast<size_t>(i - half)]));
  }
}

}  // namespace

EdgeResponse coarsened(const EdgeResponse& e, int k, const EdgeResponseOptions& opt) {
  if (k <= 1) {
    EdgeResponse out = e;
    out.more.clear();
    return out;
  }
  EdgeResponse out;  // the fields, not the fine records
  out.v_idle = e.v_idle;
  out.span = e.span;
  out.engine_note = e.engine_note;
  out.seconds = e.seconds;
  out.dt = e.dt * k;
  out.pre = e.pre / k;
  out.e.reserve(e.e.size() / static_cast<size_t>(k) + 1);
  for (size_t i = static_cast<size_t>(e.pre % k); i < e.e.size(); i += static_cast<size_t>(k))
    out.e.push_back(e.e[i]);
  out.engine = fmt::format("{}; every {}th sample kept: a {:g} ns grid", e.engine, k, out.dt * 1e9);
  measure_settling(out, to_samples(opt.expand.stimulus.encoding.half_bit, out.dt));
  return out;
}

namespace {

// EdgeResponse::Tail's column c at q samples after its start, from the closed form.
double tail_value(const EdgeResponse::Tail& t, size_t c, long q) {
  double v = t.constant[c];
  for (size_t i = 0; i < t.z.size(); ++i)
    v += (t.amplitude[c][i] * std::pow(t.z[i], static_cast<double>(q))).real();
  return v;
}

// One direction's edge response (EdgeResponse): the link driven by one 0 -> +1 edge at kLead,
// sampled from the reduced model in closed form (EdgeEngine::Auto) or from tight transients, on
// longer records until it settles.
class EdgeResponseBuilder {
 public:
  EdgeResponseBuilder(const link::LinkSpec& spec, const link::PartLibrary& parts, link::Direction d,
                      const EdgeResponseOptions& opt, EdgeResponse& out)
      : spec_(spec),
        parts_(parts),
        d_(d),
        opt_(opt),
        out_(out),
        half_(to_samples(opt.expand.stimulus.encoding.half_bit, opt.dt)) {
    out_.dt = opt.dt;
    out_.pre = to_samples(50e-9, opt.dt);
    out_.more.assign(opt.more_probes.size(), {});
    for (size_t i = 0; i < out_.more.size(); ++i) out_.more[i].probe = opt.more_probes[i];
  }

  // The reduced model: one model, sampled on longer records until settled. *done false (and
  // out.engine_note why) when the model cannot be made: the transient takes over.
  Status from_reduced_model(bool* done);
  // Transients of longer records until the response settles.
  Status from_transients();

 private:
  // Settling of a sampled record (see EdgeResponse): true when it has settled.
  bool settled(double span) {
    out_.span = span;
    measure_settling(out_, half_);
    return out_.drift <= opt_.settle_tol;
  }
  Status unsettled(const std::string& what, double span) const {
    return Status::Error(fmt::format(
        "{}: the edge response has not settled {:g} us after the edge (a half bit's response is "
        "still {:.1f} uV, more than {:.1f} uV): the link's memory is too long for the "
        "worst-case search",
        what, span * 1e6, out_.drift * 1e6, opt_.settle_tol * 1e6));
  }
  // The records from sample `from` on.
  Status finite(const std::string& what, size_t from = 0) const {
    auto all_finite = [from](const std::vector<double>& rec) {
      return std::all_of(rec.begin() + static_cast<long>(std::min(from, rec.size())), rec.end(),
                         [](double x) { return std::isfinite(x); });
    };
    if (!all_finite(out_.e)) return Status::Error(what + ": the edge response is not finite");
    for (const EdgeResponse::Column& c : out_.more)
      if (!all_finite(c.e))
        return Status::Error(what + ": the edge response of " + c.probe + " is not finite");
    return Status::Ok();
  }
  // The link driven by one 0 -> +1 edge at kLead, held for `span`.
  StatusOr<link::ExpandedLink> edge_link(double span) const {
    traffic::Drive drive;
    drive.encoding = opt_.expand.stimulus.encoding;
    drive.segments = {{0.0, kLead, 0}, {kLead, kLead + span, +1}};
    link::ExpandOptions ex = opt_.expand;
    ex.drive = drive;
    return link::expand_link(spec_, parts_, d_, ex);
  }
  // The circuit and its probes: v(rxp,rxn), then opt.more_probes.
  StatusOr<std::vector<Probe>> edge_circuit(const link::ExpandedLink& link,
                                            Circuit& circuit) const {
    for (const Card& card : link.netlist.cards)
      if (Status s = circuit.add(card); !s.ok()) return s;
    if (Status s = circuit.finalize(); !s.ok()) return s;
    std::vector<Probe> probes;
    for (size_t i = 0; i <= opt_.more_probes.size(); ++i) {
      StatusOr<Probe> p = parse_probe(circuit, i == 0 ? "v(rxp,rxn)" : opt_.more_probes[i - 1]);
      if (!p) return p.status();
      probes.push_back(*p);
    }
    return probes;
  }
  // Samples the model on records of 40 us, doubled until the response settles.
  Status sample_model(const LtiResponses& lti, const std::string& description);
  // Samples a transient's waveform w (a record of `span` after the edge).
  void sample_transient(const Waveform& w, double span);
  void attach_tail(const LtiResponses& lti, const std::vector<SourceInput>& inputs);

  const link::LinkSpec& spec_;
  const link::PartLibrary& parts_;
  const link::Direction d_;
  const EdgeResponseOptions& opt_;
  EdgeResponse& out_;
  const long half_;
};

Status EdgeResponseBuilder::from_reduced_model(bool* done) {
  StatusOr<link::ExpandedLink> link = edge_link(opt_.max_span);
  if (!link) return link.status();
  Circuit circuit;
  StatusOr<std::vector<Probe>> probes = edge_circuit(*link, circuit);
  if (!probes) return probes.status();
  for (const auto& e : circuit.elements()) e->bind_time(opt_.dt, kLead + opt_.max_span);
  LtiOptions lo;
  lo.method = LtiOptions::Method::Reduced;
  lo.horizon = kLead + opt_.max_span;
  // The driver's two lines move together (n = vdd - p): one model input, half the order. The
  // responses are only ever taken for the netlist's own drive (netlist_inputs).
  lo.tie_sources = true;
  const auto by_direction = opt_.reduced_start_points_by_direction.find(d_);
  lo.reduced.start_points = by_direction != opt_.reduced_start_points_by_direction.end()
                                ? by_direction->second
                                : opt_.reduced_start_points;
  if (opt_.progress) opt_.progress("edge response, reduced model", 0.0);
  StatusOr<LtiResponses> lti = LtiResponses::compute(circuit, *probes, lo);
  if (!lti) {
    out_.engine_note = "reduced model not used: " + lti.status().message();
    return Status::Ok();
  }
  if (Status s = sample_model(*lti, link->description); !s.ok()) return s;
  const ReducedModelStats& m = lti->stats().model;
  out_.engine = fmt::format(
      "reduced model (order {}, {} poles, {} expansion points, AC error {:.1e} of peak up to "
      "3 GHz), sampled on a {:g} ns grid",
      m.order, m.poles, m.expansion_points, m.error, opt_.dt * 1e9);
  out_.expansion_points = m.points;
  *done = true;
  return Status::Ok();
}

Status EdgeResponseBuilder::sample_model(const LtiResponses& lti, const std::string& description) {
  const std::vector<SourceInput> inputs = lti.netlist_inputs(kLead + opt_.max_span);
  out_.v_idle = lti.value(0, kLead - 2 * out_.pre * opt_.dt, inputs);
  for (size_t i = 0; i < out_.more.size(); ++i)
    out_.more[i].v_idle = lti.value(i + 1, kLead - 2 * out_.pre * opt_.dt, inputs);
  out_.e.clear();
  for (double span = 40e-6;; span *= 2) {
    // Only the samples the longer record adds: the model starts them from the edge exactly.
    const long from = static_cast<long>(out_.e.size()), n = out_.pre + to_samples(span, opt_.dt);
    std::vector<double> times(static_cast<size_t>(n - from));
    for (long i = from; i < n; ++i)
      times[static_cast<size_t>(i - from)] = kLead + static_cast<double>(i - out_.pre) * opt_.dt;
    const std::vector<std::vector<double>> v = lti.values(inputs, times);
    auto append = [](std::vector<double>& rec, const std::vector<double>& x, double idle) {
      const size_t at = rec.size();
      rec.resize(at + x.size());
      double* out = rec.data() + at;
      for (size_t i = 0; i < x.size(); ++i) out[i] = x[i] - idle;
    };
    append(out_.e, v[0], out_.v_idle);
    for (size_t i = 0; i < out_.more.size(); ++i)
      append(out_.more[i].e, v[i + 1], out_.more[i].v_idle);
    if (Status s = finite(description, static_cast<size_t>(from)); !s.ok()) return s;
    if (settled(span)) {
      attach_tail(lti, inputs);
      return Status::Ok();
    }
    if (span * 2 > opt_.max_span) return unsettled(description, span);
  }
}

// EdgeResponse::tail from the model at the first sample past the ramp's last corner, kept only
// where it reproduces the sampled record (every column, 16 samples spread over the rest of the
// record, within 1e-9 V + 1e-9 of the most the tail can be, |constant| + sum |a|): the
// superposition then trusts it past the record too.
void EdgeResponseBuilder::attach_tail(const LtiResponses& lti,
                                      const std::vector<SourceInput>& inputs) {
  double last = kLead;
  for (const SourceInput& in : inputs)
    for (const Ramp& r : in.ramps) last = std::max(last, r.t);
  const long start = static_cast<long>(std::ceil((last - kLead) / opt_.dt - 1e-9));
  const long n = static_cast<long>(out_.e.size());
  if (out_.pre + start >= n) return;
  const std::optional<LtiResponses::ModalTail> mt =
      lti.modal_tail(inputs, kLead + static_cast<double>(start) * opt_.dt);
  if (!mt) return;
  EdgeResponse::Tail tail;
  tail.start = start;
  for (const std::complex<double>& p : mt->poles) tail.z.push_back(std::exp(p * opt_.dt));
  tail.amplitude = mt->amplitude;
  tail.constant = mt->constant;
  tail.constant[0] -= out_.v_idle;
  for (size_t c = 0; c < out_.more.size(); ++c) tail.constant[c + 1] -= out_.more[c].v_idle;
  for (size_t c = 0; c <= out_.more.size(); ++c) {
    const std::vector<double>& rec = c == 0 ? out_.e : out_.more[c - 1].e;
    double peak = std::abs(tail.constant[c]);  // the most the tail can be
    for (const std::complex<double>& a : tail.amplitude[c]) peak += std::abs(a);
    const long len = n - out_.pre - start;
    for (long j = 0; j < 16; ++j) {
      const long q = j * (len - 1) / 15;
      if (std::abs(tail_value(tail, c, q) - rec[static_cast<size_t>(out_.pre + start + q)]) >
          1e-9 + 1e-9 * peak)
        return;
    }
  }
  out_.tail = std::move(tail);
}

Status EdgeResponseBuilder::from_transients() {
  for (double span = 40e-6;; span *= 2) {
    StatusOr<link::ExpandedLink> link = edge_link(span);
    if (!link) return link.status();
    Circuit circuit;
    StatusOr<std::vector<Probe>> probes = edge_circuit(*link, circuit);
    if (!probes) return probes.status();
    TransientOptions to;
    to.tstep = opt_.dt;
    to.tstop = kLead + span;
    // Steps up to 16 grid samples where the response is slow (the transformer's tail): the
    // reltol 1e-6 error control keeps them near the grid wherever v moves. Measured against
    // tmax = dt: the worst-case values of cap_2m and transformer_15m agree within 10 nV and 2.5 ps,
    // the same traffic wins, and the edge response of transformer_15m takes 4.7 s, not 20 s.
    to.tmax = kEdgeTmaxSamples * opt_.dt;
    to.reltol = opt_.reltol;
    if (opt_.progress)
      to.on_progress = [&](double t) {
        opt_.progress(fmt::format("edge response, {:g} us", span * 1e6), t / to.tstop);
      };
    if (Status s = to.validate(); !s.ok()) return s;
    StatusOr<Waveform> w = run_transient(circuit, to, *probes);
    if (!w) return w.status().with_context(link->description + ", edge response");
    sample_transient(*w, span);
    if (Status s = finite(link->description); !s.ok()) return s;
    if (settled(span)) break;
    if (span * 2 > opt_.max_span) return unsettled(link->description, span);
  }
  out_.engine = fmt::format("transient, reltol {:g}, tmax {:g} ns, sampled on a {:g} ns grid",
                            opt_.reltol, kEdgeTmaxSamples * opt_.dt * 1e9, opt_.dt * 1e9);
  return Status::Ok();
}

void EdgeResponseBuilder::sample_transient(const Waveform& w, double span) {
  out_.v_idle = w.value_at(0, kLead - 2 * out_.pre * opt_.dt);
  const long n = out_.pre + to_samples(span, opt_.dt);
  out_.e.assign(static_cast<size_t>(n), 0.0);
  for (long i = 0; i < n; ++i)
    out_.e[static_cast<size_t>(i)] =
        w.value_at(0, kLead + static_cast<double>(i - out_.pre) * opt_.dt) - out_.v_idle;
  for (size_t c = 0; c < out_.more.size(); ++c) {
    EdgeResponse::Column& col = out_.more[c];
    col.v_idle = w.value_at(c + 1, kLead - 2 * out_.pre * opt_.dt);
    col.e.assign(static_cast<size_t>(n), 0.0);
    for (long i = 0; i < n; ++i)
      col.e[static_cast<size_t>(i)] =
          w.value_at(c + 1, kLead + static_cast<double>(i - out_.pre) * opt_.dt) - col.v_idle;
  }
}

}  // namespace

StatusOr<EdgeResponse> edge_response(const link::LinkSpec& spec, const link::PartLibrary& parts,
                                     link::Direction d, const EdgeResponseOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (std::string why = link::linear_only(spec, "the edge response"); !why.empty())
    return Status::Error(why);
  if (opt.expand.driver.clamps.enabled || opt.expand.load.clamps.enabled)
    return Status::Error(
        "the edge response needs a linear link (it superposes the link's responses), and the "
        "expansion adds the pins' clamp diodes");
  EdgeResponse out;
  EdgeResponseBuilder builder(spec, parts, d, opt, out);
  bool done = false;
  if (opt.edge_engine == EdgeResponseOptions::EdgeEngine::Auto)
    if (Status s = builder.from_reduced_model(&done); !s.ok()) return s;
  if (!done)
    if (Status s = builder.from_transients(); !s.ok()) return s;
  out.seconds = seconds_since(start);
  return out;
}

namespace {

// v = v_idle + sum dL E(. - n_edge) on [0, n) of the fine grid (resp: E, its corner at resp[pre]),
// exactly, in two passes when every edge and the corner fall on every k-th sample (k > 1): the
// sum on the coarse grid (every k-th sample of E, its whole record), linearly interpolated, plus
// the sum of E's interpolation residual r (E minus the linear interpolation of its coarse
// samples), which is non-zero only while E bends (ringing after the edge; a slow tail is almost
// linear). r is cut where every later |r| stays below tol / 2 / sum |dL|, so the cut moves v by
// at most tol / 2. Linear interpolation is linear, so the two passes add up to the fine sum.
std::vector<double> superpose(const std::vector<double>& resp, long pre, double v_idle,
                              const std::vector<std::pair<long, int>>& edges, long n, long k,
                              double tol) {
  std::vector<double> v(static_cast<size_t>(n), v_idle);
  double weight = 0;
  for (const auto& [at_, dl] : edges) weight += std::abs(dl);
  // Before its record E is 0; the interpolation from there to resp[0] (the idle, 50 ns before the
  // corner: 0 to rounding) is not in the residual, so it must be below tol as well.
  if (k <= 1 || pre % k != 0 || resp.empty() || std::abs(resp[0]) * weight > tol / 2) {
    add_response(resp, pre, edges, 0, v);
    return v;
  }
  const long nc = (n + k - 1) / k + 1;  // coarse samples covering [0, n)
  const long m = static_cast<long>(resp.size());
  auto at = [&](long i) { return i < m ? resp[static_cast<size_t>(i)] : resp.back(); };
  std::vector<double> coarse_resp;  // every k-th sample, up to one at or past the record's end
  for (long i = 0; i < m + k - 1; i += k) coarse_resp.push_back(at(i));
  std::vector<std::pair<long, int>> coarse_edges = edges;
  for (auto& [at_, dl] : coarse_edges) at_ /= k;
  std::vector<double> vc(static_cast<size_t>(nc), v_idle);
  add_response(coarse_resp, pre / k, coarse_edges, 0, vc);
  // The residual on the fine grid, 0 at the coarse samples and past the record (E constant).
  std::vector<double> r(static_cast<size_t>(m), 0.0);
  for (long a = 0; a < m; a += k) {
    const double ya = at(a), slope = (at(a + k) - ya) / static_cast<double>(k);
    for (long p = 1; p < k && a + p < m; ++p)
      r[static_cast<size_t>(a + p)] = at(a + p) - (ya + slope * static_cast<double>(p));
  }
  const double cut = weight > 0 ? tol / 2 / weight : 0.0;
  long last = m - 1;
  while (last >= 0 && std::abs(r[static_cast<size_t>(last)]) <= cut) --last;
  r.resize(static_cast<size_t>(last + 2), 0.0);  // ends in 0: no step after it
  for (long j = 0; j * k < n; ++j) {
    const double a = vc[static_cast<size_t>(j)], slope = (vc[static_cast<size_t>(j + 1)] - a) / k;
    for (long p = 0; p < k && j * k + p < n; ++p)
      v[static_cast<size_t>(j * k + p)] = a + slope * static_cast<double>(p);
  }
  add_response(r, pre, edges, 0, v);
  return v;
}

// out[i] += sign Re(y_m z_m^i) for i in [0, count) and each of N modes: their recursions
// y <- z y (real and imaginary parts in registers), interleaved so that the N independent chains
// share the multiplies' latency; each out[i] gets its terms in the modes' order, the sums of one
// mode after another to the bit. y becomes y z^count.
template <int N>
void add_modes(std::complex<double>* y, const std::complex<double>* z, double sign, double* out,
               long count) {
  double yr[N], yi[N], zr[N], zi[N];
  for (int m = 0; m < N; ++m)
    yr[m] = y[m].real(), yi[m] = y[m].imag(), zr[m] = z[m].real(), zi[m] = z[m].imag();
  for (long i = 0; i < count; ++i) {
    double acc = out[i];
    for (int m = 0; m < N; ++m) {
      acc += sign * yr[m];
      const double nr = yr[m] * zr[m] - yi[m] * zi[m];
      yi[m] = yr[m] * zi[m] + yi[m] * zr[m];
      yr[m] = nr;
    }
    out[i] = acc;
  }
  for (int m = 0; m < N; ++m) y[m] = {yr[m], yi[m]};
}

// add_modes over any number of modes, four at a time.
void add_mode_groups(std::complex<double>* y, const std::complex<double>* z, size_t modes,
                     double sign, double* out, long count) {
  for (size_t g = 0; g < modes; g += 4) {
    switch (std::min<size_t>(4, modes - g)) {
      case 4:
        add_modes<4>(y + g, z + g, sign, out, count);
        break;
      case 3:
        add_modes<3>(y + g, z + g, sign, out, count);
        break;
      case 2:
        add_modes<2>(y + g, z + g, sign, out, count);
        break;
      default:
        add_modes<1>(y + g, z + g, sign, out, count);
    }
  }
}

// What superpose_with_tail does with a record's tail: which modes it sums by recursion (slow) and
// how many samples of the rest it keeps past the tail's start (head).
struct TailSplit {
  std::vector<size_t> slow;
  long head = 0;
};

// The split with the least work: the edges' overlap with the kept record (superpose's coarse pass,
// every k-th sample) against the recursion's n samples per slow mode (a complex multiply each,
// counted as three). A mode outside the slow set must have fallen below cut / modes by the end
// of the kept record (|a| |z|^head), so the modes cut off move no sample by more than cut; the
// kept record cannot outrun the sampled one (`room` samples past the tail's start). Empty
// (nothing slow, head -1) when keeping the whole record costs least.
TailSplit split_tail(const EdgeResponse::Tail& t, size_t column, long record,
                     const std::vector<std::pair<long, int>>& edges, long pre, long n, long k,
                     double cut) {
  const long room = record - pre - t.start;
  const size_t modes = t.z.size();
  std::vector<std::pair<double, size_t>> life;  // samples until the mode is below its share
  for (size_t i = 0; i < modes; ++i) {
    const double a = std::abs(t.amplitude[column][i]), r = std::abs(t.z[i]);
    const double share = cut / static_cast<double>(modes);
    double samples = 0;
    if (a > share) samples = r < 1 ? std::ceil(std::log(share / a) / std::log(r)) : kInf;
    life.emplace_back(samples, i);
  }
  std::sort(life.begin(), life.end());
  auto overlap = [&](long kept) {  // coarse samples the edges' kept records cover
    double c = 0;
    for (const auto& [at, dl] : edges)
      c += static_cast<double>(std::max(0L, std::min(kept, n - (at - pre)))) / k;
    return c;
  };
  constexpr double kRecursionCost = 3;
  TailSplit best;
  best.head = -1;
  double best_cost = overlap(record);    // no split: every edge's whole record
  for (size_t m = 0; m <= modes; ++m) {  // the m shortest-lived modes kept in the record
    const double head = m == 0 ? 0.0 : life[m - 1].first;
    if (head >= static_cast<double>(room)) break;
    if (m < modes && life[m].first == head) continue;  // ties: take them all
    const double cost = overlap(pre + static_cast<long>(head) + 1) +
                        kRecursionCost * static_cast<double>(n) * static_cast<double>(modes - m);
    if (cost < best_cost) {
      best_cost = cost;
      best.head = static_cast<long>(head);
      best.slow.clear();
      for (size_t j = m; j < modes; ++j) best.slow.push_back(life[j].second);
    }
  }
  return best;
}

// superpose() of a record whose tail is known in closed form (EdgeResponse::Tail, `column` of
// it): E = S + H, S the slow modes and the constant from the tail's start on (0 before it), H
// the rest, which the fast modes make short. H is summed as superpose() sums any record (cut
// where its modes have decayed: they move no sample by more than tol / 4); S by one recursion per
// mode over the record, s <- z s plus dL a at each edge's tail start, whatever the number of
// edges. The slow tail of a long record (a transformer link's 160 us) no longer costs each edge
// its whole length. Exact but for those cuts: within tol, as superpose().
std::vector<double> superpose_with_tail(const std::vector<double>& resp, long pre, double v_idle,
                                        const EdgeResponse::Tail& t, size_t column,
                                        const std::vector<std::pair<long, int>>& edges, long n,
                                        long k, double tol) {
  double weight = 0;
  for (const auto& [at_, dl] : edges) weight += std::abs(dl);
  const long ts = pre + t.start, m = static_cast<long>(resp.size());
  if (weight == 0 || ts >= m) return superpose(resp, pre, v_idle, edges, n, k, tol);
  const TailSplit split = split_tail(t, column, m, edges, pre, n, k, tol / 4 / weight);
  if (split.head < 0) return superpose(resp, pre, v_idle, edges, n, k, tol);
  // H: the record up to the tail's start, then minus S, cut after `head` samples (ends in 0).
  std::vector<double> h(resp.begin(), resp.begin() + ts + split.head);
  for (long q = 0; q < split.head; ++q) h[static_cast<size_t>(ts + q)] -= t.constant[column];
  const size_t ns = split.slow.size();
  std::vector<std::complex<double>> z(ns), a(ns), y(ns);  // the slow modes' z, amplitude, sum
  for (size_t s = 0; s < ns; ++s)
    z[s] = t.z[split.slow[s]], a[s] = y[s] = t.amplitude[column][split.slow[s]];
  add_mode_groups(y.data(), z.data(), ns, -1.0, h.data() + ts, split.head);
  h.push_back(0.0);
  std::vector<double> v = superpose(h, pre, v_idle, edges, n, k, tol / 2);
  // S: the constant as steps, each slow mode by its recursion, from each edge's tail start.
  std::vector<std::pair<long, double>> starts;  // (sample of the tail's start, dL)
  for (const auto& [at, dl] : edges) starts.emplace_back(at + t.start, dl);
  std::sort(starts.begin(), starts.end());
  // Between two tail starts (and after the last) every term runs freely: [from, to) of v.
  auto between = [&](size_t e, long* from, long* to) {
    *from = std::clamp(starts[e].first, 0L, n);
    *to = e + 1 < starts.size() ? std::clamp(starts[e + 1].first, 0L, n) : n;
  };
  double level = 0;
  long from = 0, to = 0;
  for (size_t e = 0; e < starts.size(); ++e) {
    level += starts[e].second * t.constant[column];
    between(e, &from, &to);
    for (long i = from; i < to; ++i) v[static_cast<size_t>(i)] += level;
  }
  // Every slow mode's sum y at sample `at`, all of them together from edge to edge.
  std::fill(y.begin(), y.end(), 0.0);
  long at = starts.front().first;
  auto move_to = [&](long sample) {
    if (sample <= at) return;
    for (size_t s = 0; s < ns; ++s) y[s] *= std::pow(z[s], static_cast<double>(sample - at));
    at = sample;
  };
  for (size_t e = 0; e < starts.size(); ++e) {
    move_to(starts[e].first);
    for (size_t s = 0; s < ns; ++s) y[s] += starts[e].second * a[s];
    between(e, &from, &to);
    move_to(from);  // a start before sample 0
    if (from >= to) continue;
    add_mode_groups(y.data(), z.data(), ns, 1.0, v.data() + from, to - from);
    at = to;
  }
  return v;
}

}  // namespace

StatusOr<Waveform> synthesize_drive(const EdgeResponse& e, const traffic::Drive& drive,
                                    double t_end) {
  // The PWL sources start at the first segment's level (the operating point) and hold the
  // last one: the response of a line idle at the start, and of each level change after.
  if (!drive.segments.empty() && drive.segments.front().level != 0)
    return Status::Error("the drive does not start idle: no edge response superposes to it");
  std::vector<std::pair<long, int>> edges;
  int level = 0;
  long k = 4;  // the coarse grid of superpose: every 4th, 2nd or 1st sample, as the edges allow
  for (const traffic::DriveSegment& g : drive.segments) {
    if (g.level == level) continue;
    if (!on_sample(g.start, e.dt))
      return Status::Error(fmt::format(
          "the drive changes level at {:.6g} us, off the {:g} ns grid of the edge response",
          g.start * 1e6, e.dt * 1e9));
    edges.push_back({to_samples(g.start, e.dt), g.level - level});
    while (edges.back().first % k != 0) k /= 2;
    level = g.level;
  }
  const long n = std::max(2L, to_samples(t_end, e.dt) + 1);
  if (n > 100'000'000)
    return Status::Error(fmt::format("a {:g} us record on a {:g} ns grid is too long to synthesize",
                                     t_end * 1e6, e.dt * 1e9));
  constexpr double kTol = 20e-6;  // V: the most the residual's cut moves any sample
  Waveform w;
  w.time.resize(static_cast<size_t>(n));
  for (long i = 0; i < n; ++i) w.time[static_cast<size_t>(i)] = static_cast<double>(i) * e.dt;
  auto column = [&](size_t c) {
    const std::vector<double>& resp = c == 0 ? e.e : e.more[c - 1].e;
    const double v_idle = c == 0 ? e.v_idle : e.more[c - 1].v_idle;
    return e.tail ? superpose_with_tail(resp, e.pre, v_idle, *e.tail, c, edges, n, k, kTol)
                  : superpose(resp, e.pre, v_idle, edges, n, k, kTol);
  };
  w.add_column("v(rxp,rxn)", column(0));
  for (size_t c = 0; c < e.more.size(); ++c) w.add_column(e.more[c].probe, column(c + 1));
  return w;
}

bool on_grid(const traffic::Drive& drive, double dt) {
  for (const traffic::DriveSegment& g : drive.segments)
    if (!on_sample(g.start, dt)) return false;
  return true;
}

}  // namespace isolink::analysis
