#include "eye/verdict.h"

#include <fmt/format.h>

#include <algorithm>

namespace isolink::eye {

std::optional<ChainRun> daisy_chain_run(std::span<const PulseMetrics> pulses, const Rules& rules) {
  const double T = rules.pulse_time;
  std::optional<ChainRun> best;
  ChainRun cur;
  auto close = [&] {
    if (cur.pulses >= kChainRunPulses && cur.singles >= kChainRunSingles &&
        (!best || cur.pulses > best->pulses))
      best = cur;
    cur = ChainRun{};
  };
  for (size_t i = 0; i < pulses.size(); ++i) {
    const PulseMetrics& p = pulses[i];
    const double w = p.width.value;
    // followed by the opposite pulse of its run: a width from a to a' was measured
    const bool timed = !p.idle && !p.truncated && p.width.measured() && w >= kChainWidthMin * T &&
                       w <= kChainWidthMax * T;
    const bool joined =
        cur.pulses > 0 && i == cur.first + cur.pulses && pulses[i - 1].sign == -p.sign;
    if (!timed) {
      close();
      continue;
    }
    if (!joined) {
      close();
      cur.first = i;
      cur.width_min = cur.width_max = w;
    }
    ++cur.pulses;
    cur.singles += w < kChainSingleMax * T ? 1 : 0;
    cur.failing += p.failing() ? 1 : 0;
    cur.width_min = std::min(cur.width_min, w);
    cur.width_max = std::max(cur.width_max, w);
  }
  close();
  return best;
}

const char* verdict_name(VerdictKind k) {
  switch (k) {
    case VerdictKind::kPass:
      return "pass";
    case VerdictKind::kFail:
      return "fail";
    case VerdictKind::kInconclusive:
      break;
  }
  return "inconclusive";
}

Verdict decide_verdict(std::span<const PulseMetrics> pulses, const Rules& rules,
                       const VerdictFacts& facts) {
  Verdict v;
  const size_t failing = static_cast<size_t>(std::count_if(
      pulses.begin(), pulses.end(), [](const PulseMetrics& p) { return p.failing(); }));
  std::vector<std::string> open;  // why the record shows nothing of the link
  if (facts.peak > kImplausibleVth * rules.vth)
    open.push_back(fmt::format("levels up to {:.4g} V: no daisy-chain signal as read", facts.peak));
  if (pulses.empty())
    open.push_back(
        fmt::format("no pulses: nothing stays past +/-{:g} V for {:g} ns (largest |v| {:.4g} V)",
                    rules.vth, rules.min_pulse * 1e9, facts.peak));
  std::string chain_fail;
  if (!pulses.empty() && !facts.decodes) {
    const std::optional<ChainRun> run = daisy_chain_run(pulses, rules);
    const std::string head = fmt::format(
        "no frame decodes: {} pulses in {} runs, none forms a byte", pulses.size(), facts.runs);
    if (!run) {
      open.push_back(fmt::format(
          "{}, and no {} pulses in a row have the daisy-chain's timing (alternating, widths "
          "{:g}-{:g} ns, {} of one half bit): the record does not show the link",
          head, kChainRunPulses, kChainWidthMin * rules.pulse_time * 1e9,
          kChainWidthMax * rules.pulse_time * 1e9, kChainRunSingles));
    } else {
      const std::string where = fmt::format(
          "pulses {}..{} ({} in a row, widths {:.0f}-{:.0f} ns) have the daisy-chain's timing",
          run->first, run->first + run->pulses - 1, run->pulses, run->width_min * 1e9,
          run->width_max * 1e9);
      if (failing > 0)
        chain_fail = fmt::format("{}, but {} and {} of {} pulses fail their rules: a failed link",
                                 head, where, failing, pulses.size());
      else
        open.push_back(fmt::format(
            "{}; {} and meet the rules: P and N swapped, or other decoding options (--no-sof, "
            "--msb-first)?",
            head, where));
    }
  }
  // A record that shows nothing of the link is inconclusive whatever its pulses measure.
  const bool nothing = pulses.empty() || facts.peak > kImplausibleVth * rules.vth ||
                       (!facts.decodes && chain_fail.empty());
  v.reasons = facts.failures;
  if (!chain_fail.empty()) v.reasons.push_back(chain_fail);
  const bool failed = !v.reasons.empty() && !nothing;
  v.reasons.insert(v.reasons.end(), open.begin(), open.end());
  v.reasons.insert(v.reasons.end(), facts.open.begin(), facts.open.end());
  v.kind = failed              ? VerdictKind::kFail
           : v.reasons.empty() ? VerdictKind::kPass
                               : VerdictKind::kInconclusive;
  return v;
}

}  // namespace isolink::eye
