// The commands a check's decoded bytes carry: TI's command and response frames, parsed by
// protocol/command_frames.h from the bytes and their times, for the check's JSON and summary
// (and for any caller that holds a CheckResult, such as a comparison with a simulation).
//
// Usage:
//   StatusOr<CheckResult> r = check_waveform(w, rules);      // fills r->commands
//   std::vector<ParsedFrame> again = parse_commands(*r);     // the same list
//   nlohmann::ordered_json j = commands_json(r->commands);   // the "commands" array
//   std::string lines = commands_text(r->commands);          // a line per command
//   std::string note = commands_note(*r);   // "the waveform meets every receiver rule, but
//                                           //  command 2 has a bad CRC: ..." or ""
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include "eye/check.h"
#include "protocol/command_frames.h"

namespace isolink::eye {

// One TimedByte per FrameResult of r (decoded or not, so input index i is r.frames[i]): start =
// its preamble, end = the end crossing of its last pulse, value = its byte when it decoded.
std::vector<TimedByte> timed_bytes(const CheckResult& r);
// parse_frames over timed_bytes(r), with the record's span; nothing for tone rules.
std::vector<ParsedFrame> parse_commands(const CheckResult& r,
                                        double max_idle_s = FrameSplitOptions{}.max_idle_s);

// The array of {start_s, end_s, kind, device, register, data, read_bytes, crc, crc_expected,
// crc_ok, flags, ok, cut_by_record, at_record_start, bytes, first_frame, frame_count, text}; at
// most kMaxJsonPulses entries (the count of the rest goes to the caller's "commands_omitted").
nlohmann::ordered_json commands_json(std::span<const ParsedFrame> commands);
// Sets j's "commands" (commands_json of r.commands), "commands_omitted" (how many the array left
// out) and "commands_note" (commands_note(r), null when empty): the fields of `isolink check
// --json`, for every output that reports a check's commands (isolink compare's JSON too).
void set_commands_json(const CheckResult& r, nlohmann::ordered_json& j);
// "commands (N, M malformed):" then a line per command (the first 20), or "" when none.
std::string commands_text(std::span<const ParsedFrame> commands);
// One sentence on what a malformed command means next to the waveform's verdict, or "" when
// every command is well formed (frames the record's end cut aside): on a passing waveform it
// points at the firmware or host, not the link.
std::string commands_note(const CheckResult& r);

}  // namespace isolink::eye
