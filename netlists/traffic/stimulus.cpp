#include "netlists/traffic/stimulus.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "base/si_number.h"
#include "netlists/traffic/command.h"
#include "netlists/traffic/patterns.h"
#include "netlists/traffic/sequences.h"

namespace isolink::traffic {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& ch : out) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

StatusOr<long> parse_count(std::string_view what, std::string_view value, long lo, long hi) {
  std::string v(value);
  char* end = nullptr;
  const long n = v.empty() ? 0 : std::strtol(v.c_str(), &end, 10);
  if (v.empty() || end != v.c_str() + v.size()) {
    return Status::Error(fmt::format("{}={} is not a whole number", what, value));
  }
  if (n < lo || n > hi) {
    return Status::Error(
        fmt::format("{}={} is out of range: it must be {}-{}", what, value, lo, hi));
  }
  return n;
}

Status add_tone_item(DriveBuilder& b, std::string_view name,
                     const std::vector<std::string_view>& fields, const StimulusOptions& opt) {
  StatusOr<Tone> tone = parse_tone(name);
  if (!tone) return tone.status();
  ToneOptions to = opt.tone;
  for (std::string_view f : fields) {
    const size_t eq = f.find('=');
    const std::string key = lower(f.substr(0, eq));
    const std::string_view value = eq == std::string_view::npos ? "" : f.substr(eq + 1);
    if (eq != std::string_view::npos && key == "couplets") {
      StatusOr<long> n = parse_count("couplets", value, 1, 100000);
      if (!n) return n.status();
      to.couplets = static_cast<int>(*n);
    } else if (eq != std::string_view::npos && key == "pulse") {
      StatusOr<double> t = parse_time(value);
      if (!t) return t.status().with_context("pulse");
      to.pulse = *t;
    } else {
      return Status::Error(
          fmt::format("tone: unknown field '{}' (expected couplets=N, pulse=T)", f));
    }
  }
  return b.add_tone(*tone, to);
}

}  // namespace

StatusOr<double> parse_time(std::string_view text) {
  const std::string s = lower(trim(text));
  if (s.empty()) return Status::Error("empty time: expected e.g. 250n or 1us");
  std::string_view body = s;
  const bool neg = body[0] == '-';
  if (body[0] == '+' || body[0] == '-') body.remove_prefix(1);
  // The one SPICE number scanner (base/si_number.h), stopping after the scale suffix: a time
  // may end in "s" and nothing else.
  const std::optional<SiNumber> n = scan_si_number(body, {.scale = true, .unit_letters = false});
  if (!n) {
    return Status::Error(fmt::format("'{}' is not a time: expected e.g. 250n, 1us, 2.5e-7", text));
  }
  const std::string_view rest = body.substr(n->length);
  if (!rest.empty() && rest != "s") {
    const char last = body[n->length - 1];
    if ((last >= '0' && last <= '9') || last == '.') {
      return Status::Error(fmt::format(
          "'{}' has an unknown unit suffix '{}': use f p n u m k meg g t mil", text, rest));
    }
    return Status::Error(fmt::format("'{}' has trailing text after the number", text));
  }
  if (!std::isfinite(n->value)) {
    return Status::Error(fmt::format("'{}' is not a finite time", text));
  }
  return neg ? -n->value : n->value;
}

