#include "netlists/spice_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "solver/elements/element.h"

namespace isolink {
namespace {

namespace fs = std::filesystem;

// A formatted diagnostic split into its parts.
struct Diag {
  std::string head;                // "file:line:col: error: message"
  std::string source;              // the source line
  int caret = -1;                  // 1-based column of the caret under the source line
  std::vector<std::string> notes;  // the lines after the caret
};

Diag split(const std::string& msg) {
  std::vector<std::string> lines;
  std::size_t a = 0;
  while (true) {
    std::size_t b = msg.find('\n', a);
    lines.push_back(msg.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  Diag d;
  d.head = lines[0];
  if (lines.size() >= 3) {
    d.source = lines[1].substr(1);
    d.caret = static_cast<int>(lines[2].find('^'));  // the caret line starts with one space
  }
  for (std::size_t i = 3; i < lines.size(); ++i) d.notes.push_back(lines[i]);
  return d;
}

Netlist read_ok(const std::string& text) {
  auto n = read_spice_text(text, "t.cir");
  EXPECT_TRUE(n) << n.status().message();
  return n ? *n : Netlist{};
}

Diag read_error(const std::string& text) {
  auto n = read_spice_text(text, "t.cir");
  EXPECT_FALSE(n) << "expected an error for:\n" << text;
  return n ? Diag{} : split(n.status().message());
}

const Card& card(const Netlist& n, const std::string& name) {
  for (const Card& c : n.cards)
    if (c.name == name) return c;
  ADD_FAILURE() << "no card " << name;
  static const Card kNone;
  return kNone;
}

double arg(const Card& c, std::size_t i) {
  EXPECT_LT(i, c.args.size()) << c.name;
  if (i >= c.args.size()) return 0;
  EXPECT_EQ(c.args[i].kind, CardArg::Kind::Number) << c.name << " arg " << i;
  return c.args[i].number;
}

TEST(SpiceReader, ElementsAndTitle) {
  Netlist n = read_ok(
      "Daisy-chain Link Test\n"
      "R1 TXP RXP 49.9\n"
      "c2 rxp 0 2.2nF ic=0\n"
      "L1 a b 10uH\n"
      "L2 c GND 10uH m=1\n"
      "K1 L1 L2 0.99\n"
      "Itest a 0 1mA\n");
  EXPECT_EQ(n.title, "Daisy-chain Link Test");
  ASSERT_EQ(n.cards.size(), 6u);
  const Card& r = n.cards[0];
  EXPECT_EQ(r.letter, 'r');
  EXPECT_EQ(r.name, "r1");
  EXPECT_EQ(r.nodes, (std::vector<std::string>{"txp", "rxp"}));
  EXPECT_EQ(r.loc.line, 2);
  EXPECT_EQ(r.loc.col, 1);
  ASSERT_EQ(r.node_locs.size(), 2u);
  EXPECT_EQ(r.node_locs[1].col, 8);
  EXPECT_DOUBLE_EQ(arg(r, 0), 49.9);
  EXPECT_EQ(r.args[0].loc.col, 12);
  const Card& c = n.cards[1];
  EXPECT_EQ(c.letter, 'c');
  EXPECT_DOUBLE_EQ(arg(c, 0), 2.2e-9);
  ASSERT_NE(c.param("ic"), nullptr);
  EXPECT_EQ(c.param("ic")->number, 0.0);
  EXPECT_EQ(card(n, "l2").nodes, (std::vector<std::string>{"c", "0"}));  // gnd is ground
  EXPECT_DOUBLE_EQ(card(n, "l2").param("m")->number, 1.0);
  const Card& k = card(n, "k1");
  EXPECT_TRUE(k.nodes.empty());
  EXPECT_EQ(k.refs, (std::vector<std::string>{"l1", "l2"}));
  EXPECT_EQ(k.ref_locs[1].col, 7);
  EXPECT_DOUBLE_EQ(arg(k, 0), 0.99);
  EXPECT_DOUBLE_EQ(arg(card(n, "itest"), 0), 1e-3);
  EXPECT_TRUE(n.warnings.empty());
  EXPECT_FALSE(n.tran);
}

TEST(SpiceReader, SourceValues) {
  Netlist n = read_ok(
      "sources\n"
      ".param vhi=5\n"
      "V1 a 0 DC 2.5\n"
      "V2 b 0 3.3\n"
      "V3 c 0 PULSE(0 5 1n 2n 2n 100n 250n)\n"
      "V4 d 0 pulse (0, {vhi}, 1n, 2n, 2n, 100n, 250n)\n"
      "V5 e 0 PWL(0 0 1n 5 2n 0)\n"
      "V6 f 0 SIN(0 1 1meg)\n"
      "V7 g 0 dc 1 AC 1 0\n"
      "V8 h 0 AC 1\n"
      "I1 i 0 PWL(0,0,1u,{vhi*1m})\n");
  const Card& v1 = card(n, "v1");
  ASSERT_EQ(v1.args.size(), 2u);
  EXPECT_EQ(v1.args[0].kind, CardArg::Kind::Word);
  EXPECT_EQ(v1.args[0].word, "dc");
  EXPECT_DOUBLE_EQ(arg(v1, 1), 2.5);
  EXPECT_DOUBLE_EQ(arg(card(n, "v2"), 0), 3.3);
  const std::vector<double> pulse{0, 5, 1e-9, 2e-9, 2e-9, 100e-9, 250e-9};
  for (const char* name : {"v3", "v4"}) {
    const Card& v = card(n, name);
    ASSERT_EQ(v.args.size(), 1u) << name;
    EXPECT_EQ(v.args[0].kind, CardArg::Kind::Call);
    EXPECT_EQ(v.args[0].word, "pulse");
    EXPECT_EQ(v.args[0].call, pulse) << name;
    EXPECT_EQ(v.args[0].loc.col, 8);
  }
  EXPECT_EQ(card(n, "v5").args[0].word, "pwl");
  EXPECT_EQ(card(n, "v5").args[0].call, (std::vector<double>{0, 0, 1e-9, 5, 2e-9, 0}));
  EXPECT_EQ(card(n, "v6").args[0].word, "sin");
  EXPECT_EQ(card(n, "v6").args[0].call, (std::vector<double>{0, 1, 1e6}));
  // AC specifications are dropped with one warning.
  const Card& v7 = card(n, "v7");
  ASSERT_EQ(v7.args.size(), 2u);
  EXPECT_EQ(v7.args[0].word, "dc");
  EXPECT_DOUBLE_EQ(arg(v7, 1), 1.0);
  EXPECT_TRUE(card(n, "v8").args.empty());
  ASSERT_EQ(n.warnings.size(), 1u);
  EXPECT_EQ(split(n.warnings[0]).head,
            "t.cir:9:13: warning: AC specification ignored (isolink runs transient analyses)");
  EXPECT_EQ(card(n, "i1").args[0].call, (std::vector<double>{0, 0, 1e-6, 5e-3}));
}

TEST(SpiceReader, ParamsInOrder) {
  Netlist n = read_ok(
      "params\n"
      "R1 a b rload\n"                    // used before its .param line
      ".param a=1 b={a*2} c = b*3 + 1\n"  // several per line, later ones use earlier ones
      ".PARAM rload='c*10' d=-a\n"
      "R2 a b {sqrt(c+2)*1k}\n"
      "R3 a b -d\n"
      "C1 a b {2*pi*1n}\n");
  EXPECT_DOUBLE_EQ(arg(card(n, "r1"), 0), 70.0);  // c = 2*3+1 = 7
  EXPECT_DOUBLE_EQ(arg(card(n, "r2"), 0), 3000.0);
  EXPECT_DOUBLE_EQ(arg(card(n, "r3"), 0), 1.0);
  EXPECT_DOUBLE_EQ(arg(card(n, "c1"), 0), 2 * 3.14159265358979323846 * 1e-9);
}

TEST(SpiceReader, ParamRedefinitionUsesLatestValueInOrder) {
  Netlist n = read_ok(
      "t\n"
      ".param a=1\n"
      ".param b={a+1}\n"
      ".param a=10\n"
      "R1 x y {a+b}\n");
  EXPECT_DOUBLE_EQ(arg(card(n, "r1"), 0), 12.0);  // b was computed when a was 1
}

TEST(SpiceReader, ContinuationAndComments) {
  Netlist n = read_ok(
      "t\n"
      "* full-line comment\n"
      "R1 a b ; the value comes next\n"
      "+ 1k\n"
      "   * indented comment\n"
      "V1 a 0 PWL(0 0 $ first point\n"
      "+ 1n 1\n"
      "+ 2n 0) ; last\n"
      "C1 a 0\n"
      "+ 1p\n"
      "+ ic=0.5\n");
  ASSERT_EQ(n.cards.size(), 3u);
  EXPECT_DOUBLE_EQ(arg(card(n, "r1"), 0), 1000.0);
  EXPECT_EQ(card(n, "r1").args[0].loc.line, 4);
  EXPECT_EQ(card(n, "r1").args[0].loc.col, 3);
  EXPECT_EQ(card(n, "v1").args[0].call, (std::vector<double>{0, 0, 1e-9, 1, 2e-9, 0}));
  EXPECT_DOUBLE_EQ(arg(card(n, "c1"), 0), 1e-12);
  EXPECT_DOUBLE_EQ(card(n, "c1").param("ic")->number, 0.5);
  EXPECT_EQ(card(n, "c1").param("ic")->loc.line, 11);
}

TEST(SpiceReader, SubcircuitFlattening) {
  Netlist n = read_ok(
      "subckt\n"
      ".param rt=100\n"
      "X1 in out 0 filt r=1k\n"
      "Xb out2 in GND filt\n"
      ".subckt FILT a b gnd_ref params: r=50 c={r*1p}\n"
      "R1 a mid {r}\n"
      "C1 mid gnd_ref {c}\n"
      "R2 mid b rt\n"
      "C2 b 0 1p\n"
      ".ends filt\n"
      "R1 in out 1\n");
  ASSERT_EQ(n.cards.size(), 9u);
  const Card& r1 = card(n, "x1.r1");
  EXPECT_EQ(r1.letter, 'r');
  EXPECT_EQ(r1.nodes, (std::vector<std::string>{"in", "x1.mid"}));
  EXPECT_DOUBLE_EQ(arg(r1, 0), 1000.0);              // override
  EXPECT_EQ(r1.loc.line, 6);                         // where the body card was written
  EXPECT_DOUBLE_EQ(arg(card(n, "x1.c1"), 0), 1e-9);  // default c={r*1p} sees the override
  EXPECT_EQ(card(n, "x1.c1").nodes, (std::vector<std::string>{"x1.mid", "0"}));
  EXPECT_DOUBLE_EQ(arg(card(n, "x1.r2"), 0), 100.0);  // global parameter
  EXPECT_EQ(card(n, "x1.c2").nodes, (std::vector<std::string>{"out", "0"}));
  EXPECT_DOUBLE_EQ(arg(card(n, "xb.r1"), 0), 50.0);  // default
  EXPECT_DOUBLE_EQ(arg(card(n, "xb.c1"), 0), 50e-12);
  EXPECT_EQ(card(n, "xb.r1").nodes, (std::vector<std::string>{"out2", "xb.mid"}));
  EXPECT_EQ(card(n, "xb.c1").nodes, (std::vector<std::string>{"xb.mid", "0"}));
  EXPECT_EQ(card(n, "r1").nodes, (std::vector<std::string>{"in", "out"}));
}

TEST(SpiceReader, TwoLevelHierarchy) {
  Netlist n = read_ok(
      "two levels\n"
      ".subckt inner p q params: l=1u\n"
      "L1 p q {l}\n"
      "L2 q 0 {l}\n"
      "K1 L1 L2 0.5\n"
      ".ends\n"
      ".subckt outer x y params: scale=1\n"
      "X2 x mid inner l={scale*2u}\n"
      "R1 mid y 10\n"
      ".ends\n"
      "X1 a b outer scale=3\n");
  ASSERT_EQ(n.cards.size(), 4u);
  const Card& l1 = card(n, "x1.x2.l1");
  EXPECT_EQ(l1.nodes, (std::vector<std::string>{"a", "x1.mid"}));
  EXPECT_DOUBLE_EQ(arg(l1, 0), 6e-6);
  EXPECT_EQ(card(n, "x1.x2.l2").nodes, (std::vector<std::string>{"x1.mid", "0"}));
  EXPECT_EQ(card(n, "x1.x2.k1").refs, (std::vector<std::string>{"x1.x2.l1", "x1.x2.l2"}));
  EXPECT_EQ(card(n, "x1.r1").nodes, (std::vector<std::string>{"x1.mid", "b"}));
}

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("isolink_netlists_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "sub");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& rel, const std::string& text) {
    std::ofstream(dir_ / rel) << text;
    return (dir_ / rel).string();
  }
  fs::path dir_;
};

TEST_F(TempDir, IncludeRelativeToIncludingFile) {
  const std::string top = write("top.cir",
                                "top\n"
                                ".include \"sub/parts.cir\"\n"
                                "X1 a b buf\n"
                                "R9 a 0 {rp}\n");
  write("sub/parts.cir",
        "* no title line in included files\n"
        ".include defs.cir\n"
        ".subckt buf in out\n"
        "R1 in out 10\n"
        ".ends\n");
  write("sub/defs.cir", ".param rp=75\nR5 q 0 5\n");
  auto n = read_spice_file(top);
  ASSERT_TRUE(n) << n.status().message();
  ASSERT_EQ(n->cards.size(), 3u);
  EXPECT_EQ(n->cards[0].name, "r5");  // included cards come in place of the .include
  EXPECT_EQ(n->cards[0].loc.file->path, (dir_ / "sub/defs.cir").string());
  EXPECT_EQ(n->cards[0].loc.line, 2);
  EXPECT_EQ(n->cards[1].name, "x1.r1");
  EXPECT_DOUBLE_EQ(arg(card(*n, "r9"), 0), 75.0);
}

TEST_F(TempDir, MissingIncludeShowsChain) {
  const std::string top = write("top.cir", "top\nR1 a 0 1\n.include sub/a.cir\n");
  write("sub/a.cir", "R2 a 0 1\n  .INCLUDE 'nothere.cir'\n");
  auto n = read_spice_file(top);
  ASSERT_FALSE(n);
  Diag d = split(n.status().message());
  EXPECT_EQ(d.head, (dir_ / "sub/a.cir").string() +
                        ":2:12: error: cannot open include file 'nothere.cir' (looked for '" +
                        (dir_ / "sub/nothere.cir").string() + "')");
  EXPECT_EQ(d.source, "  .INCLUDE 'nothere.cir'");
  EXPECT_EQ(d.caret, 12);
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_EQ(d.notes[0], " (included from " + top + ":3:10)");
}

// A file name longer than NAME_MAX (255 bytes) made std::filesystem throw out of the reader
// (tests/fuzz); it is an error at the .include with the system's reason.
TEST(SpiceReader, IncludeNameTooLongIsAnError) {
  const std::string name(300, 'q');
  auto n = read_spice_text("title\nR1 a 0 1\n.inc " + name + "\n", "long.cir");
  ASSERT_FALSE(n);
  EXPECT_NE(n.status().message().find("long.cir:3:6: error: include file '" + name +
                                      "': cannot open the file: File name too long"),
            std::string::npos)
      << n.status().message();
}

TEST_F(TempDir, RecursiveInclude) {
  const std::string top = write("top.cir", "top\n.include a.cir\n");
  write("a.cir", "R1 a 0 1\n.include b.cir\n");
  write("b.cir", "R2 a 0 1\n.include a.cir\n");
  auto n = read_spice_file(top);
  ASSERT_FALSE(n);
  Diag d = split(n.status().message());
  EXPECT_EQ(d.head, (dir_ / "b.cir").string() + ":2:10: error: recursive include of '" +
                        (dir_ / "a.cir").string() + "'");
  EXPECT_EQ(d.caret, 10);
  ASSERT_EQ(d.notes.size(), 2u);
  EXPECT_EQ(d.notes[0], " (included from " + (dir_ / "a.cir").string() + ":2:10)");
  EXPECT_EQ(d.notes[1], " (included from " + top + ":2:10)");
}

TEST(SpiceReader, MissingTopFile) {
  auto n = read_spice_file("/nonexistent/isolink/x.cir");
  ASSERT_FALSE(n);
  EXPECT_EQ(n.status().message(),
            "/nonexistent/isolink/x.cir: error: cannot open the file: No such file or directory");
}

TEST(SpiceReader, AnalysisOptionsAndSkippedCards) {
  Netlist n = read_ok(
      "analysis\n"
      ".options reltol=1e-4 method=gear noacct\n"
      ".option abstol = 1p\n"
      ".tran 1n 10u 0 2n uic\n"
      ".model dmod d(is=1e-14)\n"
      ".print tran v(a)\n"
      ".print tran v(b)\n"
      ".save v(a)\n"
      ".ic v(a)=0\n"
      ".meas tran x max v(a)\n"
      ".temp 27\n"
      ".control\n"
      "run\n"
      "plot v(a)\n"
      ".endc\n"
      "R1 a 0 1\n"
      ".end\n"
      "R2 a 0 1\n");
  ASSERT_EQ(n.cards.size(), 1u);  // R2 comes after .end
  ASSERT_TRUE(n.tran);
  EXPECT_DOUBLE_EQ(n.tran->tstep, 1e-9);
  EXPECT_DOUBLE_EQ(n.tran->tstop, 10e-6);
  EXPECT_DOUBLE_EQ(n.tran->tstart, 0.0);
  EXPECT_DOUBLE_EQ(n.tran->tmax, 2e-9);
  EXPECT_TRUE(n.tran->uic);
  EXPECT_EQ(n.tran->loc.line, 4);
  ASSERT_EQ(n.options.size(), 4u);
  EXPECT_EQ(n.options[0].key, "reltol");
  EXPECT_EQ(n.options[0].value.kind, CardArg::Kind::Number);
  EXPECT_DOUBLE_EQ(n.options[0].value.number, 1e-4);
  EXPECT_EQ(n.options[0].loc.col, 10);
  EXPECT_EQ(n.options[1].key, "method");
  EXPECT_EQ(n.options[1].value.kind, CardArg::Kind::Word);
  EXPECT_EQ(n.options[1].value.word, "gear");
  EXPECT_EQ(n.options[2].key, "noacct");
  EXPECT_EQ(n.options[2].value.kind, CardArg::Kind::Word);
  EXPECT_EQ(n.options[2].value.word, "");
  EXPECT_EQ(n.options[3].key, "abstol");
  EXPECT_DOUBLE_EQ(n.options[3].value.number, 1e-12);
  EXPECT_EQ(n.options[3].loc.line, 3);
  // One warning per kind of skipped card, at its first occurrence, in order.
  std::vector<std::string> heads;
  for (const auto& w : n.warnings) heads.push_back(split(w).head);
  EXPECT_EQ(heads, (std::vector<std::string>{
                       "t.cir:12:1: warning: '.control' ... '.endc' block ignored",
                       "t.cir:6:1: warning: unsupported card '.print' ignored",
                       "t.cir:8:1: warning: unsupported card '.save' ignored",
                       "t.cir:10:1: warning: unsupported card '.meas' ignored",
                   }));
  ASSERT_EQ(n.initial_voltages.size(), 1u);  // .ic is read, not skipped
  EXPECT_EQ(n.initial_voltages[0].node, "a");
}

TEST(SpiceReader, TranMinimal) {
  Netlist n = read_ok("t\n.tran 10p 1u\n");
  ASSERT_TRUE(n.tran);
  EXPECT_DOUBLE_EQ(n.tran->tstep, 10e-12);
  EXPECT_DOUBLE_EQ(n.tran->tstop, 1e-6);
  EXPECT_EQ(n.tran->tmax, 0.0);
  EXPECT_FALSE(n.tran->uic);
}

TEST(SpiceReader, HundredThousandPointPwl) {
  constexpr int kPoints = 100000;
  std::string text = "pwl\nV1 in 0 PWL(\n";
  for (int i = 0; i < kPoints; ++i) {
    text += (i % 10 == 0) ? "+ " : " ";
    text += std::to_string(i) + "n " + ((i % 2) ? "2.5" : "0");
    if (i % 10 == 9) text += "\n";
  }
  text += "+ )\nR1 in 0 50\n";
  const auto t0 = std::chrono::steady_clock::now();
  auto n = read_spice_text(text, "pwl.cir");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(n) << n.status().message();
  ASSERT_EQ(n->cards.size(), 2u);
  const CardArg& pwl = n->cards[0].args.at(0);
  ASSERT_EQ(pwl.call.size(), 2u * kPoints);
  EXPECT_DOUBLE_EQ(pwl.call[2 * 12345], 12345e-9);
  EXPECT_EQ(pwl.call[2 * 12345 + 1], 2.5);
  EXPECT_DOUBLE_EQ(pwl.call[2 * (kPoints - 1)], (kPoints - 1) * 1e-9);
  // Generous bound (sanitizer builds too); catches quadratic behaviour, not a benchmark.
  EXPECT_LT(seconds, 3.0);
}

// The cards the reader produces are the ones the element kinds accept.
TEST(SpiceReader, CardsParseWithElementKinds) {
  Netlist n = read_ok(
      "isolated daisy-chain link\n"
      ".param cser=2.2n\n"
      ".subckt xfmr p1 p2 s1 s2 params: lm=150u\n"
      "L1 p1 p2 {lm}\n"
      "L2 s1 s2 {lm}\n"
      "K1 L1 L2 0.99\n"
      ".ends\n"
      "Vtx txp txn PULSE(-2.5 2.5 0 10n 10n 240n 500n)\n"
      "Vb b 0 DC 1\n"
      "Ib b 0 PWL(0 0 1u 1m)\n"
      "C1 txp a {cser}\n"
      "C2 txn c {cser} ic=0\n"
      "X1 a c rxp rxn xfmr\n"
      "R1 rxp rxn 100\n"
      "R2 rxn 0 1meg\n"
      ".tran 1n 5u\n");
  ASSERT_EQ(n.cards.size(), 10u);
  for (const Card& c : n.cards) {
    const ElementKind* kind = find_element_kind(c.letter);
    ASSERT_NE(kind, nullptr) << c.name;
    auto e = kind->parse(c);
    EXPECT_TRUE(e) << c.name << ": " << e.status().message();
  }
}

// ---- errors: exact location and caret ----

TEST(SpiceReaderErrors, RefusedElementLetters) {
  Diag d = read_error("t\nR1 a b 1\n  Q1 c b e npn\n");
  EXPECT_EQ(d.head.substr(0, 57), "t.cir:3:3: error: bipolar transistor (Q) is not supported");
  EXPECT_EQ(d.source, "  Q1 c b e npn");
  EXPECT_EQ(d.caret, 3);
  // The transmission-line message points at the link-spec cable model.
  d = read_error("t\nT1 a 0 b 0 z0=100 td=1n\n");
  EXPECT_EQ(d.head.substr(0, 56), "t.cir:2:1: error: transmission line (T) is not supported");
  EXPECT_NE(d.head.find("'cable:' key"), std::string::npos) << d.head;
  for (const char* card : {"B1 a 0 v=1", "E1 a 0 b 0 2", "A1 a b amp", "O1 a 0 b 0 m", "U1 a b 0 m",
                           "P1 a b 0 c d 0 m", "M1 d g s b n", "J1 d g s j", "W1 a b vc sw"}) {
    d = read_error(std::string("t\n") + card + "\n");
    EXPECT_NE(d.head.find("t.cir:2:1: error: "), std::string::npos) << d.head;
    EXPECT_NE(d.head.find(" is not supported ("), std::string::npos) << d.head;
  }
}

TEST(SpiceReaderDialect, DiodeModelsResolveInTheirScope) {
  Netlist n = read_ok(
      "diodes\n"
      ".param bvx=27\n"
      ".model dtvs D(IS=1e-14 BV={bvx} CJO=12p, IBV=1m)\n"
      ".model dsig d is=2e-14 n=1.1 mfg=NXP\n"
      ".subckt clamp a\n"
      ".model dsig D(IS=5e-15)\n"  // local: shadows the top level's inside the subcircuit
      "D1 a 0 dsig\n"
      ".ends\n"
      "D1 a 0 DTVS 2 off\n"
      "D2 0 a dsig area=3 ic=0.1\n"
      "X1 a clamp\n"
      ".temp 85\n");
  ASSERT_EQ(n.cards.size(), 3u);
  ASSERT_TRUE(n.cards[0].model);
  EXPECT_EQ(n.cards[0].model->name, "dtvs");
  EXPECT_EQ(n.cards[0].model->type, "d");
  ASSERT_NE(n.cards[0].model->param("bv"), nullptr);
  EXPECT_DOUBLE_EQ(n.cards[0].model->param("bv")->number, 27);
  EXPECT_DOUBLE_EQ(n.cards[0].model->param("ibv")->number, 1e-3);
  EXPECT_EQ(n.cards[0].model->param("bv")->loc.line, 3);
  ASSERT_EQ(n.cards[0].args.size(), 2u);
  EXPECT_DOUBLE_EQ(n.cards[0].args[0].number, 2);
  EXPECT_EQ(n.cards[0].args[1].word, "off");
  EXPECT_EQ(n.cards[1].model->param("n")->number, 1.1);
  EXPECT_EQ(n.cards[1].model->param("mfg"), nullptr);  // documentation only, dropped
  EXPECT_DOUBLE_EQ(n.cards[2].model->param("is")->number, 5e-15);
  for (const Card& c : n.cards) {  // .temp reaches every diode
    ASSERT_NE(c.param("temp"), nullptr) << c.name;
    EXPECT_DOUBLE_EQ(c.param("temp")->number, 85);
  }
  ASSERT_FALSE(n.warnings.empty());
  EXPECT_NE(n.warnings[0].find("'mfg' in .model dsig ignored"), std::string::npos) << n.warnings[0];
}

TEST(SpiceReaderErrors, DiodeModelErrorsPointAtTheModel) {
  Diag d = read_error("t\nD1 a 0 nomodel\n");
  EXPECT_EQ(d.head,
            "t.cir:2:8: error: unknown model 'nomodel' (no .model nomodel in this "
            "netlist or subcircuit)");
  d = read_error("t\n.model q1 d\n.model q1 npn(bf=100)\nD1 a 0 q1\n");
  EXPECT_NE(d.head.find("t.cir:3:8: error: model 'q1' defined twice"), std::string::npos) << d.head;
  d = read_error("t\n.model dm d(is 1e-14)\n");
  EXPECT_EQ(d.head.substr(0, 45), "t.cir:2:13: error: expected KEY=VALUE in .mod");
  d = read_error("t\n.model dm d(is=1e-14\n");
  EXPECT_NE(d.head.find("missing ')'"), std::string::npos) << d.head;
  d = read_error("t\nD1 a 0\n");
  EXPECT_NE(d.head.find("expected a model name"), std::string::npos) << d.head;
}

TEST(SpiceReaderErrors, TooFewNodes) {
  Diag d = read_error("t\nR1 a\n");
  EXPECT_EQ(d.head.substr(0, 50), "t.cir:2:5: error: too few nodes: resistor 'r1' nee");
  EXPECT_EQ(d.caret, 5);  // just after the last token
  d = read_error("t\nC1 a ic=0\n");
  EXPECT_EQ(d.head.substr(0, 45), "t.cir:2:6: error: too few nodes: capacitor 'c");
  EXPECT_EQ(d.caret, 6);  // at the key=value that took the node's place
  d = read_error("t\nK1 L1\n");
  EXPECT_EQ(d.head.substr(0, 40), "t.cir:2:6: error: too few element names:");
}

TEST(SpiceReaderErrors, DuplicateElementName) {
  Diag d = read_error("t\nR1 a b 1\nr1 b c 2\n");
  EXPECT_EQ(d.head, "t.cir:3:1: error: duplicate element name 'r1' (first defined at t.cir:2:1)");
  EXPECT_EQ(d.caret, 1);
  // After flattening: the top level's flattened-name card collides with x1's r1.
  d = read_error(
      "t\n"
      ".subckt s a\n"
      "R1 a 0 1\n"
      ".ends\n"
      "X1 n s\n"
      "R.X1.R1 n 0 1\n");
  EXPECT_EQ(d.head,
            "t.cir:6:1: error: duplicate element name 'x1.r1' (first defined at t.cir:3:1)");
  EXPECT_EQ(d.caret, 1);
}

TEST(SpiceReaderErrors, DuplicateInsideSubcircuitNamesInstance) {
  Diag d = read_error(
      "t\n"
      ".subckt s a\n"
      "R1 a 0 1\n"
      "R1 a 0 2\n"
      ".ends\n"
      "X7 n s\n");
  EXPECT_EQ(d.head,
            "t.cir:4:1: error: duplicate element name 'x7.r1' (first defined at t.cir:3:1)");
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_EQ(d.notes[0], " (in subcircuit instance 'x7' of 's' at t.cir:6:1)");
}

TEST(SpiceReaderErrors, UndefinedParameter) {
  Diag d = read_error("t\n.param a=1\nR1 a b {a + rx*2}\n");
  EXPECT_EQ(d.head, "t.cir:3:13: error: undefined parameter 'rx'");
  EXPECT_EQ(d.source, "R1 a b {a + rx*2}");
  EXPECT_EQ(d.caret, 13);
  d = read_error("t\n.param a=1 b={a*c}\n");
  EXPECT_EQ(d.head, "t.cir:2:17: error: undefined parameter 'c'");
  EXPECT_EQ(d.caret, 17);
}

TEST(SpiceReaderErrors, UndefinedParameterInCallOnContinuation) {
  Diag d = read_error("t\nV1 a 0 PWL(0 0\n+ 1n {vmax})\n");
  EXPECT_EQ(d.head, "t.cir:3:7: error: undefined parameter 'vmax'");
  EXPECT_EQ(d.source, "+ 1n {vmax})");
  EXPECT_EQ(d.caret, 7);
}

TEST(SpiceReaderErrors, RecursiveSubcircuit) {
  Diag d = read_error(
      "t\n"
      ".subckt a p\n"
      "X1 p b\n"
      ".ends\n"
      ".subckt b p\n"
      "X1 p a\n"
      ".ends\n"
      "Xtop n a\n");
  EXPECT_EQ(d.head, "t.cir:6:6: error: recursive subcircuit: a -> b -> a");
  EXPECT_EQ(d.caret, 6);
  ASSERT_EQ(d.notes.size(), 2u);
  EXPECT_EQ(d.notes[0], " (in subcircuit instance 'xtop.x1' of 'b' at t.cir:3:1)");
  EXPECT_EQ(d.notes[1], " (in subcircuit instance 'xtop' of 'a' at t.cir:8:1)");
}

TEST(SpiceReaderErrors, UnknownSubcircuit) {
  Diag d = read_error("t\nX1 a b nosuch r=1\n");
  EXPECT_EQ(d.head, "t.cir:2:8: error: unknown subcircuit 'nosuch'");
  EXPECT_EQ(d.caret, 8);
}

TEST(SpiceReaderErrors, WrongNodeCountForInstance) {
  const std::string defs = "t\n.subckt buf in out\nR1 in out 1\n.ends\n";
  Diag d = read_error(defs + "X1 a b c buf\n");
  EXPECT_EQ(d.head, "t.cir:5:8: error: 'x1': subcircuit 'buf' has 2 ports (in out), 3 nodes given");
  EXPECT_EQ(d.caret, 8);  // the first extra node
  d = read_error(defs + "X1 a buf\n");
  EXPECT_EQ(d.head, "t.cir:5:6: error: 'x1': subcircuit 'buf' has 2 ports (in out), 1 nodes given");
  EXPECT_EQ(d.caret, 6);  // the subcircuit name
  d = read_error(defs + "X1 a b buf gain=2\n");
  EXPECT_EQ(d.head, "t.cir:5:12: error: subcircuit 'buf' has no parameter 'gain'");
}

TEST(SpiceReaderErrors, MalformedNumber) {
  Diag d = read_error("t\nR1 a b 1.2.3\n");
  EXPECT_EQ(d.head, "t.cir:2:8: error: malformed number '1.2.3'");
  EXPECT_EQ(d.caret, 8);
  d = read_error("t\nR1 a b abc\n");
  EXPECT_EQ(
      d.head,
      "t.cir:2:8: error: expected a number, got 'abc' (no parameter of that name is defined)");
  EXPECT_EQ(d.caret, 8);
  d = read_error("t\nV1 a 0 PULSE(0 5 1n 2x3)\n");
  EXPECT_EQ(d.head, "t.cir:2:21: error: malformed number '2x3'");
  d = read_error("t\n.tran 1n 1.0.0\n");
  EXPECT_EQ(d.head, "t.cir:2:10: error: malformed number '1.0.0'");
  d = read_error("t\nC1 a b 1p ic=1..2\n");
  EXPECT_EQ(d.head, "t.cir:2:14: error: malformed number '1..2'");
}

TEST(SpiceReaderErrors, UnbalancedParenthesesAndBraces) {
  Diag d = read_error("t\nV1 a 0 PWL(0 0\n+ 1n 5\n");
  EXPECT_EQ(d.head, "t.cir:2:11: error: unbalanced '(': missing ')'");
  EXPECT_EQ(d.caret, 11);
  d = read_error("t\nV1 a 0 SIN(0 1 1k))\n");
  EXPECT_EQ(d.head, "t.cir:2:19: error: unbalanced ')': no '(' before it");
  EXPECT_EQ(d.caret, 19);
  d = read_error("t\nR1 a b {(1+2}\n");
  EXPECT_EQ(d.head, "t.cir:2:9: error: unbalanced '(' in expression: missing ')'");
  EXPECT_EQ(d.caret, 9);
  d = read_error("t\nR1 a b {1+2\n");
  EXPECT_EQ(d.head, "t.cir:2:8: error: unbalanced '{': missing '}'");
  EXPECT_EQ(d.caret, 8);
}

TEST(SpiceReaderErrors, MissingEnds) {
  Diag d = read_error("t\nR1 a 0 1\n.subckt amp in out\nR1 in out 1\n");
  EXPECT_EQ(d.head, "t.cir:3:1: error: missing '.ends' for subcircuit 'amp'");
  EXPECT_EQ(d.caret, 1);
  d = read_error("t\n.ends\n");
  EXPECT_EQ(d.head, "t.cir:2:1: error: '.ends' without '.subckt'");
}

TEST(SpiceReaderErrors, TranNeedsTwoValues) {
  Diag d = read_error("t\n.tran 1n\n");
  EXPECT_EQ(d.head, "t.cir:2:9: error: expected .tran TSTEP TSTOP [TSTART [TMAX]] [UIC]");
}

TEST(SpiceReaderErrors, StrayTokenAfterParams) {
  Diag d = read_error("t\nC1 a b 1p ic=0 5\n");
  EXPECT_EQ(d.head, "t.cir:2:16: error: unexpected '5' after key=value parameters");
}

// ---- issue 13: dialect of netlists from the wild ----

TEST(SpiceReaderDialect, DcAndAcAsKeyValue) {
  Netlist n = read_ok("t\nV1 a 0 dc=1 ac=1\nV2 b 0 dc = 2.5 AC 1 0\nI1 c 0 acmag=1 dc=1m\n");
  // dc= reads as DC VALUE; the AC forms are dropped with one warning.
  for (auto [name, v] : {std::pair{"v1", 1.0}, std::pair{"v2", 2.5}, std::pair{"i1", 1e-3}}) {
    const Card& c = card(n, name);
    ASSERT_EQ(c.args.size(), 2u) << name;
    EXPECT_EQ(c.args[0].word, "dc");
    EXPECT_EQ(c.args[1].number, v);
    EXPECT_TRUE(c.params.empty());
  }
  ASSERT_EQ(n.warnings.size(), 1u);
  EXPECT_NE(n.warnings[0].find("AC specification ignored"), std::string::npos);
  // The solver's source reads dc= (it was silently 0 V before issue 13).
  for (const char* name : {"v1", "v2", "i1"}) {
    const Card& c = card(n, name);
    auto e = find_element_kind(c.letter)->parse(c);
    ASSERT_TRUE(e) << e.status().message();
  }
}

TEST(SpiceReaderDialect, SourceFunctionsWithoutParentheses) {
  Netlist n = read_ok(
      "t\nV1 a 0 SIN 0 1 1K\nV2 b 0 PULSE 0 1 0 1n 1n 5u 10u\nV3 c 0 PWL 0 0 1u 1\n"
      "V4 d 0 DC 0.5 SIN 0.5 {2*0.25} 1meg AC 1\nV5 e 0 EXP 0 1 1u\n");
  EXPECT_EQ(card(n, "v1").args[0].word, "sin");
  EXPECT_EQ(card(n, "v1").args[0].call, (std::vector<double>{0, 1, 1e3}));
  EXPECT_EQ(card(n, "v2").args[0].call, (std::vector<double>{0, 1, 0, 1e-9, 1e-9, 5e-6, 1e-5}));
  EXPECT_EQ(card(n, "v3").args[0].call, (std::vector<double>{0, 0, 1e-6, 1}));
  const Card& v4 = card(n, "v4");
  ASSERT_EQ(v4.args.size(), 3u);  // dc, 0.5, sin(...); AC 1 dropped
  EXPECT_EQ(v4.args[2].call, (std::vector<double>{0.5, 0.5, 1e6}));
  EXPECT_EQ(card(n, "v5").args[0].word, "exp");
}

TEST(SpiceReaderDialect, GlobalNodesStayGlobalInSubcircuits) {
  Netlist n =
      read_ok("t\n.global vcc\n.subckt s a\nR1 vcc a 1\nR2 a mid 1\n.ends\nX1 in s\nV1 vcc 0 1\n");
  EXPECT_EQ(card(n, "x1.r1").nodes, (std::vector<std::string>{"vcc", "in"}));
  EXPECT_EQ(card(n, "x1.r2").nodes, (std::vector<std::string>{"in", "x1.mid"}));
}

TEST(SpiceReaderDialect, IfElseifElseTakesOneBranch) {
  const std::string body =
      ".if (sel == 1)\nR1 a 0 1\n.elseif (sel == 2 && 1)\nR2 a 0 2\n.if (0)\nR9 a 0 9\n"
      ".else\nR3 a 0 3\n.endif\n.else\nR4 a 0 4\n.endif\n";
  for (int sel : {1, 2, 3}) {
    Netlist n = read_ok("t\n.param sel=" + std::to_string(sel) + "\n" + body);
    std::vector<std::string> names;
    for (const Card& c : n.cards) names.push_back(c.name);
    const std::vector<std::vector<std::string>> want = {{"r1"}, {"r2", "r3"}, {"r4"}};
    EXPECT_EQ(names, want[sel - 1]) << "sel=" << sel;
  }
  EXPECT_NE(read_error("t\n.if (1)\nR1 a 0 1\n").head.find("missing '.endif'"), std::string::npos);
  EXPECT_NE(read_error("t\n.else\n").head.find("'.else' without '.if'"), std::string::npos);
  EXPECT_NE(read_error("t\n.if (1)\n.else\n.else\n.endif\n").head.find("after '.else'"),
            std::string::npos);
}

// ngspice reads a single '=' in a .if / .elseif condition as equality (`.elseif (select2 = 2)`
// in its examples; tests/cli/data/wild/dialect_if_single_equals.cir compares the branch taken
// with ngspice's); elsewhere a single '=' stays an error that says what to write.
TEST(SpiceReaderDialect, SingleEqualsIsEqualityInConditionsOnly) {
  const std::string body =
      ".if (select2 = 1)\nR1 a 0 1\n.elseif (select2 = 2)\nR2 a 0 2\n.else\nR3 a 0 3\n.endif\n";
  for (int sel : {1, 2, 3}) {
    Netlist n = read_ok("t\n.param select2=" + std::to_string(sel) + "\n" + body);
    ASSERT_EQ(n.cards.size(), 1u) << "select2=" << sel;
    EXPECT_EQ(n.cards[0].name, "r" + std::to_string(sel)) << "select2=" << sel;
  }
  // '=' binds as '==' does: below '+', above '&&'
  Netlist n = read_ok("t\n.param a=1 b=2\n.if (a + 1 = b && b = 2)\nR1 x 0 1\n.endif\n");
  EXPECT_EQ(n.cards.size(), 1u);
  const Diag d = read_error("t\n.param a=1\nR1 x 0 {a = 1}\n");
  EXPECT_EQ(d.head,
            "t.cir:3:11: error: '=' in an expression: equality is '==' (a single '=' means "
            "equality only in a .if / .elseif condition)");
}

TEST(SpiceReaderDialect, FuncAndOperatorsInParams) {
  Netlist n = read_ok(
      "t\n.func par(a,b) {a*b/(a+b)}\n.func twice(x) = 2*x\n"
      ".param r={par(2k, 2k)} s={twice(r) > 1k ? 1 : 0}\nR1 a 0 {twice(r)}\nR2 a 0 {s}\n");
  EXPECT_EQ(card(n, "r1").args[0].number, 2000.0);
  EXPECT_EQ(card(n, "r2").args[0].number, 1.0);
}

TEST(SpiceReaderDialect, LibSections) {
  const fs::path dir = fs::path(::testing::TempDir()) / "lib_sections";
  fs::create_directories(dir);
  std::ofstream(dir / "m.lib") << "* lib\n.lib tt\n.param r=1k\n.endl tt\n.lib ff\n.param "
                                  "r=500\nR9 x 0 1\n.endl\n";
  std::ofstream(dir / "top.cir") << "top\n.lib m.lib ff\n.lib mine\nR8 y 0 1\n.endl\nR1 a 0 "
                                    "{r}\n";
  auto n = read_spice_file((dir / "top.cir").string());
  ASSERT_TRUE(n) << n.status().message();
  std::vector<std::string> names;
  for (const Card& c : n->cards) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"r9", "r1"}));  // section ff only; 'mine' not called
  EXPECT_EQ(card(*n, "r1").args[0].number, 500.0);
  std::ofstream(dir / "bad.cir") << "bad\n.lib m.lib xx\n";
  auto bad = read_spice_file((dir / "bad.cir").string());
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("bad.cir:2:6: error: library '"), std::string::npos)
      << bad.status().message();
  EXPECT_NE(bad.status().message().find("has no section 'xx'"), std::string::npos);
}

