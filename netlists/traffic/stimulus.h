// Stimulus scripts: a list of commands, tones, patterns and idle times -> one Drive.
//
// Usage:
//   StimulusOptions opt;                       // encoding, timing, tone defaults
//   StatusOr<Drive> d = build_drive("wake; stack-write reg=0x0100 data=02B778BC;"
//                                   " pattern prbs7 bytes=32; idle 20u; tone fault couplets=4",
//                                   opt);
//   if (!d) return d.status();                 // "item 3 (pattern prbs7 bytes=0): ..."
// Items are separated by ';' or newlines; empty items and '#' comments are skipped:
//   <command text>                     see command.h (single-read ..., raw ...)
//   tone NAME [couplets=N] [pulse=T]   or just NAME (wake, sleep-to-active, shutdown, ...)
//   pattern NAME [bytes=N]             see patterns.h (prbs7, prbs15, all256, alt, ...)
//   idle T                             extra idle before the next item
//   gap T                              the idle before the next item is T exactly (instead of
//                                      the 1 us lead / 12 us frame gap; `idle` still adds)
//   raw HEX... [nocrc] [err]           err: the bytes carry the byte-error bit (a resent byte)
//   auto-address devices=N             TI's auto-addressing commands (sequences.h)
//   responses reg=R n=B devices=D [first=A]   the response frames of a read (sequences.h)
// Times take SPICE suffixes with an optional trailing "s": 250n, 250ns, 1u, 1us, 2.5e-7, 20us.
#pragma once

#include <cstddef>
#include <string_view>

#include "base/status.h"
#include "netlists/traffic/drive.h"
#include "netlists/traffic/encoding.h"
#include "netlists/traffic/tones.h"

namespace isolink::traffic {

// The longest traffic build_drive accepts, in seconds of simulated time.
inline constexpr double kMaxDriveSeconds = 1.0;
// The most level segments build_drive builds: 1 s of back-to-back bytes at the 250 ns half bit is
// 2.6 M; tones of very short pulses would be many more in that time.
inline constexpr size_t kMaxDriveSegments = 4'000'000;

struct StimulusOptions {
  EncodingOptions encoding;  // byte frame format
  Timing timing;             // lead, gaps, tail
  ToneOptions tone;          // default couplets and pulse width for tones
};

// Seconds from "250n", "250ns", "1u", "1us", "10ms", "1meg"... (SPICE suffixes, case-insensitive).
StatusOr<double> parse_time(std::string_view text);
// Adds one script item to b (a command, tone, pattern or idle).
Status add_item(DriveBuilder& b, std::string_view item, const StimulusOptions& opt);
// Builds the drive of a whole script; errors name the item number and its text.
StatusOr<Drive> build_drive(std::string_view script, const StimulusOptions& opt = {});

}  // namespace isolink::traffic
