#include "reports/pack_png.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "fixtures.h"

namespace isolink::reports {
namespace {

using fixtures::Png;
using fixtures::read_png;
using fixtures::temp_dir;

bool overlap(const Rect& a, const Rect& b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

// A 16-device ring whose hops carry the longest isolation names the pack report writes.
PackDiagram ring16(const std::string& isolation) {
  PackDiagram d{.title = "pack-16", .verdict = "PASS", .devices = 16, .ring = true, .weakest = 9};
  for (int k = 1; k <= 17; ++k)
    d.hops.push_back({.index = k,
                      .ring_return = k == 17,
                      .pass = k != 5,
                      .margin = 0.01 * k,
                      .length = k % 2 ? 0.3 : 12.5,
                      .isolation = isolation});
  return d;
}

// No hop label (with the weakest hop's frame) touches a device box or another label, for short
// and long labels; every label lies inside the image.
TEST(PackPng, LabelsClearOfBoxesAndOfEachOther) {
  StatusOr<Canvas> m = Canvas::create(1, 1);
  ASSERT_TRUE(m.ok()) << m.status().message();
  for (const char* iso : {"cap", "cap+2 chokes", "cap+2 chokes/xfmr+choke"}) {
    const PackDiagram d = ring16(iso);
    const PackLayout L = pack_layout(d, *m);
    ASSERT_EQ(L.boxes.size(), 17u);
    ASSERT_EQ(L.labels.size(), 17u) << iso;
    for (const PackLayout::Label& lab : L.labels) {
      const Rect framed = lab.bounds.inset(-4);
      const Rect clear = framed.inset(-6);  // at least 6 px of white around the frame
      EXPECT_GE(framed.x0, 0);
      EXPECT_LE(framed.x1, L.width);
      EXPECT_LE(framed.y1, L.legend_y - 20);
      ASSERT_EQ(lab.lines.size(), 4u);
      EXPECT_GT(lab.lines[2].width(), m->measure(iso, 15).width);  // the isolation line, whole
      for (size_t k = 0; k < L.boxes.size(); ++k)
        EXPECT_FALSE(overlap(clear, L.boxes[k])) << iso << ": hop " << lab.hop << ", box " << k;
      for (const PackLayout::Label& other : L.labels) {
        if (other.hop == lab.hop) continue;
        EXPECT_FALSE(overlap(lab.bounds, other.bounds))
            << iso << ": hops " << lab.hop << ", " << other.hop;
      }
    }
  }
}

// The pixels agree: inside every device box, the strips beside the device name hold only the
// box's fill (a label running over the box would put its backing and text there), and every
// label's text is drawn.
TEST(PackPng, BoxesHoldOnlyTheirOwnFillBesideTheirName) {
  const PackDiagram d = ring16("cap+2 chokes/xfmr+choke");
  const std::string path = temp_dir("pack_png") + "/pack.png";
  ASSERT_TRUE(draw_pack_png(d, path).ok());
  const Png img = read_png(path);
  StatusOr<Canvas> m = Canvas::create(1, 1);
  ASSERT_TRUE(m.ok());
  const PackLayout L = pack_layout(d, *m);
  ASSERT_EQ(img.width, L.width);
  ASSERT_EQ(img.height, L.height);
  for (size_t k = 0; k < L.boxes.size(); ++k) {
    const Rect b = L.boxes[k];
    const uint32_t fill = k == 0 ? 0xDCE6F2 : 0xF4F4F4;
    int wrong = 0;
    for (int y = b.y0 + 3; y < b.y1 - 3; ++y)
      for (int x : {b.x0 + 3, b.x0 + 8, b.x0 + 12, b.x1 - 13, b.x1 - 9, b.x1 - 4})
        wrong += img.is(x, y, fill) ? 0 : 1;
    EXPECT_EQ(wrong, 0) << "box " << k;
  }
  for (const PackLayout::Label& lab : L.labels)
    for (const Rect& r : lab.lines) {
      int ink = 0;
      for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) {
          const auto c = img.at(x, y);
          ink += c[0] + c[1] + c[2] < 3 * 160 ? 1 : 0;
        }
      EXPECT_GT(ink, 10) << "hop " << lab.hop;
    }
}

}  // namespace
}  // namespace isolink::reports
