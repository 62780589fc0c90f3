// Synthetic receiver waveforms and PNG read-back for the reports tests (and the preview program).
//
//   LinkWave w = link_wave({0x80, 0x02}, {});                 // ideal trapezoids, 1 ns samples
//   LinkWave bad = link_wave({0x80}, {.short_pulse = 3});     // pulse 3 of frame 0 is 150 ns
//   Png img = read_png(path);  img.at(x, y)[0] ...
// The differential is built with tests/eye/synth.h (edges of a full swing in tr, widths exactly
// k*T); `realistic` passes it through a 30 MHz second-order low-pass (zeta 0.6: overshoot) and a
// 3 us AC-coupling high-pass (droop on long pulses). Pins: P = 2.5 + v/2 + cm, N = 2.5 - v/2 + cm.
#pragma once

#include <OpenImageIO/imagebuf.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "base/waveform.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "protocol/frame.h"
#include "tests/eye/synth.h"

namespace isolink::reports::fixtures {

struct LinkWaveOptions {
  double dt = 1e-9;        // sample step (s)
  double amplitude = 2.0;  // pulse level (V)
  double gap = 2e-6;       // idle between frames (s)
  int short_pulse = -1;    // >= 0: this pulse of frame short_frame ends 100 ns early
  int short_frame = 0;
  bool realistic = false;   // filter: overshoot, ringing and droop
  double cm_amplitude = 0;  // common-mode sine on both pins (V)
  double cm_frequency = 150e3;
};

struct LinkWave {
  std::vector<double> t, v, p, n;  // time, differential, pins
};

inline LinkWave link_wave(const std::vector<uint8_t>& bytes, const LinkWaveOptions& o) {
  synth::Pwl pwl;
  double t0 = 1e-6;
  for (size_t f = 0; f < bytes.size(); ++f) {
    synth::Train tr;
    tr.t0 = t0;
    tr.pulses = synth::pulses_from_half_bits(
        isolink::frame_half_bits(bytes[f], isolink::FrameFormat{}), o.amplitude);
    if (static_cast<int>(f) == o.short_frame && o.short_pulse >= 0 &&
        o.short_pulse < static_cast<int>(tr.pulses.size()))
      tr.pulses[static_cast<size_t>(o.short_pulse)].shift = -100e-9;
    synth::append_train(pwl, tr);
    t0 = tr.end() + o.gap;
  }
  const Waveform w = synth::sample(pwl, o.dt, t0);
  LinkWave out;
  out.t = w.time;
  out.v = w.columns[0];
  if (o.realistic) {
    // Second-order low-pass (f0 30 MHz, zeta 0.45), then a first-order high-pass (3 us).
    const double w0 = 2 * std::numbers::pi * 30e6, zeta = 0.6, tau_hp = 3e-6;
    double x = 0, xd = 0, slow = 0;
    for (size_t i = 0; i < out.v.size(); ++i) {
      const double u = out.v[i];
      const double h = i ? out.t[i] - out.t[i - 1] : o.dt;
      const int sub = 8;
      for (int k = 0; k < sub; ++k) {  // semi-implicit Euler, small steps
        const double hs = h / sub;
        xd += hs * (w0 * w0 * (u - x) - 2 * zeta * w0 * xd);
        x += hs * xd;
      }
      slow += h / tau_hp * (x - slow);
      out.v[i] = x - slow;
    }
  }
  out.p.resize(out.v.size());
  out.n.resize(out.v.size());
  for (size_t i = 0; i < out.v.size(); ++i) {
    const double cm = o.cm_amplitude * std::sin(2 * std::numbers::pi * o.cm_frequency * out.t[i]);
    out.p[i] = 2.5 + out.v[i] / 2 + cm;
    out.n[i] = 2.5 - out.v[i] / 2 + cm;
  }
  return out;
}

inline eye::Rules rules(const char* name = "bq7961x") {
  StatusOr<eye::Rules> r = eye::load_rules(name);
  EXPECT_TRUE(r.ok()) << r.status().message();
  return r.ok() ? *r : eye::Rules{};
}

inline eye::CheckResult check(const LinkWave& w, const eye::Rules& r) {
  StatusOr<eye::CheckResult> c = eye::check_samples(w.t, w.v, r);
  EXPECT_TRUE(c.ok()) << c.status().message();
  return c.ok() ? *c : eye::CheckResult{};
}

// An 8-bit RGB image read back from a file.
struct Png {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> px;
  std::array<int, 3> at(int x, int y) const {
    const size_t i = (static_cast<size_t>(y) * width + x) * channels;
    return {px[i], px[i + 1], px[i + 2]};
  }
  bool is(int x, int y, uint32_t rgb) const {
    const auto c = at(x, y);
    return c[0] == static_cast<int>((rgb >> 16) & 0xFF) &&
           c[1] == static_cast<int>((rgb >> 8) & 0xFF) && c[2] == static_cast<int>(rgb & 0xFF);
  }
};

inline Png read_png(const std::string& path) {
  Png out;
  OIIO::ImageBuf in(path);
  if (!in.read(0, 0, true, OIIO::TypeDesc::UINT8)) {
    ADD_FAILURE() << "cannot read " << path << ": " << in.geterror();
    return out;
  }
  const OIIO::ImageSpec& s = in.spec();
  out.width = s.width;
  out.height = s.height;
  out.channels = s.nchannels;
  out.px.resize(static_cast<size_t>(s.width) * s.height * s.nchannels);
  in.get_pixels(OIIO::ROI(0, s.width, 0, s.height, 0, 1, 0, s.nchannels), OIIO::TypeDesc::UINT8,
                out.px.data());
  return out;
}

// A fresh directory under the test temp dir.
inline std::string temp_dir(const std::string& name) {
  const std::string d = ::testing::TempDir() + "isolink_reports_" + name;
  std::error_code ec;
  std::filesystem::remove_all(d, ec);
  std::filesystem::create_directories(d, ec);
  return d;
}

}  // namespace isolink::reports::fixtures
