#include "reports/wave_png.h"

#include <gtest/gtest.h>

#include <filesystem>
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

bool reddish(const std::array<int, 3>& c) {
  return c[0] > 200 && c[1] < 80 && c[2] < 80;
}

int count_if(const Png& img, const Rect& r, auto pred) {
  int n = 0;
  for (int y = std::max(r.y0, 0); y < std::min(r.y1, img.height); ++y)
    for (int x = std::max(r.x0, 0); x < std::min(r.x1, img.width); ++x)
      n += pred(img.at(x, y)) ? 1 : 0;
  return n;
}

int columns_with(const Png& img, const PlotArea& a, int row, uint32_t rgb) {
  int n = 0;
  for (int x = a.rect.x0; x < a.rect.x1; ++x) {
    bool hit = false;
    for (int y = row - 1; y <= row + 1; ++y) hit = hit || img.is(x, y, rgb);
    n += hit ? 1 : 0;
  }
  return n;
}

struct Direction {
  LinkWave w;
  eye::Rules r;
  eye::CheckResult c;
  WavePanel panel(const std::string& name, bool pins = true) const {
    WavePanel p{.direction = name, .time = w.t, .diff = w.v, .rules = &r, .result = &c};
    if (pins) {
      p.p = w.p;
      p.n = w.n;
    }
    return p;
  }
};

Direction direction(const std::vector<uint8_t>& bytes, const fixtures::LinkWaveOptions& o) {
  Direction d;
  d.w = link_wave(bytes, o);
  d.r = rules();
  d.c = check(d.w, d.r);
  return d;
}

Png render(const std::vector<WavePanel>& panels, const std::string& name) {
  const std::string path = temp_dir(name) + "/wave.png";
  Status s = render_wave_png(panels, {.spec = name}, path);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp.png"));
  return read_png(path);
}

TEST(WavePng, PassingWaveHasNoRedAndThresholdsOnTheirRows) {
  const Direction d = direction({0x80, 0x02, 0x15}, {.cm_amplitude = 0.5});
  ASSERT_TRUE(d.c.pass);
  const std::vector<WavePanel> panels{d.panel("down: bq79600 -> bq7961x")};
  const Png img = render(panels, "wave_pass");
  const WaveLayout L = wave_layout(panels, {.spec = "wave_pass"});
  ASSERT_EQ(img.width, L.width);
  ASSERT_EQ(img.height, L.height);
  EXPECT_GE(img.width, 1600);
  EXPECT_GE(img.height, 1000);
  EXPECT_EQ(count_if(img, {0, 0, img.width, img.height}, reddish), 0);
  const PlotArea& a = L.panels[0].diff;
  for (double v : {1.2, -1.2})
    EXPECT_GE(columns_with(img, a, a.row(v), kThresholdRgb), a.rect.width() * 95 / 100) << v;
  // The trace reaches +2 V and -2 V.
  const auto trace = [](const std::array<int, 3>& c) {
    return c[0] == 0x1F && c[1] == 0x3A && c[2] == 0x5F;
  };
  EXPECT_GT(count_if(img, {a.rect.x0, a.row(2.0) - 2, a.rect.x1, a.row(2.0) + 3}, trace), 200);
  EXPECT_GT(count_if(img, {a.rect.x0, a.row(-2.0) - 2, a.rect.x1, a.row(-2.0) + 3}, trace), 200);
  // Pins: P, N and the common mode in their colours inside the lower plot.
  ASSERT_TRUE(L.panels[0].pins.has_value());
  const Rect pr = L.panels[0].pins->rect;
  for (uint32_t rgb : {0x1F77B4u, 0xFF7F0Eu, 0x2CA02Cu}) {
    const int n = count_if(img, pr, [rgb](const std::array<int, 3>& c) {
      return c[0] == static_cast<int>(rgb >> 16) && c[1] == static_cast<int>((rgb >> 8) & 0xFF) &&
             c[2] == static_cast<int>(rgb & 0xFF);
    });
    EXPECT_GT(n, 500) << std::hex << rgb;
  }
}

