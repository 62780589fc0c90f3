// Touchstone reader: every format and unit against values converted by hand, version 2.0's
// keywords, the refusals with their file:line:col, and the writer read back.
#include "netlists/touchstone.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/vector_fit.h"

namespace isolink {
namespace {

using cd = std::complex<double>;

std::string error_of(const std::string& text, const std::string& name) {
  StatusOr<Touchstone> t = read_touchstone_text(text, name);
  return t.ok() ? "" : t.status().message();
}

TEST(Touchstone, TwoPortMaInMhzIsOrdered11_21_12_22) {
  StatusOr<Touchstone> t = read_touchstone_text(
      "! comment\n# MHz S MA R 50\n1 0.5 90 0.8 -45 0.1 0 0.25 180 ! trailing\n2 1 0 1 0 1 0 1 0\n",
      "a.s2p");
  ASSERT_TRUE(t.ok()) << t.status().message();
  ASSERT_EQ(t->ports, 2);
  ASSERT_EQ(t->freqs.size(), 2u);
  EXPECT_DOUBLE_EQ(t->freqs[0], 1e6);
  EXPECT_NEAR(t->s[0](0, 0).real(), 0, 1e-15);
  EXPECT_NEAR(t->s[0](0, 0).imag(), 0.5, 1e-15);
  // The second pair is S21, the third S12.
  EXPECT_NEAR(std::abs(t->s[0](1, 0) - std::polar(0.8, -std::numbers::pi / 4)), 0, 1e-15);
  EXPECT_NEAR(std::abs(t->s[0](0, 1) - cd(0.1, 0)), 0, 1e-15);
  EXPECT_NEAR(std::abs(t->s[0](1, 1) - cd(-0.25, 0)), 0, 1e-15);
}

TEST(Touchstone, DbAndRiAndDefaultsGhz) {
  StatusOr<Touchstone> db = read_touchstone_text("# hz s db\n100 -20 0\n", "x.s1p");
  ASSERT_TRUE(db.ok()) << db.status().message();
  EXPECT_NEAR(db->s[0](0, 0).real(), 0.1, 1e-15);                              // -20 dB = 0.1
  StatusOr<Touchstone> ri = read_touchstone_text("0.5 0.25 -0.5\n", "x.s1p");  // GHz S MA R 50
  ASSERT_TRUE(ri.ok()) << ri.status().message();
  EXPECT_DOUBLE_EQ(ri->freqs[0], 0.5e9);
  EXPECT_NEAR(std::abs(ri->s[0](0, 0) - std::polar(0.25, -0.5 * std::numbers::pi / 180)), 0, 1e-15);
}

TEST(Touchstone, FourPortRowsOverLinesAndYNormalisedInVersion1) {
  // A 4-port, row by row over four lines; Y normalised to R = 100: y = 1 on the diagonal is
  // 10 mS, S = (1 - 100 * 0.01) / (1 + 1) = 0 for a diagonal admittance with z0 = 100.
  std::string text = "# khz y ri r 100\n1";
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) text += i == j ? " 1 0" : " 0 0";
    text += "\n";
  }
  StatusOr<Touchstone> t = read_touchstone_text(text, "x.s4p");
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_DOUBLE_EQ(t->z0, 100);
  EXPECT_NEAR(t->s[0].cwiseAbs().maxCoeff(), 0, 1e-15);
}

TEST(Touchstone, Version2KeywordsAndPerPortReference) {
  // Z = 50 ohm on both ports' diagonals with references 50 and 25: S11 = 0, and S22 at the
  // common reference (the first port's, 50 ohm) is 0 as well.
  const std::string text =
      "[Version] 2.0\n# Hz Z RI\n[Number of Ports] 2\n[Two-Port Data Order] 12_21\n"
      "[Number of Frequencies] 1\n[Reference] 50\n 25\n[Begin Information]\nanything\n"
      "[End Information]\n[Network Data]\n1e6 50 0 0 0 0 0 50 0\n[End]\n";
  StatusOr<Touchstone> t = read_touchstone_text(text, "v2.ts");
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(t->version, 2);
  EXPECT_NEAR(t->s[0].cwiseAbs().maxCoeff(), 0, 1e-12);
}

