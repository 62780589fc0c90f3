// Drive: what the transmitter puts on the line, as level segments the solver turns into voltages.
//
// Usage:
//   DriveBuilder b;                                     // default encoding and Timing
//   Status s = b.add_tone(Tone::kWake);                 // 8 couplets of 1 us pulses
//   s = b.add_frame(*command_bytes("stack-write reg=0x0100 data=02B778BC"));
//   s = b.add_frame(pattern_bytes(Pattern::kPrbs7, 16), "prbs7");
//   Drive d = b.finish();
//   for (const DriveSegment& g : d.segments) { /* [g.start, g.end) at g.level */ }
//   std::vector<double> bp = d.corners();               // solver breakpoints
//   StatusOr<std::string> pwl = pwl_sources(d);         // "VTXP txp 0 PWL(...)\nVTXN ..."
// Levels: +1 = P at VDD (5 V), N at 0 V; -1 = the reverse; 0 = idle, both at VDD / 2 (2.5 V).
// Segments are contiguous from t = 0 to duration() and merged: neighbours never share a level,
// so touching same-sign half bits (a "double bit") are one segment of twice the length.
//
// Timing defaults (our choice, see netlists/traffic/README.md):
//   lead 1 us idle before the first item, so the solver starts from the idle operating point;
//   byte_gap 3.8 us idle between the byte frames of one command: a byte every 10.3 us, the
//     UART byte time at 1 Mbps (docs/physics.md section 7) that the bridge re-sends at, 10.3 - 6.5
//     us;
//   frame_gap 12 us idle between commands / tones / patterns: the bridge's 12 us byte delay,
//     and longer than tblank (4 us), so the idle check after every command sees a quiet line;
//   tail 5 us idle after the last item: covers tblank (4 us) for the undershoot check.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "base/status.h"
#include "netlists/traffic/encoding.h"
#include "netlists/traffic/tones.h"

namespace isolink::traffic {

struct DriveSegment {
  double start;  // s
  double end;    // s, > start
  int level;     // +1, -1 or 0 (idle)
};

// A non-idle segment seen as a pulse.
struct Pulse {
  double start;  // s
  double width;  // s
  int sign;      // +1 or -1
};

enum class FrameKind { kData, kTone };

// One item sent: a command / pattern (bytes) or a tone.
struct DriveFrame {
  FrameKind kind = FrameKind::kData;
  std::string label;                // the command text, pattern or tone name
  double start = 0;                 // s, first pulse edge
  double end = 0;                   // s, end of the last pulse
  std::vector<uint8_t> bytes;       // data: bytes sent, in order (empty for tones)
  std::vector<double> byte_starts;  // data: start of each byte frame (its preamble), s
  Tone tone = Tone::kWake;          // tones only
  int couplets = 0;                 // tones only
};

struct Drive {
  std::vector<DriveSegment> segments;  // contiguous from 0, merged
  std::vector<DriveFrame> frames;      // in time order
  EncodingOptions encoding;            // how the data frames were encoded

  // End of the last segment (0 when empty).
  double duration() const;
  // Times where the level changes (the interior segment boundaries), increasing.
  std::vector<double> corners() const;
  // Level at t (a segment owns its start); 0 outside [0, duration()).
  int level_at(double t) const;
  // The non-idle segments as pulses.
  std::vector<Pulse> pulses() const;
};

struct Timing {
  double lead = 1e-6;        // idle before the first item, s
  double byte_gap = 3.8e-6;  // idle between byte frames of one item, s
  double frame_gap = 12e-6;  // idle between items, s
  double tail = 5e-6;        // idle after the last item, s
};

// Ok, or an error naming the bad field (all >= 0 and finite).
Status validate(const Timing& t);

class DriveBuilder {
 public:
  explicit DriveBuilder(EncodingOptions encoding = {}, Timing timing = {});
  // Sends bytes as one frame (a command or pattern), byte frames byte_gap apart. error_bit 0 or 1
  // overrides the encoding's byte-error bit for these bytes (1: a resent byte); -1 keeps it.
  Status add_frame(const std::vector<uint8_t>& bytes, std::string label = "", int error_bit = -1);
  // Sends a tone run.
  Status add_tone(Tone tone, const ToneOptions& opt = {});
  // Extra idle time (added to the automatic lead / frame_gap before the next item).
  Status add_idle(double seconds);
  // The idle time before the next item is `seconds` exactly instead of the automatic lead /
  // frame_gap (any add_idle still adds to it): traffic with given gaps (a worst case's replay).
  Status set_gap(double seconds);
  // Refuses, before building it, any item that would end after `seconds` of traffic (the error
  // names both times): a script's memory stays bounded however many bytes or couplets it asks
  // for. The default is no limit.
  Status set_max_duration(double seconds);
  // The same for the number of level segments (tones of very short pulses are many segments in
  // little time). The default is no limit.
  Status set_max_segments(size_t count);
  // Adds the tail and returns the drive; the builder is left empty.
  Drive finish();

 private:
  // The idle before the next item (the automatic lead / frame_gap or set_gap's, plus add_idle's).
  double next_idle() const;
  // Ok, or the error for an item of `length` seconds and at most `segments` segments that would
  // end past max_duration_ or max_segments_.
  Status check_room(double length, double segments) const;
  // The idle before an item (callers have validated timing_ and checked the room).
  void begin_item();
  void push(double start, double end, int level);

  EncodingOptions enc_;
  Timing timing_;
  Drive drive_;
  double t_ = 0;  // end of what is built so far
  double pending_idle_ = 0;
  double gap_ = -1;  // set_gap's value for the next item, -1 = automatic
  bool any_item_ = false;
  double max_duration_ = HUGE_VAL;
  double max_segments_ = HUGE_VAL;
};

// Line voltages for a level: P = vdd/2 * (1 + level), N = vdd/2 * (1 - level).
double p_volts(int level, double vdd = 5.0);
double n_volts(int level, double vdd = 5.0);

struct PwlOptions {
  double edge = 10e-9;  // full transition time, centred on each corner, s
  double vdd = 5.0;     // driver supply (CVDD), V
  std::string p_source = "VTXP";
  std::string p_node = "txp";
  std::string n_source = "VTXN";
  std::string n_node = "txn";
  int points_per_line = 8;  // time/value pairs per line before a "+ " continuation
};

// One line's voltage as flat PWL points t0 v0 t1 v1 ... (line_sign +1: P, -1: N). Each level
// change ramps linearly over [corner - edge/2, corner + edge/2]; times strictly increase. Errors
// when edge <= 0 or edge is not shorter than the shortest segment.
StatusOr<std::vector<double>> line_pwl(const Drive& d, int line_sign, double edge,
                                       double vdd = 5.0);

// Two ngspice sources "VTXP txp 0 PWL(t v ...)" and "VTXN txn 0 PWL(...)", each ending in "\n".
// Each level change ramps linearly over [corner - edge/2, corner + edge/2]; times strictly
// increase. Errors when edge <= 0 or edge is not shorter than the shortest segment.
StatusOr<std::string> pwl_sources(const Drive& d, const PwlOptions& opt = {});

}  // namespace isolink::traffic
