#include "netlists/traffic/tones.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <string>

namespace isolink::traffic {

std::string_view tone_name(Tone tone) {
  switch (tone) {
    case Tone::kWake:
      return "wake";
    case Tone::kSleepToActive:
      return "sleep-to-active";
    case Tone::kShutdown:
      return "shutdown";
    case Tone::kHeartbeat:
      return "heartbeat";
    case Tone::kFault:
      return "fault";
  }
  return "wake";
}

StatusOr<Tone> parse_tone(std::string_view name) {
  std::string n(name);
  for (char& ch : n) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (n == "wake") return Tone::kWake;
  if (n == "sleep-to-active" || n == "sleep2active" || n == "stoa") return Tone::kSleepToActive;
  if (n == "shutdown") return Tone::kShutdown;
  if (n == "heartbeat") return Tone::kHeartbeat;
  if (n == "fault") return Tone::kFault;
  return Status::Error(fmt::format(
      "unknown tone '{}': expected wake, sleep-to-active, shutdown, heartbeat or fault", name));
}

int tone_polarity(Tone tone) {
  return (tone == Tone::kShutdown || tone == Tone::kFault) ? -1 : +1;
}

Status validate(const ToneOptions& opt) {
  if (opt.couplets < 1 || opt.couplets > 100000) {
    return Status::Error(
        fmt::format("tone couplets={} is out of range: a tone is 1-100000 couplets", opt.couplets));
  }
  if (!(opt.pulse > 0.0) || !std::isfinite(opt.pulse)) {
    return Status::Error(
        fmt::format("tone pulse width {} s is invalid: it must be a positive time", opt.pulse));
  }
  return Status::Ok();
}

std::vector<int> tone_half_bits(Tone tone, const ToneOptions& opt) {
  const int p = tone_polarity(tone);
  std::vector<int> h;
  h.reserve(static_cast<size_t>(opt.couplets > 0 ? opt.couplets : 0) * 2);
  for (int i = 0; i < opt.couplets; ++i) {
    h.push_back(p);
    h.push_back(-p);
  }
  return h;
}

double tone_duration(const ToneOptions& opt) {
  return opt.couplets * 2 * opt.pulse;
}

}  // namespace isolink::traffic