TEST(Touchstone, Version2LowerMatrixIsMirrored) {
  const std::string text =
      "[Version] 2.0\n# Hz S RI R 50\n[Number of Ports] 2\n[Two-Port Data Order] 12_21\n"
      "[Matrix Format] Lower\n[Network Data]\n1 0.1 0 0.2 0 0.3 0\n";
  StatusOr<Touchstone> t = read_touchstone_text(text, "v2.ts");
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_DOUBLE_EQ(t->s[0](1, 0).real(), 0.2);
  EXPECT_DOUBLE_EQ(t->s[0](0, 1).real(), 0.2);
  EXPECT_DOUBLE_EQ(t->s[0](1, 1).real(), 0.3);
}

TEST(Touchstone, TwoPortNoiseBlockIsSkipped) {
  StatusOr<Touchstone> t = read_touchstone_text(
      "# GHz S RI\n1 0 0 1 0 1 0 0 0\n2 0 0 1 0 1 0 0 0\n1 1.5 0.5 20 0.3\n2 1.6 0.5 25 0.3\n",
      "amp.s2p");
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(t->freqs.size(), 2u);
  EXPECT_EQ(t->noise_lines_skipped, 1);
}

TEST(Touchstone, ErrorsNameLineAndColumn) {
  EXPECT_EQ(error_of("# MHz S RI\n1 0 0 1 0 1 0 0 0\n1 0 0 1 0 1 0 0 0\n", "a.s2p")
                .rfind("a.s2p:3:1: error: frequency 1e+06 Hz does not rise", 0),
            0u);
  EXPECT_EQ(error_of("# MHz S RI\n1 0 0 1 0 nan 0 0 0\n", "a.s2p")
                .rfind("a.s2p:2:11: error: 'nan' is not a finite number", 0),
            0u);
  EXPECT_EQ(error_of("# MHz S RI\n1 0 0 1 0 1 0 0\n", "a.s2p")
                .rfind("a.s2p:2:1: error: 8 values for 2-port data", 0),
            0u);
  EXPECT_EQ(error_of("# MHz H RI\n", "a.s2p").rfind("a.s2p:1:7: error: H parameters", 0), 0u);
  EXPECT_EQ(error_of("[Version] 2.0\n[Number of Ports] 4\n[Mixed-Mode Order] D2,1 D4,3\n", "m.ts")
                .rfind("m.ts:3:1: error: [Mixed-Mode Order]", 0),
            0u);
  EXPECT_EQ(error_of("[Version] 2.0\n[Number of Ports] 2\n[Foo] 1\n", "m.ts")
                .rfind("m.ts:3:1: error: keyword [Foo] is not supported", 0),
            0u);
  EXPECT_EQ(error_of("# MHz S RI\n1 0 0\n", "noport.txt")
                .rfind("noport.txt:1:1: error: a version 1 file's port count", 0),
            0u);
  // A 4-port point cut short at the end of the file.
  EXPECT_EQ(error_of("# MHz S RI\n1 0 0 0 0 0 0 0 0\n", "x.s4p")
                .rfind("x.s4p:2:1: error: the point at this frequency has 9 of its 33 values", 0),
            0u);
  EXPECT_NE(error_of("", "x.s2p").find("no network data"), std::string::npos);
  // A second [Number of Ports] after data sized by the first (fuzz_touchstone's finding: the
  // reference impedances were then read past their end).
  EXPECT_EQ(error_of("[Version] 2.0\n# Hz S RI\n[Number of Ports] 2\n[Reference] 50 50\n"
                     "[Network Data]\n1e6 0.1 0 0.9 0 0.9 0 0.1 0\n[Number of Ports] 3\n[End]\n",
                     "m.ts")
                .rfind("m.ts:7:19: error: [Number of Ports] again (it was 2)", 0),
            0u);
}

TEST(Touchstone, WriterReadsBack) {
  Touchstone t;
  t.ports = 4;
  t.z0 = 50;
  for (int k = 0; k < 3; ++k) {
    Eigen::MatrixXcd s(4, 4);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) s(i, j) = cd(0.01 * (i + 1) * (k + 1), -0.02 * (j + 1));
    t.freqs.push_back(1e6 * (k + 1));
    t.s.push_back(s);
  }
  StatusOr<Touchstone> back = read_touchstone_text(write_touchstone(t, "two\nlines"), "w.s4p");
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->freqs.size(), 3u);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR((back->s[k] - t.s[k]).cwiseAbs().maxCoeff(), 0, 1e-12);
}

}  // namespace
}  // namespace isolink
