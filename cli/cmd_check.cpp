// isolink check WAVE [N]: score a waveform (simulated or a scope capture) against a rule
// set. The work is in eye/check.h and eye/waveform_csv.h; this file maps flags and prints.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "base/hex.h"
#include "cli/capture_options.h"
#include "cli/commands.h"
#include "eye/check.h"
#include "eye/rules.h"
#include "eye/waveform_csv.h"
#include "netlists/traffic/stimulus.h"
#include "protocol/frame.h"

namespace isolink::cli {
namespace {

struct CheckArgs {
  std::vector<std::string> files;
  std::string rules = "bq7961x";
  eye::CsvColumns cols;
  bool json = false;
  std::string pulses_csv;
  std::string expect;
  std::optional<bool> sof;
  std::optional<int> sof_value;
  bool msb_first = false;
  bool lsb_first = false;
  std::string command_idle;
};

int fail_input(const std::string& message) {
  std::fprintf(stderr, "isolink check: %s\n", message.c_str());
  return 2;
}

int run_check(const CheckArgs& a) {
  StatusOr<eye::Rules> rules = eye::load_rules(a.rules);
  if (!rules) return fail_input(rules.status().message());
  eye::CheckOptions opt;
  if (a.sof) opt.sof = *a.sof;
  if (a.sof_value) opt.sof_value = *a.sof_value;
  if (a.msb_first) opt.bit_order = BitOrder::kMsbFirst;
  if (a.lsb_first) opt.bit_order = BitOrder::kLsbFirst;
  if (!a.command_idle.empty()) {
    StatusOr<double> t = traffic::parse_time(a.command_idle);
    if (!t) return fail_input("--command-idle: error: " + t.status().message());
    if (*t < 0) return fail_input("--command-idle: error: " + a.command_idle + " is negative");
    opt.command_idle = *t;
  }
  if (!a.expect.empty()) {
    StatusOr<std::vector<uint8_t>> e = parse_hex_bytes(a.expect);
    if (!e) return fail_input("--expect: error: " + e.status().message());
    opt.expect = *e;
  }
  eye::CaptureInfo info;
  StatusOr<Waveform> w = eye::read_capture(a.files, a.cols, &info);
  if (!w) return fail_input(w.status().message());
  StatusOr<eye::CheckResult> r = eye::check_waveform(*w, *rules, opt);
  if (!r) return fail_input(a.files[0] + ": error: " + r.status().message());
  if (!a.pulses_csv.empty())
    if (Status s = eye::write_pulses_csv(*r, a.pulses_csv); !s.ok()) return fail_input(s.message());
  if (a.json) {
    nlohmann::ordered_json j = eye::to_json(*r);
    j["input"] = eye::capture_json(info);
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::string source = a.files[0];
    if (a.files.size() > 1) source += " - " + a.files[1];
    std::fputs(eye::summary_text(*r, source).c_str(), stdout);
    std::fputs(eye::capture_text(info).c_str(), stdout);
  }
  return r->pass ? 0 : 1;
}

}  // namespace

void add_check_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<CheckArgs>();
  auto* cmd = app.add_subcommand(
      "check",
      "Score a waveform CSV or scope export against the receiver rules (exit 0 pass, 1 fail or "
      "inconclusive, 2 bad input)");
  cmd->add_option("wave", args->files,
                  "WAVE: a CSV with time and a differential (or P and N) column, or a scope file "
                  "(Tektronix .isf/.wfm, Keysight/Rigol .bin, LeCroy .trc, Rigol DS1000E/D .wfm); "
                  "or P N: P from the first file, N from the second")
      ->required()
      ->expected(1, 2);
  cmd->add_option("--rules", args->rules,
                  "a shipped rule set (bq7961x, bq79600, tone) or a YAML rule file")
      ->capture_default_str();
  add_capture_column_options(*cmd, args->cols);
  cmd->add_flag("--json", args->json, "print one JSON object instead of the summary");
  cmd->add_option("--pulses-csv", args->pulses_csv, "write the per-pulse table to this CSV file");
  cmd->add_option("--expect", args->expect,
                  "bytes expected, e.g. \"80 00 02 15 0B CB 49\": fails on a mismatch");
  cmd->add_option("--command-idle", args->command_idle,
                  "an idle longer than this between two bytes ends a command frame (default "
                  "8us; the bytes of one command come 3.8 us apart)");
  cmd->add_flag_function(
      "--sof,!--no-sof", [args](int64_t count) { args->sof = count > 0; },
      "frames carry (or lack) a start-of-frame bit after the sync pair (default: the rules')");
  cmd->add_option_function<int>(
         "--sof-value", [args](const int& v) { args->sof_value = v; }, "the SOF bit's value")
      ->check(CLI::Range(0, 1));
  auto* msb = cmd->add_flag("--msb-first", args->msb_first, "data bits most significant first");
  auto* lsb = cmd->add_flag("--lsb-first", args->lsb_first, "data bits least significant first");
  msb->excludes(lsb);
  cmd->callback([args, exit_code] { *exit_code = run_check(*args); });
}

}  // namespace isolink::cli
