// reports_preview [DIR]: renders eye.png / wave.png for synthetic links so people can judge the
// layout: a passing two-direction link (pass_eye.png, pass_wave.png), a failing one with a 150 ns
// pulse (fail_eye.png, fail_wave.png), a single direction (one_eye.png) and a wake tone burst
// judged with the tone rules (tone_eye.png).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "fixtures.h"
#include "reports/eye_png.h"
#include "reports/wave_png.h"

using namespace isolink;
using namespace isolink::reports;

namespace {

struct Dir {
  fixtures::LinkWave w;
  eye::Rules r;
  eye::CheckResult c;
};

Dir make(const std::vector<uint8_t>& bytes, fixtures::LinkWaveOptions o, const char* rules) {
  Dir d;
  d.w = fixtures::link_wave(bytes, o);
  d.r = fixtures::rules(rules);
  d.c = fixtures::check(d.w, d.r);
  return d;
}

EyePanel eye_panel(const Dir& d, const std::string& name) {
  return {.direction = name, .time = d.w.t, .diff = d.w.v, .rules = &d.r, .result = &d.c};
}
WavePanel wave_panel(const Dir& d, const std::string& name) {
  return {.direction = name,
          .time = d.w.t,
          .diff = d.w.v,
          .p = d.w.p,
          .n = d.w.n,
          .rules = &d.r,
          .result = &d.c};
}

int report(const Status& s, const std::string& path) {
  if (!s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 1;
  }
  std::printf("wrote %s\n", path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "/tmp/reports_preview";
  std::filesystem::create_directories(dir);
  const std::vector<uint8_t> cmd{0xA0, 0x02, 0x15, 0x0B, 0xCC, 0xB3};  // stack read + CRC
  fixtures::LinkWaveOptions o{
      .dt = 0.5e-9, .amplitude = 2.3, .gap = 1.5e-6, .realistic = true, .cm_amplitude = 0.8};
  const Dir down = make(cmd, o, "bq7961x");
  fixtures::LinkWaveOptions ou = o;
  ou.amplitude = 2.6;
  const Dir up = make({0x00, 0x15, 0x80}, ou, "bq79600");
  fixtures::LinkWaveOptions of = o;
  of.short_pulse = 3;
  of.short_frame = 2;
  of.amplitude = 1.75;
  const Dir bad = make(cmd, of, "bq7961x");
  std::printf("down %s, up %s, bad %s (%zu failing)\n", down.c.pass ? "pass" : "FAIL",
              up.c.pass ? "pass" : "FAIL", bad.c.pass ? "pass" : "FAIL", bad.c.failing());

  int rc = 0;
  const std::string a = "down: bq79600 -> bq7961x", b = "up: bq7961x -> bq79600";
  const EyeReportInfo ei{.spec = "cap_2m (synthetic)", .source = "tests/reports/preview.cpp"};
  const WaveReportInfo wi{.spec = "cap_2m (synthetic)", .source = "tests/reports/preview.cpp"};
  rc |= report(render_eye_png({eye_panel(down, a), eye_panel(up, b)}, ei, dir + "/pass_eye.png"),
               dir + "/pass_eye.png");
  rc |=
      report(render_wave_png({wave_panel(down, a), wave_panel(up, b)}, wi, dir + "/pass_wave.png"),
             dir + "/pass_wave.png");
  rc |=
      report(render_eye_png({eye_panel(bad, a)}, ei, dir + "/fail_eye.png"), dir + "/fail_eye.png");
  rc |= report(render_wave_png({wave_panel(bad, a)}, wi, dir + "/fail_wave.png"),
               dir + "/fail_wave.png");
  rc |=
      report(render_eye_png({eye_panel(down, a)}, ei, dir + "/one_eye.png"), dir + "/one_eye.png");
  // A wake tone burst: 1 us pulses, judged with the tone rules.
  synth::Pwl pwl;
  synth::Train tone;
  tone.T = 1e-6;
  for (int k = 0; k < 16; ++k)
    tone.pulses.push_back({.sign = k % 2 ? -1 : +1, .vstart = 2.4, .vend = 2.0});
  synth::append_train(pwl, tone);
  const Waveform tw = synth::sample(pwl, 1e-9, tone.end() + 5e-6);
  const eye::Rules tr = fixtures::rules("tone");
  const eye::CheckResult tc = *eye::check_samples(tw.time, tw.columns[0], tr);
  rc |= report(render_eye_png({{.direction = "up: wake tone",
                                .time = tw.time,
                                .diff = tw.columns[0],
                                .rules = &tr,
                                .result = &tc}},
                              ei, dir + "/tone_eye.png"),
               dir + "/tone_eye.png");
  return rc;
}
