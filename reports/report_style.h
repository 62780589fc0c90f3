// Pieces eye.png and wave.png share: title and panel headers with a coloured verdict, the symmetric
// voltage range, number formats. Internal to reports/ (header only).
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "eye/check.h"
#include "eye/rules.h"
#include "reports/plot.h"

namespace isolink::reports::style {

inline constexpr int kTitleHeight = 96;  // the title block at the top of an image
inline constexpr int kTitleSize = 34;
inline constexpr int kHeaderSize = 26;
inline constexpr int kLabelSize = 18;  // tick labels, notes, legends (>= 18 px for slides)
inline constexpr int kAxisTitleSize = 20;
inline constexpr Color kWarn = rgb(0xB35C00);  // warnings (droop over its limit): dark orange

inline std::string verdict(bool pass) {
  return pass ? "PASS" : "FAIL";
}
inline Color verdict_color(bool pass) {
  return pass ? kPass : kFail;
}

// Largest |v| over the samples (0 when none).
inline double max_abs(std::span<const double> v) {
  double m = 0;
  for (double x : v)
    if (std::isfinite(x)) m = std::max(m, std::abs(x));
  return m;
}
// A symmetric range that holds max_abs with a little room: at least 2.5 V, in 0.5 V steps.
inline double symmetric_range(double max_abs_v) {
  return std::max(2.5, std::ceil(max_abs_v * 1.08 / 0.5) * 0.5);
}

// "Eye diagram  cap_2m  PASS" in the title block, the source below it.
inline void draw_title(Canvas& c, const std::string& what, const std::string& spec,
                       const std::string& source, bool pass) {
  std::vector<TextRun> runs{{what, kInk, FontFace::kBold}};
  if (!spec.empty()) runs.push_back({"   " + spec, kInk, FontFace::kSans});
  runs.push_back({"   " + verdict(pass), verdict_color(pass), FontFace::kBold});
  draw_runs(c, 28, 16, runs, kTitleSize, VAlign::kTop);
  if (!source.empty())
    c.text(30, 64, source, kLabelSize, kMuted, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
  c.fill_rect({0, kTitleHeight - 2, c.width(), kTitleHeight}, rgb(0xBBBBBB));
}

// Panel header: direction, rule set and verdict; below it the rules' description, or on a failure
// the reasons (cut to one line).
inline void draw_panel_header(Canvas& c, const Rect& panel, const std::string& direction,
                              const eye::Rules& rules, const eye::CheckResult& r) {
  std::vector<TextRun> runs;
  if (!direction.empty()) runs.push_back({direction, kInk, FontFace::kBold});
  runs.push_back({(direction.empty() ? "" : "   ") + std::string("rules ") + rules.name, kInk,
                  FontFace::kSans});
  runs.push_back({"   " + verdict(r.pass), verdict_color(r.pass), FontFace::kBold});
  const size_t nf = r.failing();
  if (nf > 0)
    runs.push_back(
        {fmt::format("   {} failing pulse{}", nf, nf == 1 ? "" : "s"), kFail, FontFace::kSans});
  draw_runs(c, 28, panel.y0 + 14, runs, kHeaderSize, VAlign::kTop);
  std::string line2 = rules.description;
  Color col = kMuted;
  if (!r.pass && !r.reasons.empty()) {
    line2.clear();
    for (const std::string& why : r.reasons) line2 += (line2.empty() ? "" : "; ") + why;
    col = kFail;
  }
  // Keep it on one line. Cut first to what could fit (no glyph is narrower than 3 px at this
  // size): measuring the whole text once per character dropped was quadratic in its length, and
  // a long record's reasons run to megabytes (minutes in FreeType on 2,000 frames).
  const int max_w = c.width() - 60;
  std::string shown = ascii_text(line2);
  if (const size_t most = static_cast<size_t>(std::max(max_w, 0)) / 3 + 4; shown.size() > most)
    shown = shown.substr(0, most - 3) + "...";
  while (shown.size() > 4 && c.measure(shown, kLabelSize).width > max_w)
    shown = shown.substr(0, shown.size() - 4) + "...";
  c.text(30, panel.y0 + 52, shown, kLabelSize, col, FontFace::kSans, HAlign::kLeft, VAlign::kTop);
}

// "5.431 us" style time with a fixed unit.
inline std::string time_us(double t) {
  return fmt::format("{:.3f} us", t * 1e6);
}

// Drops whole labels that would overlap the one placed before (x ranges), for long records.
struct LabelRow {
  double last_right = -1e18;
  std::vector<std::pair<double, double>> reserved;  // column spans no label may touch
  bool fits(double left, double right, double gap = 6) {
    if (left < last_right + gap) return false;
    for (const auto& [x0, x1] : reserved)
      if (left < x1 + gap && right > x0 - gap) return false;
    last_right = right;
    return true;
  }
};

}  // namespace isolink::reports::style