TEST(SpiceReaderDialect, TemperatureReachesResistorsWithCoefficients) {
  Netlist n = read_ok(
      "t\n.temp 85\n.options tnom=25\nR1 a 0 1k tc1=1m\nR2 a 0 1k tc1=1m temp=0\nR3 a 0 1k\n");
  EXPECT_EQ(card(n, "r1").param("temp")->number, 85.0);
  EXPECT_EQ(card(n, "r1").param("tnom")->number, 25.0);
  EXPECT_EQ(card(n, "r2").param("temp")->number, 0.0);  // the card's own temp= wins
  EXPECT_EQ(card(n, "r3").param("temp"), nullptr);      // no coefficient: nothing to add
  EXPECT_TRUE(n.options.empty());                       // tnom consumed here
}

TEST(SpiceReaderDialect, InitialConditions) {
  Netlist n =
      read_ok("t\n.subckt s a\nR1 a in 1\n.ic v(in)=2\n.ends\nX1 p s\n.ic v(p)=1 V(q) = -0.5\n");
  ASSERT_EQ(n.initial_voltages.size(), 3u);  // in elaboration order: X1 comes first
  EXPECT_EQ(n.initial_voltages[0].node, "x1.in");
  EXPECT_EQ(n.initial_voltages[1].node, "p");
  EXPECT_EQ(n.initial_voltages[2].node, "q");
  EXPECT_EQ(n.initial_voltages[2].value, -0.5);
  Diag d = read_error("t\n.ic i(l1)=1\n");
  EXPECT_EQ(d.head, "t.cir:2:5: error: expected v(NODE)=VALUE in .ic, got 'i'");
}

TEST(SpiceReaderDialect, UnknownDotCardIsAnErrorAndWarningsComeFirst) {
  auto n = read_spice_text("t\n.print tran v(a)\n.step param r 1 2 1\n", "t.cir");
  ASSERT_FALSE(n);
  const std::string& m = n.status().message();
  const std::size_t warn = m.find("t.cir:2:1: warning: unsupported card '.print' ignored");
  const std::size_t err = m.find("t.cir:3:1: error: '.step' is not supported");
  ASSERT_NE(warn, std::string::npos) << m;
  ASSERT_NE(err, std::string::npos) << m;
  EXPECT_LT(warn, err);
}

}  // namespace
}  // namespace isolink