TEST(WavePng, FailingPulseIsRedWhereItIs) {
  const Direction d = direction({0x80, 0x02}, {.short_pulse = 3});
  ASSERT_FALSE(d.c.pass);
  const eye::PulseMetrics* bad = nullptr;
  for (const eye::PulseMetrics& p : d.c.pulses)
    if (p.failing()) {
      bad = &p;
      break;
    }
  ASSERT_NE(bad, nullptr);
  EXPECT_NEAR(bad->width.value, 150e-9, 2e-9);
  const std::vector<WavePanel> panels{d.panel("down")};
  const Png img = render(panels, "wave_fail");
  const WaveLayout L = wave_layout(panels, {});
  const PlotArea& a = L.panels[0].diff;
  EXPECT_GT(count_if(img, a.rect, reddish), 50);
  // Red at the failing pulse's columns, and not far away from it.
  const int col = a.col((bad->a + bad->b) / 2);
  EXPECT_GT(count_if(img, {col - 3, a.rect.y0 + 40, col + 4, a.rect.y1}, reddish), 5);
  EXPECT_EQ(count_if(img, {a.col(bad->b + 3e-6), a.rect.y0, a.rect.x1, a.rect.y1}, reddish), 0);
}

TEST(WavePng, LongRecordKeepsEveryExcursion) {
  std::vector<uint8_t> bytes(30);
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(i * 37);
  Direction d = direction(bytes, {.gap = 4e-6});
  // A one-sample spike to 4 V in the gap after frame 10: ringing (a warning), one sample wide.
  ASSERT_GT(d.c.frames.size(), 11u);
  const double t_spike = d.c.pulses[d.c.frames[10].last_pulse].b + 2e-6;
  const size_t i = static_cast<size_t>(std::lround(t_spike / 1e-9));
  d.w.v[i] = 4.0;
  d.c = check(d.w, d.r);
  ASSERT_TRUE(d.c.pass);
  ASSERT_GT(d.w.t.size(), 300000u);
  const std::vector<WavePanel> panels{d.panel("down", false)};
  const WaveLayout L = wave_layout(panels, {});
  EXPECT_FALSE(L.panels[0].pins.has_value());
  const Png img = render(panels, "wave_long");
  const PlotArea& a = L.panels[0].diff;
  const int col = a.col(d.w.t[i]);
  const auto trace = [](const std::array<int, 3>& c) {
    return c[0] == 0x1F && c[1] == 0x3A && c[2] == 0x5F;
  };
  EXPECT_GT(count_if(img, {col - 1, a.row(4.0) - 1, col + 2, a.row(4.0) + 2}, trace), 0);
  EXPECT_EQ(count_if(img, {0, 0, img.width, img.height}, reddish), 0);
}

TEST(WavePng, TwoDirectionsAndErrors) {
  const Direction down = direction({0x80}, {});
  const Direction up = direction({0x81}, {.short_pulse = 5});
  const std::vector<WavePanel> two{down.panel("down"), up.panel("up")};
  const WaveLayout L = wave_layout(two, {});
  ASSERT_EQ(L.panels.size(), 2u);
  EXPECT_GE(L.panels[1].diff.rect.y0, L.panels[0].panel.y1);
  const Png img = render(two, "wave_two");
  EXPECT_EQ(img.height, L.height);
  EXPECT_EQ(count_if(img, L.panels[0].diff.rect, reddish), 0);
  EXPECT_GT(count_if(img, L.panels[1].diff.rect, reddish), 20);

  EXPECT_FALSE(render_wave_png({}, {}, temp_dir("wave_bad") + "/w.png").ok());
  WavePanel mismatch = down.panel("down");
  mismatch.n = mismatch.n.subspan(1);
  Status s = render_wave_png({mismatch}, {}, temp_dir("wave_bad") + "/w.png");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("P and N"), std::string::npos) << s.message();
  const std::string path = "/nonexistent-isolink-dir/wave.png";
  s = render_wave_png({down.panel("down")}, {}, path);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
}

bool orange(const std::array<int, 3>& c) {
  return c[0] > 200 && c[1] > 100 && c[1] < 190 && c[2] < 90;
}

