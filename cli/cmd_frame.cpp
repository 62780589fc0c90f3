// isolink frame: command bytes with CRC, the bit string and the pulse train (or JSON / PWL).
// All protocol logic lives in netlists/traffic; this file maps flags and prints.
#include <fmt/format.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "base/hex.h"
#include "cli/commands.h"
#include "netlists/traffic/command.h"
#include "netlists/traffic/drive.h"
#include "netlists/traffic/encoding.h"
#include "netlists/traffic/patterns.h"
#include "netlists/traffic/stimulus.h"
#include "netlists/traffic/tones.h"

namespace isolink::cli {
namespace {

namespace tr = isolink::traffic;

struct FrameArgs {
  std::vector<std::string> items;
  std::string tone;
  int couplets = tr::ToneOptions{}.couplets;
  std::string tone_pulse = "1u";
  std::string pattern;
  long bytes = 0;
  bool json = false;
  bool pwl = false;
  std::string edge = "10n";
  std::string pulse_width = "250n";
  bool no_sof = false;
  int sof = 1;
  bool msb_first = false;
  int error_bit = 0;
  std::string lead = "1u";
  std::string byte_gap = "3.8u";
  std::string frame_gap = "12u";
  std::string tail = "5u";
};

// Times are checked up front: widths and edges must be positive, idle times not negative.
Status set_time(const std::string& flag, const std::string& text, double* out) {
  StatusOr<double> t = tr::parse_time(text);
  if (!t) return t.status().with_context(flag);
  const bool idle =
      flag == "--lead" || flag == "--byte-gap" || flag == "--frame-gap" || flag == "--tail";
  if (idle ? *t < 0 : *t <= 0)
    return Status::Error(fmt::format("{} {}: must be {} time", flag, text,
                                     idle ? "a zero or positive" : "a positive"));
  *out = *t;
  return Status::Ok();
}

StatusOr<std::string> script_of(const FrameArgs& a) {
  std::string script;
  auto add = [&script](const std::string& item) {
    if (!script.empty()) script += ';';
    script += item;
  };
  if (!a.tone.empty()) add("tone " + a.tone);
  for (const std::string& it : a.items) add(it);
  if (!a.pattern.empty()) {
    add("pattern " + a.pattern + (a.bytes > 0 ? fmt::format(" bytes={}", a.bytes) : ""));
  } else if (a.bytes > 0) {
    return Status::Error("--bytes needs --pattern");
  }
  if (script.empty()) {
    return Status::Error(
        "nothing to send: give a command (e.g. \"stack-write reg=0x0100 data=02B778BC\"), "
        "--tone NAME or --pattern NAME");
  }
  return script;
}

std::string sign_char(int s) {
  return s > 0 ? "+" : "-";
}

void print_text(const tr::Drive& d) {
  for (const tr::DriveFrame& f : d.frames) {
    if (f.kind == tr::FrameKind::kData) {
      std::printf("%s\n", to_hex(f.bytes).c_str());
    } else {
      const int p = tr::tone_polarity(f.tone);
      std::printf("tone %s: %d couplets (%s%s), %g us pulses\n", f.label.c_str(), f.couplets,
                  sign_char(p).c_str(), sign_char(-p).c_str(),
                  f.couplets > 0 ? (f.end - f.start) / (2.0 * f.couplets) * 1e6 : 0.0);
    }
  }
  bool any_bytes = false;
  for (const tr::DriveFrame& f : d.frames) any_bytes = any_bytes || !f.bytes.empty();
  if (any_bytes) {
    std::printf("bits (preamble sync %sdata error postamble; 0 = -+, 1 = +-):\n",
                d.encoding.sof ? "SOF " : "");
    for (const tr::DriveFrame& f : d.frames) {
      for (uint8_t b : f.bytes) {
        std::printf("  %02X  %s\n", b, tr::byte_bit_string(b, d.encoding).c_str());
      }
    }
  }
  const std::vector<tr::Pulse> pulses = d.pulses();
  std::printf("pulses: %zu (start us, width ns, sign); line idle outside them, %g us in all\n",
              pulses.size(), d.duration() * 1e6);
  for (const tr::Pulse& p : pulses) {
    std::printf("  %10.4f  %6.1f  %s\n", p.start * 1e6, p.width * 1e9, sign_char(p.sign).c_str());
  }
}

void print_json(const tr::Drive& d) {
  nlohmann::json j;
  nlohmann::json bytes = nlohmann::json::array();
  nlohmann::json bits = nlohmann::json::array();
  nlohmann::json frames = nlohmann::json::array();
  for (const tr::DriveFrame& f : d.frames) {
    nlohmann::json jf;
    jf["kind"] = f.kind == tr::FrameKind::kData ? "data" : "tone";
    jf["label"] = f.label;
    jf["start"] = f.start;
    jf["end"] = f.end;
    if (f.kind == tr::FrameKind::kData) {
      jf["bytes"] = f.bytes;
      jf["hex"] = to_hex(f.bytes);
      jf["byte_starts"] = f.byte_starts;
      nlohmann::json fb = nlohmann::json::array();
      for (uint8_t b : f.bytes) {
        bytes.push_back(b);
        bits.push_back(tr::byte_bit_string(b, d.encoding));
        fb.push_back(tr::byte_bit_string(b, d.encoding));
      }
      jf["bits"] = fb;
    } else {
      jf["tone"] = std::string(tr::tone_name(f.tone));
      jf["couplets"] = f.couplets;
      jf["polarity"] = tr::tone_polarity(f.tone);
    }
    frames.push_back(jf);
  }
  nlohmann::json pulses = nlohmann::json::array();
  for (const tr::Pulse& p : d.pulses()) {
    pulses.push_back({{"start", p.start}, {"width", p.width}, {"sign", p.sign}});
  }
  j["bytes"] = bytes;
  j["hex"] = to_hex(bytes.get<std::vector<uint8_t>>());
  j["bits"] = bits;
  j["pulses"] = pulses;
  j["frames"] = frames;
  j["duration"] = d.duration();
  j["encoding"] = {{"half_bit", d.encoding.half_bit},
                   {"sof", d.encoding.sof},
                   {"sof_value", d.encoding.sof_value},
                   {"bit_order", d.encoding.bit_order == BitOrder::kLsbFirst ? "lsb" : "msb"},
                   {"error_bit", d.encoding.error_bit}};
  std::printf("%s\n", j.dump(2).c_str());
}

int run_frame(const FrameArgs& a) {
  tr::StimulusOptions opt;
  opt.encoding.sof = !a.no_sof;
  opt.encoding.sof_value = a.sof;
  opt.encoding.bit_order = a.msb_first ? BitOrder::kMsbFirst : BitOrder::kLsbFirst;
  opt.encoding.error_bit = a.error_bit;
  opt.tone.couplets = a.couplets;
  tr::PwlOptions pwl;
  const std::pair<std::string, std::pair<const std::string*, double*>> times[] = {
      {"--pulse-width", {&a.pulse_width, &opt.encoding.half_bit}},
      {"--tone-pulse", {&a.tone_pulse, &opt.tone.pulse}},
      {"--lead", {&a.lead, &opt.timing.lead}},
      {"--byte-gap", {&a.byte_gap, &opt.timing.byte_gap}},
      {"--frame-gap", {&a.frame_gap, &opt.timing.frame_gap}},
      {"--tail", {&a.tail, &opt.timing.tail}},
      {"--edge", {&a.edge, &pwl.edge}},
  };
  Status s;
  for (const auto& [flag, io] : times) {
    if (s = set_time(flag, *io.first, io.second); !s.ok()) break;
  }
  StatusOr<std::string> script = s.ok() ? script_of(a) : StatusOr<std::string>(s);
  if (!script) {
    std::fprintf(stderr, "isolink frame: %s\n", script.status().message().c_str());
    return 2;
  }
  StatusOr<tr::Drive> d = tr::build_drive(*script, opt);
  if (!d) {
    std::fprintf(stderr, "isolink frame: %s\n", d.status().message().c_str());
    return 2;
  }
  if (a.pwl) {
    StatusOr<std::string> text = tr::pwl_sources(*d, pwl);
    if (!text) {
      std::fprintf(stderr, "isolink frame: %s\n", text.status().message().c_str());
      return 2;
    }
    for (const tr::DriveFrame& f : d->frames) {
      std::printf("* %s\n", f.kind == tr::FrameKind::kData ? to_hex(f.bytes).c_str()
                                                           : ("tone " + f.label).c_str());
    }
    std::fputs(text->c_str(), stdout);
  } else if (a.json) {
    print_json(*d);
  } else {
    print_text(*d);
  }
  return 0;
}

}  // namespace

void add_frame_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<FrameArgs>();
  auto* cmd = app.add_subcommand("frame",
                                 "Command bytes with CRC and the daisy-chain pulse train, e.g. "
                                 "isolink frame \"stack-write reg=0x0100 data=02B778BC\"");
  cmd->add_option("command", args->items,
                  "Command text (single-read dev= reg= n=, single-write dev= reg= data=, "
                  "stack-read/-write, broadcast-read/-write/-write-reverse, raw HEX.. [nocrc]); "
                  "several commands or ';'-separated items are sent in order");
  cmd->add_option("--tone", args->tone,
                  "Send a tone first: wake, sleep-to-active, shutdown, heartbeat, fault");
  cmd->add_option("--couplets", args->couplets, "Couplets per tone (default 8)");
  cmd->add_option("--tone-pulse", args->tone_pulse, "Tone pulse width (default 1u)");
  cmd->add_option("--pattern", args->pattern,
                  "Send a pattern last: prbs7, prbs9, prbs15, all256, alt, zeros, ones, runs, "
                  "doubles");
  cmd->add_option("--bytes", args->bytes, "Pattern length in bytes (default per pattern)")
      ->check(CLI::Range(1L, 1000000L));
  auto* json = cmd->add_flag("--json", args->json, "JSON: bytes, bits, pulses (seconds), frames");
  auto* pwl = cmd->add_flag("--pwl", args->pwl, "Two ngspice PWL sources VTXP txp / VTXN txn");
  json->excludes(pwl);
  cmd->add_option("--edge", args->edge,
                  "PWL edge (transition) time, centred on each corner "
                  "(default 10n)");
  cmd->add_option("--pulse-width", args->pulse_width, "Data pulse (half-bit) width (default 250n)");
  cmd->add_flag("--no-sof", args->no_sof, "Send no start-of-frame bit (12 bit times per byte)");
  cmd->add_option("--sof", args->sof, "SOF bit value (default 1)")->check(CLI::Range(0, 1));
  cmd->add_flag("--msb-first", args->msb_first, "Data bits most significant first");
  cmd->add_option("--error-bit", args->error_bit, "Byte-error bit value (default 0)")
      ->check(CLI::Range(0, 1));
  cmd->add_option("--lead", args->lead, "Idle before the first item (default 1u)");
  cmd->add_option("--byte-gap", args->byte_gap,
                  "Idle between bytes of a command (default 3.8u: a byte every 10.3 us)");
  cmd->add_option("--frame-gap", args->frame_gap, "Idle between items (default 12u)");
  cmd->add_option("--tail", args->tail, "Idle after the last item (default 5u)");
  cmd->callback([args, exit_code] { *exit_code = run_frame(*args); });
}

}  // namespace isolink::cli