Status add_item(DriveBuilder& b, std::string_view item, const StimulusOptions& opt) {
  const std::vector<std::string_view> tok = split_ws(item);
  if (tok.empty()) return Status::Ok();
  const std::string kw = lower(tok[0]);
  const std::vector<std::string_view> rest(tok.begin() + 1, tok.end());
  if (kw == "idle") {
    if (rest.size() != 1) return Status::Error("idle: expected one time, e.g. 'idle 20us'");
    StatusOr<double> t = parse_time(rest[0]);
    if (!t) return t.status().with_context("idle");
    return b.add_idle(*t);
  }
  if (kw == "gap") {
    if (rest.size() != 1) return Status::Error("gap: expected one time, e.g. 'gap 3.8us'");
    StatusOr<double> t = parse_time(rest[0]);
    if (!t) return t.status().with_context("gap");
    return b.set_gap(*t);
  }
  if (kw == "tone") {
    if (rest.empty()) return Status::Error("tone: expected a tone name, e.g. 'tone wake'");
    return add_tone_item(b, rest[0], {rest.begin() + 1, rest.end()}, opt);
  }
  if (parse_tone(kw).ok()) return add_tone_item(b, kw, rest, opt);
  if (kw == "pattern") {
    if (rest.empty()) return Status::Error("pattern: expected a name, e.g. 'pattern prbs7'");
    StatusOr<Pattern> p = parse_pattern(rest[0]);
    if (!p) return p.status();
    size_t n = default_pattern_bytes(*p);
    for (size_t i = 1; i < rest.size(); ++i) {
      const std::string_view f = rest[i];
      const size_t eq = f.find('=');
      if (eq == std::string_view::npos || lower(f.substr(0, eq)) != "bytes") {
        return Status::Error(fmt::format("pattern: unknown field '{}' (expected bytes=N)", f));
      }
      StatusOr<long> v = parse_count("bytes", f.substr(eq + 1), 1, 1000000);
      if (!v) return v.status().with_context("pattern");
      n = static_cast<size_t>(*v);
    }
    return b.add_frame(pattern_bytes(*p, n), std::string(pattern_name(*p)));
  }
  if (kw == "auto-address") {  // sequences.h: TI's auto-addressing of a stack
    StatusOr<std::vector<std::string>> cmds = auto_address_item(rest);
    if (!cmds) return cmds.status();
    for (const std::string& c : *cmds)
      if (Status s = b.add_frame(*command_bytes(c), c); !s.ok()) return s;
    return Status::Ok();
  }
  if (kw == "responses") {  // sequences.h: the frames a stack sends back to a read
    StatusOr<std::vector<std::vector<uint8_t>>> frames = response_frames(rest);
    if (!frames) return frames.status();
    for (size_t k = 0; k < frames->size(); ++k)
      if (Status s =
              b.add_frame((*frames)[k], fmt::format("response {} of {}", k + 1, frames->size()));
          !s.ok())
        return s;
    return Status::Ok();
  }
  // `raw ... err`: the bytes go out with the byte-error bit set (as a resent byte).
  int error_bit = -1;
  std::string command(item);
  if (kw == "raw") {
    command.clear();
    for (std::string_view w : tok) {
      if (lower(w) == "err") {
        error_bit = 1;
      } else {
        command += (command.empty() ? "" : " ") + std::string(w);
      }
    }
  }
  StatusOr<std::vector<uint8_t>> bytes = command_bytes(command);
  if (!bytes) {
    if (bytes.status().message().rfind("unknown command", 0) == 0) {
      return Status::Error(
          fmt::format("unknown item '{}': expected a command (single-read ... raw), a tone (wake, "
                      "sleep-to-active, shutdown, heartbeat, fault), 'pattern NAME', "
                      "'auto-address devices=N', 'responses reg=R n=B devices=D', 'idle T' or "
                      "'gap T'",
                      tok[0]));
    }
    return bytes.status();
  }
  return b.add_frame(*bytes, std::string(trim(item)), error_bit);
}

StatusOr<Drive> build_drive(std::string_view script, const StimulusOptions& opt) {
  DriveBuilder b(opt.encoding, opt.timing);
  // Each item is refused before it is built if it would end past the limit ('pattern prbs15
  // bytes=999999' twice built 2 x 20 M segments, 1 GB and 20 s, before the check below).
  if (Status s = b.set_max_duration(kMaxDriveSeconds); !s.ok()) return s;
  if (Status s = b.set_max_segments(kMaxDriveSegments); !s.ok()) return s;
  size_t index = 0;
  size_t pos = 0;
  while (pos <= script.size()) {
    size_t next = script.find_first_of(";\n", pos);
    if (next == std::string_view::npos) next = script.size();
    std::string_view item = script.substr(pos, next - pos);
    const size_t hash = item.find('#');
    if (hash != std::string_view::npos) item = item.substr(0, hash);
    item = trim(item);
    if (!item.empty()) {
      ++index;
      Status s = add_item(b, item, opt);
      if (!s.ok()) return s.with_context(fmt::format("item {} ({})", index, item));
    }
    pos = next + 1;
  }
  if (index == 0) return Status::Error("stimulus is empty: no command, tone or pattern given");
  Drive d = b.finish();
  // Bounded before anything is simulated ('idle 1e30' asked the solver for 1e30 s of steps).
  if (!(d.duration() <= kMaxDriveSeconds))
    return Status::Error(
        fmt::format("stimulus: the traffic lasts {:g} s; the limit is {:g} s "
                    "(about 12,000 stack writes)",
                    d.duration(), kMaxDriveSeconds));
  return d;
}

}  // namespace isolink::traffic
