#include "tests/analysis/synthetic_capture.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "analysis/simulate.h"
#include "base/file_io.h"
#include "netlists/link/expand.h"
#include "netlists/link/parts.h"

namespace isolink::testing {
namespace {

// One-pole low-pass of a piecewise-linear input, exact per interval (ramp invariant).
std::vector<double> low_pass(const std::vector<double>& t, const std::vector<double>& x,
                             double bandwidth) {
  const double tau = 1.0 / (2 * M_PI * bandwidth);
  std::vector<double> y(x.size());
  y[0] = x[0];
  for (size_t i = 1; i < x.size(); ++i) {
    const double h = t[i] - t[i - 1], a = std::exp(-h / tau);
    y[i] = x[i] + (y[i - 1] - x[i - 1]) * a - (x[i] - x[i - 1]) * tau / h * (1 - a);
  }
  return y;
}

double interp(const std::vector<double>& t, const std::vector<double>& y, double at) {
  auto it = std::upper_bound(t.begin(), t.end(), at);
  if (it == t.begin()) return y.front();
  if (it == t.end()) return y.back();
  const size_t i = static_cast<size_t>(it - t.begin());
  const double f = (at - t[i - 1]) / (t[i] - t[i - 1]);
  return y[i - 1] + f * (y[i] - y[i - 1]);
}

}  // namespace

Status write_synthetic_capture(const std::string& spec_text, const std::string& name,
                               const std::vector<analysis::sweep::Assignment>& truth,
                               const ScopeModel& scope, const std::string& path) {
  StatusOr<link::LinkSpec> spec = analysis::sweep::spec_with(spec_text, name, truth);
  if (!spec) return spec.status();
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  if (!parts) return parts.status();
  StatusOr<link::ExpandedLink> x =
      link::expand_link(*spec, *parts, scope.up ? link::Direction::kUp : link::Direction::kDown);
  if (!x) return x.status();
  analysis::SimulationRequest req;
  req.probes = {"v(rxp)", "v(rxn)"};
  req.engine = analysis::Engine::Transient;
  req.tstep = 0.25e-9;
  req.tmax = 0.25e-9;
  StatusOr<analysis::SimulationResult> sim = analysis::simulate_netlist(x->netlist, req);
  if (!sim) return sim.status();
  const std::vector<double>& t = sim->wave.time;
  const std::vector<double> p = low_pass(t, sim->wave.columns[0], scope.bandwidth);
  const std::vector<double> n = low_pass(t, sim->wave.columns[1], scope.bandwidth);
  std::mt19937_64 rng(scope.seed);
  std::normal_distribution<double> noise(0.0, scope.noise_v);
  const double q = 2 * scope.range_v / std::pow(2.0, scope.bits);
  auto quantise = [&](double v) {
    v = std::clamp(v, -scope.range_v, scope.range_v - q);
    return std::round(v / q) * q;
  };
  const double dt = 1.0 / scope.sample_rate;
  const long count = static_cast<long>((t.back() - t.front()) / dt);
  std::string out;
  if (scope.layout == "rigol")
    out = fmt::format("X,CH1,CH2,Start,Increment,\nSequence,Volt,Volt,{:.9e},{:.9e}\n",
                      t.front() + scope.trigger, dt);
  else if (scope.layout == "picoscope")
    out = "Time,Channel A,Channel B\n(us),(V),(V)\n\n";
  else if (scope.layout == "saleae")
    out = "Time [s],Channel 0,Channel 1\n";
  else if (scope.layout == "keysight")
    out = "x-axis,1\nsecond,Volt\n";
  else
    return Status::Error("synthetic capture: unknown layout '" + scope.layout + "'");
  for (long k = 0; k < count; ++k) {
    const double ts = t.front() + static_cast<double>(k) * dt;
    const double vp = interp(t, p, ts) + noise(rng), vn = interp(t, n, ts) + noise(rng);
    if (scope.layout == "rigol")
      out += fmt::format("{},{:.6e},{:.6e},\n", k, quantise(vp), quantise(vn));
    else if (scope.layout == "picoscope")
      out += fmt::format("{:.9f},{:.6e},{:.6e}\n", (ts + scope.trigger) * 1e6, quantise(vp),
                         quantise(vn));
    else if (scope.layout == "saleae")
      out += fmt::format("{:.12e},{:.6e},{:.6e}\n", ts + scope.trigger, quantise(vp), quantise(vn));
    else
      out += fmt::format("{:.12e},{:.6e}\n", ts + scope.trigger, quantise(vp - vn));
  }
  return write_file_atomic(path, out);
}

}  // namespace isolink::testing
