// pack.png: a pack's daisy chain as a diagram. The bridge and the stack devices as boxes in rows
// (a snake: left to right, then right to left), each hop a thick line coloured by its worst
// relative margin, labelled with its number, cable length, isolation and margin; the ring's return
// hop drawn around the chain back to the bridge; the weakest hop marked.
//
//   PackDiagram d{.title = "pack-16", .verdict = "PASS", .devices = 16, .ring = true};
//   d.hops.push_back({.index = 1, .pass = true, .margin = 0.31, .length = 0.3, .isolation =
//   "cap"}); Status s = draw_pack_png(d, "out/pack.png");
//
// Contract: the inputs are read during the call only. Errors: a Status naming the file (the
// image plug-in or its fonts not found, a write that fails); the PNG is written to a temporary
// name and renamed, so a failure leaves no file.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "reports/plot.h"

namespace isolink::reports {

struct PackDiagram {
  std::string title;
  std::string verdict;  // "PASS" | "FAIL"
  int devices = 0;      // stack devices; node 0 is the bridge
  bool ring = false;
  int weakest = 0;  // hop index, 0: none
  struct Hop {
    int index = 0;  // hop k joins node k - 1 and node k; the return hop is devices + 1
    bool ring_return = false;
    bool pass = true;
    double margin = 0;      // worst relative margin (NaN: none judged)
    double length = 0;      // m
    std::string isolation;  // "cap", "xfmr", "cap/xfmr"
  };
  std::vector<Hop> hops;
};

// Where everything goes. Labels are measured: the gap between boxes in a row is as wide as the
// widest hop label (so no label reaches over a box), and the rows are far enough apart that the
// labels of a turn's vertical hop sit between the labels of the rows above and below it.
struct PackLayout {
  int width = 0, height = 0;
  std::vector<Rect> boxes;  // node k's box (0: the bridge)
  struct Label {
    int hop = 0;              // PackDiagram::Hop::index
    std::vector<Rect> lines;  // "hop N", length, isolation, margin: each line's backing box
    Rect bounds;              // all of them (the weakest hop's frame goes 4 px outside it)
  };
  std::vector<Label> labels;  // one per hop drawn, in d.hops order
  double ring_y = 0;          // the return hop's run along the bottom (pixel row)
  double ring_x = 0;          // and up the left side (pixel column)
  int legend_y = 0;           // the colour scale's centre row
};
// `measure` is any canvas (text extents only; nothing is drawn on it).
PackLayout pack_layout(const PackDiagram& d, const Canvas& measure);

// The colour of a hop: red when it fails, else from orange (margin 0) through yellow to green
// (relative margin >= 15 %; the width rule alone caps it near 12 %).
Color margin_color(bool pass, double margin);

Status draw_pack_png(const PackDiagram& d, const std::string& path);

}  // namespace isolink::reports
