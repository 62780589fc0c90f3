#include "reports/run_images.h"

#include "reports/eye_png.h"
#include "reports/wave_png.h"

namespace isolink::reports {

Status render_run_images(const link::LinkSpec& spec, const LinkRun& run, const std::string& dir,
                         std::vector<std::string>* images) {
  std::vector<reports::EyePanel> eyes;
  std::vector<reports::WavePanel> waves;
  for (const DirectionRun& d : run.directions) {
    const Waveform& w = d.sim.wave;
    const eye::CheckResult* data = d.data ? &*d.data : nullptr;
    const eye::CheckResult* tones = d.tones ? &*d.tones : nullptr;
    const std::string label = d.link.description + " [" + d.link.rules + "]";
    // The eye folds the data frames on T = 250 ns; tones on their own 1 us only when no data
    // was sent.
    if (data != nullptr) eyes.push_back({label, w.time, w.columns[0], &d.rules, data});
    if (data == nullptr && tones == nullptr) continue;  // nothing was sent this way
    reports::WavePanel wp{label,        w.time,   w.columns[0], w.columns[1],
                          w.columns[2], &d.rules, data,         tones};
    if (data == nullptr) wp.rules = &d.tone_rules, wp.result = tones, wp.tones = nullptr;
    waves.push_back(wp);
    if (data == nullptr) eyes.push_back({label, w.time, w.columns[0], &d.tone_rules, tones});
  }
  const std::string source = spec.source;
  if (!eyes.empty()) {
    if (Status s =
            reports::render_eye_png(eyes, {.spec = spec.name, .source = source}, dir + "/eye.png");
        !s.ok())
      return s;
    images->push_back("eye.png");
  }
  if (waves.empty()) return Status::Ok();
  if (Status s =
          reports::render_wave_png(waves, {.spec = spec.name, .source = source}, dir + "/wave.png");
      !s.ok())
    return s;
  images->push_back("wave.png");
  return Status::Ok();
}

}  // namespace isolink::reports