// A worst-case image: the marked pulse is magnified in an inset under the plot, and its label sits
// above the inset, not in the plot's bottom row where the frames' byte labels are.
TEST(WavePng, MarkedPulseGetsAZoomInsetAndItsLabelClearOfTheFrameLabels) {
  const Direction d = direction({0x80, 0x02, 0x15}, {});
  ASSERT_TRUE(d.c.pass);
  const size_t marked = d.c.frames[1].first_pulse + 3;
  const eye::PulseMetrics& pm = d.c.pulses[marked];
  WavePanel panel = d.panel("down: worst vstart", false);
  panel.marked = marked;
  panel.mark_label = "vstart 1.913 V (margin +0.213 V)";
  const std::vector<WavePanel> panels{panel};
  const WaveLayout L = wave_layout(panels, {});
  const WavePanelLayout& P = L.panels[0];
  ASSERT_TRUE(P.zoom.has_value());
  const PlotArea& a = P.diff;
  const PlotArea& z = *P.zoom;
  // Four half bits (250 ns) either side of the pulse.
  EXPECT_NEAR(z.x.lo, pm.a - 1e-6, 1e-12);
  EXPECT_NEAR(z.x.hi, pm.b + 1e-6, 1e-12);
  // Inset and label band lie below the plot, inside the panel, one under the other.
  EXPECT_GT(P.zoom_label.y0, a.rect.y1 + 30);  // below the plot's tick labels
  EXPECT_LE(P.zoom_label.y1, z.rect.y0);
  EXPECT_LE(z.rect.y1 + 60, P.panel.y1);

  const Png img = render(panels, "wave_marked");
  // The inset is drawn: the trace and the orange pulse inside it.
  const auto trace = [](const std::array<int, 3>& c) {
    return c[0] == 0x1F && c[1] == 0x3A && c[2] == 0x5F;
  };
  EXPECT_GT(count_if(img, z.rect, trace), 300);
  EXPECT_GT(count_if(img, z.rect, orange), 300);
  // Magnified: the pulse spans far more columns in the inset than in the plot.
  const double wide = z.px(pm.b) - z.px(pm.a), narrow = a.px(pm.b) - a.px(pm.a);
  EXPECT_GT(wide, 8 * narrow);
  // The label, in orange, in its band.
  EXPECT_GT(count_if(img, P.zoom_label, orange), 150);
  // Nothing orange in the plot's bottom label row apart from the dashed box around the zoom
  // window (the old layout centred the label there, over the frame labels).
  const int bx0 = a.col(z.x.lo) - 4, bx1 = a.col(z.x.hi) + 5;
  const Rect bottom{a.rect.x0, a.rect.y1 - 30, a.rect.x1, a.rect.y1};
  EXPECT_EQ(count_if(img, {bottom.x0, bottom.y0, bx0, bottom.y1}, orange), 0);
  EXPECT_EQ(count_if(img, {bx1, bottom.y0, bottom.x1, bottom.y1}, orange), 0);
  // The frames' byte labels are still there (dark text in that row outside the box).
  const auto dark = [](const std::array<int, 3>& c) { return c[0] < 140 && c[1] < 140; };
  EXPECT_GT(count_if(img, {bottom.x0, bottom.y0, bx0, bottom.y1}, dark), 50);
  // No frame label inside the dashed box, where its sides would cross the text: no grey text
  // pixels (kMuted 0x666666 and its anti-aliased edges) in that part of the row. The frame that
  // holds the marked pulse starts inside the box, so its label would otherwise sit there.
  ASSERT_GT(a.col(d.c.frames[1].start), bx0);
  ASSERT_LT(a.col(d.c.frames[1].start) + 40, bx1);
  const auto grey = [](const std::array<int, 3>& c) {
    return std::abs(c[0] - c[1]) < 10 && std::abs(c[1] - c[2]) < 10 && c[0] < 0xB0;
  };
  EXPECT_EQ(count_if(img, {bx0, bottom.y0, bx1, bottom.y1}, grey), 0);
  // That frame's label moves just right of the box, still inside the frame.
  EXPECT_GT(count_if(img, {bx1, bottom.y0, bx1 + 120, bottom.y1}, grey), 30);
}

}  // namespace
}  // namespace isolink::reports
