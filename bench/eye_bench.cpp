// Eye checker throughput: isolink::eye::check_samples on a 10-million-sample waveform
// (1 ns steps: about 1100 frames of 6.5 us with 2 us idle, droop, ringing-free edges, noise),
// CSV parsing of a 1-million-row capture, and reading a 10-million-sample LeCroy .trc (binary,
// from a file: the size-checked, chunked byte cursor of eye/scope_binary.cpp). Run:
// build/bench/eye_bench
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "eye/check.h"
#include "eye/rules.h"
#include "eye/waveform_csv.h"
#include "protocol/frame.h"

namespace {

using isolink::FrameFormat;

struct Wave {
  std::vector<double> t, v;
};

// Frames of bytes 0, 1, 2, ... each 2 us apart; 20 ns edges, droop tau 3 us, +/-10 mV noise.
Wave make_wave(size_t n, double dt) {
  Wave w;
  w.t.resize(n);
  w.v.resize(n);
  const double T = 250e-9, tr = 20e-9, amp = 2.2, tau = 3e-6, gap = 2e-6;
  std::vector<int> hb;  // half bits of the whole record, 0 = idle
  const size_t idle_halves = static_cast<size_t>(gap / T);
  size_t byte = 0;
  while (static_cast<double>(hb.size()) * T < static_cast<double>(n) * dt) {
    for (int s : isolink::frame_half_bits(static_cast<uint8_t>(byte++), FrameFormat{}))
      hb.push_back(s);
    hb.insert(hb.end(), idle_halves, 0);
  }
  uint64_t state = 12345;
  double level_start = 0;  // time the current level began
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    const size_t h = static_cast<size_t>(t / T);
    const double into = t - static_cast<double>(h) * T;
    const int cur = hb[h];
    const int prev = h > 0 ? hb[h - 1] : 0;
    if (cur != prev && into < 1.5 * dt) level_start = static_cast<double>(h) * T;
    double target = cur * amp * std::exp(-(t - level_start) / tau);
    if (cur != prev && into < tr / 2) {  // second half of the edge from prev towards cur
      const double from = prev * amp * 0.9;
      const double mid = 0.5 * (from + cur * amp);
      target = mid + (cur * amp - mid) * (into / (tr / 2));
    }
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const double u = static_cast<double>(state >> 11) / 9007199254740992.0;
    w.t[i] = t;
    w.v[i] = target + 0.02 * (u - 0.5);
  }
  return w;
}

void BM_CheckSamples10M(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const Wave w = make_wave(n, 1e-9);
  const isolink::eye::Rules rules = *isolink::eye::load_rules("bq7961x");
  size_t pulses = 0, bytes = 0;
  for (auto _ : state) {
    auto r = isolink::eye::check_samples(w.t, w.v, rules);
    pulses = r->pulses.size();
    bytes = r->bytes.size();
    benchmark::DoNotOptimize(r->pass);
  }
  state.counters["pulses"] = static_cast<double>(pulses);
  state.counters["bytes"] = static_cast<double>(bytes);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_CheckSamples10M)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

void BM_ParseCsv1M(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const Wave w = make_wave(n, 1e-9);
  std::string text = "time,v(rxp,rxn)\n";
  char buf[64];
  for (size_t i = 0; i < n; ++i) {
    std::snprintf(buf, sizeof buf, "%.12g,%.9g\n", w.t[i], w.v[i]);
    text += buf;
  }
  for (auto _ : state) {
    auto r = isolink::eye::parse_differential_csv(text, "bench.csv");
    benchmark::DoNotOptimize(r->time.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ParseCsv1M)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

// A LECROY_2_3 .trc (little-endian, 16-bit, 0.1 mV counts) of the same waveform, read from a
// temporary file: header checks, chunked reads, the time axis, what-was-read.
void BM_ReadTrc10M(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const Wave w = make_wave(n, 1e-9);
  std::string d(346, '\0');
  auto put = [&](size_t off, const void* x, size_t len) { std::memcpy(&d[off], x, len); };
  const int16_t comm_type = 1, comm_order = 1;
  const int32_t desc = 346, bytes = static_cast<int32_t>(2 * n), count = static_cast<int32_t>(n),
                last = count - 1, one = 1;
  const float gain = 1e-4f, offset = 0.0f, interval = 1e-9f;
  const double t0 = 0.0;
  std::memcpy(&d[0], "WAVEDESC", 8);
  std::memcpy(&d[16], "LECROY_2_3", 10);
  put(32, &comm_type, 2);
  put(34, &comm_order, 2);
  put(36, &desc, 4);
  put(60, &bytes, 4);
  put(116, &count, 4);
  put(128, &last, 4);
  put(136, &one, 4);
  put(144, &one, 4);
  put(156, &gain, 4);
  put(160, &offset, 4);
  put(176, &interval, 4);
  put(180, &t0, 8);
  d[196] = 'V';
  d[244] = 'S';
  std::vector<int16_t> raw(n);
  for (size_t i = 0; i < n; ++i) raw[i] = static_cast<int16_t>(std::lround(w.v[i] / 1e-4));
  const std::string path =
      (std::filesystem::temp_directory_path() / "isolink_eye_bench.trc").string();
  {
    std::ofstream f(path, std::ios::binary);
    f.write(d.data(), static_cast<std::streamsize>(d.size()));
    f.write(reinterpret_cast<const char*>(raw.data()), static_cast<std::streamsize>(2 * n));
  }
  for (auto _ : state) {
    auto r = isolink::eye::read_capture({path}, {});
    benchmark::DoNotOptimize(r->time.data());
  }
  std::filesystem::remove(path);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(346 + 2 * n));
}
BENCHMARK(BM_ReadTrc10M)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
