// Daisy-chain tones: runs of same-polarity couplets with 1 us pulses (docs/physics.md section 2).
//
// Usage:
//   StatusOr<Tone> t = parse_tone("wake");
//   ToneOptions opt;                                   // 8 couplets of 1 us pulses
//   std::vector<int> h = tone_half_bits(*t, opt);      // +1 -1 +1 -1 ... (16 half bits)
//   // DriveBuilder::add_tone(*t, opt) puts it on the line (drive.h)
// A + couplet is (+, -) and a - couplet is (-, +), each half 1 us. Our sources do not say which
// polarity each tone uses nor how many couplets a device sends. OUR ASSUMPTION: wake,
// sleep-to-active and heartbeat are + tones, shutdown and fault are - tones; the default run is
// 8 couplets (16 us), enough for the eye checker's tone rules while keeping simulations short.
#pragma once

#include <string_view>
#include <vector>

#include "base/status.h"

namespace isolink::traffic {

enum class Tone { kWake, kSleepToActive, kShutdown, kHeartbeat, kFault };

struct ToneOptions {
  int couplets = 8;     // couplets in the run (>= 1)
  double pulse = 1e-6;  // width of each half of a couplet, s
};

// "wake", "sleep-to-active", "shutdown", "heartbeat", "fault".
std::string_view tone_name(Tone tone);
// Case-insensitive; also accepts "sleep2active" and "stoa"; errors list the valid names.
StatusOr<Tone> parse_tone(std::string_view name);
// +1 for wake, sleep-to-active, heartbeat; -1 for shutdown, fault (our assumption).
int tone_polarity(Tone tone);
// Ok, or an error naming the bad option (couplets 1-100000, pulse > 0).
Status validate(const ToneOptions& opt);
// Half-bit signs of the run: couplets x (p, -p) with p = tone_polarity(tone).
std::vector<int> tone_half_bits(Tone tone, const ToneOptions& opt);
// couplets * 2 * pulse.
double tone_duration(const ToneOptions& opt);

}  // namespace isolink::traffic
