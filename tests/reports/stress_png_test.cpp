// stress.png (reports/stress_png.h) read back by pixel: the limit lines at +/- pin_abs_max in each
// panel's rows, each pin's trace at the row its value maps to, one panel per broken scenario (at
// most kStressPanels), and the closest scenario alone when nothing broke.
#include "reports/stress_png.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fixtures.h"

namespace isolink::reports {
namespace {

using fixtures::Png;
using fixtures::read_png;
using fixtures::temp_dir;

uint32_t hex(Color c) {
  auto ch = [](float x) { return static_cast<uint32_t>(x * 255.0f + 0.5f); };
  return ch(c.r) << 16 | ch(c.g) << 8 | ch(c.b);
}

// A scenario whose txp ramps 0 -> peak over 1 us (the others sit at 2.5 V), the disturbance
// between 0.2 and 0.4 us.
analysis::StressScenario ramp_scenario(const std::string& id, double peak, bool broken) {
  analysis::StressScenario s;
  s.id = id;
  s.kind = "esd";
  s.t_start = 0.2e-6, s.t_end = 0.4e-6;
  for (int i = 0; i <= 1000; ++i) s.pins.time.push_back(i * 1e-9);
  for (const char* name : {"rxn", "rxp", "txn", "txp"}) {
    s.pins.names.push_back(name);
    std::vector<double> col;
    for (double t : s.pins.time) col.push_back(std::string(name) == "txp" ? peak * t / 1e-6 : 2.5);
    s.pins.columns.push_back(col);
    s.pin_ground[name] = "0";
    s.peak_pin_v[name] = {std::string(name) == "txp" ? peak : 2.5,
                          std::string(name) == "txp" ? 0.0 : 2.5};
  }
  if (broken) s.first_broken = s.broken.emplace_back("the tx end's COM pin txp reached beyond");
  return s;
}

analysis::StressResult result(std::vector<analysis::StressScenario> sc) {
  analysis::StressResult r;
  r.limits = {{"pin_abs_max_V", 20, "assumed"}, {"pin_cm_limit_V", 20, "TI"}};
  r.scenarios = std::move(sc);
  for (const auto& s : r.scenarios) r.survives = r.survives && s.first_broken.empty();
  r.verdict = r.survives ? "survives" : "breaks";
  return r;
}

// Pixels of colour c within +-2 rows of row y at column x.
bool near_row(const Png& img, int x, int y, uint32_t c) {
  for (int d = -2; d <= 2; ++d)
    if (img.is(x, y + d, c)) return true;
  return false;
}

TEST(StressPng, LimitLinesAndTracesWhereTheAxesPutThem) {
  const analysis::StressResult r =
      result({ramp_scenario("ok_one", 10, false), ramp_scenario("esd_tx_p_pos", 30, true)});
  const StressPngLayout L = stress_png_layout(r);
  ASSERT_EQ(L.scenarios, std::vector<size_t>{1});  // only the broken one
  ASSERT_EQ(L.areas.size(), 1u);
  EXPECT_EQ(L.pin_limit_v, 20);
  const std::string path = temp_dir("stress_png") + "/stress.png";
  ASSERT_TRUE(write_stress_png(r, "link", path).ok());
  const Png img = read_png(path);
  ASSERT_EQ(img.width, L.width);
  ASSERT_EQ(img.height, L.height);
  const PlotArea& a = L.areas[0];
  // The y range holds the limits and the 30 V peak.
  EXPECT_LE(a.y.lo, -20);
  EXPECT_GE(a.y.hi, 30);
  // The dashed limit lines: red on at least half the columns of their rows (left of the ramp's
  // crossing, which happens at 2/3 of the width for +20 V).
  for (double v : {20.0, -20.0}) {
    int red = 0, n = 0;
    for (int x = a.rect.x0 + 5; x < a.rect.x0 + a.rect.width() / 2; ++x, ++n)
      red += img.is(x, a.row(v), hex(kStressLimit)) ? 1 : 0;
    EXPECT_GT(red, n / 2) << v;
  }
  // txp's ramp: at 0.5 us it is at 15 V, at 0.9 us at 27 V.
  for (double t : {0.5e-6, 0.9e-6})
    EXPECT_TRUE(near_row(img, a.col(t), a.row(30 * t / 1e-6), hex(stress_pin_color("txp")))) << t;
  // The pins at 2.5 V: drawn in order txp, txn, rxp, rxn, so rxn is on top.
  EXPECT_TRUE(near_row(img, a.col(0.8e-6), a.row(2.5), hex(stress_pin_color("rxn"))));
  // Nothing of the trace colours far from any trace (here: -10 V at 0.8 us).
  EXPECT_FALSE(near_row(img, a.col(0.8e-6), a.row(-10), hex(stress_pin_color("txp"))));
}

TEST(StressPng, ClosestScenarioWhenNothingBreaksAndAtMostSixPanels) {
  const analysis::StressResult calm = result(
      {ramp_scenario("a", 5, false), ramp_scenario("b", 12, false), ramp_scenario("c", 8, false)});
  EXPECT_EQ(stress_png_layout(calm).scenarios, std::vector<size_t>{1});
  std::vector<analysis::StressScenario> many;
  for (int k = 0; k < 9; ++k) many.push_back(ramp_scenario("s" + std::to_string(k), 25, true));
  const StressPngLayout L = stress_png_layout(result(std::move(many)));
  ASSERT_EQ(L.scenarios.size(), static_cast<size_t>(kStressPanels));
  for (size_t k = 1; k < L.areas.size(); ++k)
    EXPECT_GT(L.areas[k].rect.y0, L.areas[k - 1].rect.y1);  // stacked, not overlapping
  EXPECT_LE(L.areas.back().rect.y1, L.height);
}

TEST(StressPng, RefusesAScenarioWithoutPins) {
  analysis::StressResult r = result({ramp_scenario("x", 30, true)});
  r.scenarios[0].pins = Waveform{};
  const std::string path = temp_dir("stress_png_empty") + "/stress.png";
  const Status s = write_stress_png(r, "link", path);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no pin waveform"), std::string::npos);
}

}  // namespace
}  // namespace isolink::reports
