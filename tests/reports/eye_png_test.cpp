#include "reports/eye_png.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <vector>

#include "fixtures.h"

namespace isolink::reports {
namespace {

using fixtures::check;
using fixtures::link_wave;
using fixtures::LinkWave;
using fixtures::Png;
using fixtures::read_png;
using fixtures::rules;
using fixtures::temp_dir;

constexpr uint32_t kThresholdRgb = 0xD4008F;
constexpr uint32_t kLevelRgb = 0x333333;

// Columns of the plot where rows row-1..row+1 hold colour rgb.
int columns_with(const Png& img, const PlotArea& a, int row, uint32_t rgb) {
  int n = 0;
  for (int x = a.rect.x0; x < a.rect.x1; ++x) {
    bool hit = false;
    for (int y = row - 1; y <= row + 1; ++y) hit = hit || img.is(x, y, rgb);
    n += hit ? 1 : 0;
  }
  return n;
}

int count_if(const Png& img, const Rect& r, auto pred) {
  int n = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) n += pred(img.at(x, y)) ? 1 : 0;
  return n;
}

bool is_kfail(const std::array<int, 3>& c) {
  return c[0] == 0xE0 && c[1] == 0 && c[2] == 0;
}

struct Direction {
  LinkWave w;
  eye::Rules r;
  eye::CheckResult c;
  EyePanel panel(const std::string& name) const {
    return {.direction = name, .time = w.t, .diff = w.v, .rules = &r, .result = &c};
  }
};

Direction direction(const std::vector<uint8_t>& bytes, const fixtures::LinkWaveOptions& o,
                    const char* rule_set = "bq7961x") {
  Direction d;
  d.w = link_wave(bytes, o);
  d.r = rules(rule_set);
  d.c = check(d.w, d.r);
  return d;
}

TEST(EyePng, PassingEyeWithThresholdsWhereTheAxisPutsThem) {
  const Direction d = direction({0x80, 0x02, 0x15}, {});
  ASSERT_TRUE(d.c.pass);
  const std::vector<EyePanel> panels{d.panel("down: bq79600 -> bq7961x")};
  const EyeReportInfo info{.spec = "synthetic", .source = "tests/reports"};
  const std::string path = temp_dir("eye_pass") + "/eye.png";
  Status s = render_eye_png(panels, info, path);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp.png"));
  const Png img = read_png(path);
  const EyeLayout L = eye_layout(panels, info);
  ASSERT_EQ(img.width, L.width);
  ASSERT_EQ(img.height, L.height);
  EXPECT_GE(img.width, 1600);
  EXPECT_GE(img.height, 1000);
  ASSERT_EQ(L.panels.size(), 1u);
  const PlotArea& a = L.panels[0].plot;
  // +/-1.2 V lines at the rows of the axis mapping, across the plot.
  for (double v : {1.2, -1.2})
    EXPECT_GE(columns_with(img, a, a.row(v), kThresholdRgb), a.rect.width() * 97 / 100) << v;
  EXPECT_LT(columns_with(img, a, a.row(0.0), kThresholdRgb), 5);
  // Dashed VSTART minima 1.6 and 1.7 V (about 9 px on, 5 off).
  for (double v : {1.6, 1.7, -1.6, -1.7}) {
    const int n = columns_with(img, a, a.row(v), kLevelRgb);
    EXPECT_GE(n, a.rect.width() * 45 / 100) << v;
    EXPECT_LE(n, a.rect.width() * 85 / 100) << v;
  }
  // Plenty drawn, and the density in viridis colours inside the plot.
  const int drawn = count_if(img, {0, 0, img.width, img.height}, [](const std::array<int, 3>& c) {
    return !(c[0] == 255 && c[1] == 255 && c[2] == 255);
  });
  EXPECT_GT(drawn, img.width * img.height / 5);
  std::set<uint32_t> viridis;
  for (const Color& c : ColorMap::viridis().table())
    viridis.insert(static_cast<uint32_t>(std::lround(c.r * 255)) << 16 |
                   static_cast<uint32_t>(std::lround(c.g * 255)) << 8 |
                   static_cast<uint32_t>(std::lround(c.b * 255)));
  const int density = count_if(img, a.rect, [&](const std::array<int, 3>& c) {
    return viridis.count(static_cast<uint32_t>(c[0] << 16 | c[1] << 8 | c[2])) > 0;
  });
  EXPECT_GT(density, 5000);
  // The verdict is green: no FAIL red in the title block.
  EXPECT_EQ(count_if(img, {0, 0, img.width, 96}, is_kfail), 0);
}

TEST(EyePng, TwoPanelsStackWithTheirOwnRules) {
  const Direction down = direction({0x80, 0x02}, {});
  const Direction up = direction({0x5A}, {.amplitude = 2.2}, "bq79600");
  ASSERT_TRUE(down.c.pass);
  ASSERT_TRUE(up.c.pass);
  const std::vector<EyePanel> one{down.panel("down")};
  const std::vector<EyePanel> two{down.panel("down: bq79600 -> bq7961x"),
                                  up.panel("up: bq7961x -> bq79600")};
  const EyeLayout L1 = eye_layout(one, {});
  const EyeLayout L2 = eye_layout(two, {});
  EXPECT_GT(L2.height, L1.height + 800);
  ASSERT_EQ(L2.panels.size(), 2u);
  EXPECT_GE(L2.panels[1].plot.rect.y0, L2.panels[0].panel.y1);
  const std::string path = temp_dir("eye_two") + "/eye.png";
  Status s = render_eye_png(two, {.spec = "two"}, path);
  ASSERT_TRUE(s.ok()) << s.message();
  const Png img = read_png(path);
  ASSERT_EQ(img.height, L2.height);
  const PlotArea& b = L2.panels[1].plot;
  EXPECT_GE(columns_with(img, b, b.row(-1.2), kThresholdRgb), b.rect.width() * 97 / 100);
  // The bridge's VSTART minimum is 1.8 V; it has no 1.6 V level.
  EXPECT_GE(columns_with(img, b, b.row(1.8), kLevelRgb), b.rect.width() * 45 / 100);
  EXPECT_LT(columns_with(img, b, b.row(1.6), kLevelRgb), b.rect.width() / 10);
}

// Tones: T = 1 us, the window -0.25..2.25 us and the 920-1080 ns width band.
TEST(EyePng, ToneRulesFoldOnTheirPeriod) {
  synth::Pwl pwl;
  synth::Train tr;
  tr.T = 1e-6;
  for (int k = 0; k < 12; ++k) tr.pulses.push_back({.sign = k % 2 ? -1 : +1});
  synth::append_train(pwl, tr);
  const Waveform w = synth::sample(pwl, 2e-9, tr.end() + 5e-6);
  const eye::Rules r = rules("tone");
  StatusOr<eye::CheckResult> c = eye::check_samples(w.time, w.columns[0], r);
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE(c->pass) << (c->reasons.empty() ? "" : c->reasons[0]);
  const std::vector<EyePanel> panels{
      {.direction = "wake", .time = w.time, .diff = w.columns[0], .rules = &r, .result = &*c}};
  const EyeLayout L = eye_layout(panels, {});
  const PlotArea& a = L.panels[0].plot;
  EXPECT_DOUBLE_EQ(a.x.lo, -0.25e-6);
  EXPECT_DOUBLE_EQ(a.x.hi, 2.25e-6);
  StatusOr<Canvas> img = draw_eye(panels, {.spec = "tones"});
  ASSERT_TRUE(img.ok()) << img.status().message();
  // The width band (0x3A7BD5 at 16 %) spans 920..1080 ns: tinted at 1 us, not at 800 ns.
  const int y = a.row(0.3);  // inside the red zone, away from traces
  const Color in = img->pixel(a.col(1e-6), y), out = img->pixel(a.col(0.8e-6), y);
  EXPECT_LT(in.r, out.r - 0.05f);
}

TEST(EyePng, FailingVerdictIsRed) {
  const Direction d = direction({0x80}, {.short_pulse = 3});
  ASSERT_FALSE(d.c.pass);
  StatusOr<Canvas> c = draw_eye({d.panel("down")}, {.spec = "short pulse"});
  ASSERT_TRUE(c.ok()) << c.status().message();
  int red = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < c->width(); ++x) {
      const Color p = c->pixel(x, y);
      red += (std::lround(p.r * 255) == 0xE0 && p.g == 0 && p.b == 0) ? 1 : 0;
    }
  EXPECT_GT(red, 50);
}

TEST(EyePng, BadInputAndUnwritablePathsAreErrors) {
  const Direction d = direction({0x80}, {});
  EXPECT_FALSE(render_eye_png({}, {}, temp_dir("eye_bad") + "/eye.png").ok());
  EyePanel no_rules = d.panel("down");
  no_rules.rules = nullptr;
  Status s = render_eye_png({no_rules}, {}, temp_dir("eye_bad") + "/eye.png");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("down"), std::string::npos) << s.message();
  const std::string path = "/nonexistent-isolink-dir/eye.png";
  s = render_eye_png({d.panel("down")}, {}, path);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
}

}  // namespace
}  // namespace isolink::reports
