#include "cli/run_images.h"

#include "reports/eye_png.h"
#include "reports/wave_png.h"

namespace isolink::cli {

Status render_run_images(const link::LinkSpec& spec, const LinkRun& run, const std::string& dir,
                         std::vector<std::string>* images) {
  std::vector<reports::EyePanel> eyes;
  std::vector<reports::WavePanel> waves;
  for (const DirectionRun& d : run.directions) {
    const Waveform& w = d.sim.wave;
    const eye::CheckResult* data = d.data ? &*d.data : nullptr;
    const eye::CheckResult* tones = d.tones ? &*d.tones : nullptr;
    const std::string label = d.link.description + " [" + d.link.rules + "]";
    // The eye shows the data frames (tones only when nothing else was sent).
    if (data != nullptr)
      eyes.push_back({label, w.time, w.columns[0], &d.rules, data});
    reports::WavePanel wp{label, w.time, w.columns[0], w.columns[1], w.columns[2],
                          &d.rules, data, tones};
    if (data == nullptr && tones != nullptr) wp.result = tones, wp.tones = nullptr;
    waves.push_back(wp);
  }
  const std::string source = spec.source;
  if (!eyes.empty()) {
    if (Status s = reports::render_eye_png(eyes, {.spec = spec.name, .source = source},
                                           dir + "/eye.png");
        !s.ok())
      return s;
    images->push_back("eye.png");
  }
  if (Status s = reports::render_wave_png(waves, {.spec = spec.name, .source = source},
                                          dir + "/wave.png");
      !s.ok())
    return s;
  images->push_back("wave.png");
  return Status::Ok();
}

}  // namespace isolink::cli
