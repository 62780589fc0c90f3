// TVS parts (netlists/link/parts.h, kind tvs): each built-in TVS, built as diodes by add_tvs and
// simulated by the solver, meets its data sheet's figures: VBR at the test current and VCL at
// IPP in DC (the two points derive() solves BV and RS from), the capacitance at 0 V (the charge
// a small constant current puts on it), and a unidirectional part's forward drop for a negative
// line. The figures come from the part files, each with its source; the tolerances are the
// model's own approximations (the breakdown current at -BV is IBV to within vt ln(1 + IS/IBV)).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "builtin_library.h"
#include "netlists/link/cards.h"
#include "netlists/link/expand.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/parts.h"
#include "netlists/spice_reader.h"
#include "netlists/spice_writer.h"
#include "solver/probe.h"
#include "solver/transient.h"

namespace isolink::link {
namespace {

using testing::builtin;

std::vector<const Part*> tvs_parts() {
  std::vector<const Part*> out;
  for (const Part& p : builtin().parts())
    if (p.kind == PartKind::Tvs) out.push_back(&p);
  return out;
}

// The DC voltage of a TVS from "line" to ground with a current i pushed into the line.
double dc_voltage(const TvsModel& m, double i) {
  std::vector<Card> cards = {make_card('i', "iin", {"0", "line"}, {number_arg(i)})};
  EXPECT_TRUE(add_tvs(cards, "dx", "line", "0", "tvs", m).ok());
  Circuit c;
  Status s = add_cards(c, cards);
  EXPECT_TRUE(s.ok()) << s.message();
  s = c.finalize();
  EXPECT_TRUE(s.ok()) << s.message();
  StatusOr<std::vector<double>> x = dc_operating_point(c);
  EXPECT_TRUE(x.ok()) << x.status().message();
  StatusOr<Probe> p = parse_probe(c, "v(line)");
  if (!x || !p) return NAN;
  return (*x)[p->a];
}

TEST(Tvs, TheLibraryHasTheDataSheetParts) {
  std::vector<std::string> names;
  for (const Part* p : tvs_parts()) names.push_back(p->number);
  for (const char* want : {"PESD2CAN", "ESD24VS2U", "ESDCAN24-2BLY"})
    EXPECT_NE(builtin().find(want), nullptr) << want;
  ASSERT_GE(names.size(), 3u);
  const Part* pesd = builtin().find("pesd2can");
  ASSERT_NE(pesd, nullptr);
  // Nexperia PESD2CAN Rev. 2, table 8: VRWM 24 V, VBR 28 V typ at 1 mA, VCL 41 V at 5 A, 25 pF.
  EXPECT_EQ(pesd->tvs.standoff, 24);
  EXPECT_EQ(pesd->tvs.breakdown, 28);
  EXPECT_EQ(pesd->tvs.clamp, 41);
  EXPECT_EQ(pesd->tvs.clamp_current, 5);
  EXPECT_DOUBLE_EQ(pesd->tvs.capacitance, 25e-12);
  EXPECT_TRUE(pesd->tvs.bidirectional);
  for (const char* key : {"standoff", "breakdown", "clamp", "capacitance"}) {
    const Figure* f = pesd->figure(key);
    ASSERT_NE(f, nullptr) << key;
    EXPECT_NE(f->source.find("data sheet"), std::string::npos) << key;
  }
}

TEST(Tvs, DcMeetsBreakdownAtTheTestCurrentAndClampAtIpp) {
  for (const Part* p : tvs_parts()) {
    const TvsModel& m = p->tvs;
    SCOPED_TRACE(p->number);
    EXPECT_NEAR(dc_voltage(m, m.breakdown_current), m.breakdown, 5e-3);
    EXPECT_NEAR(dc_voltage(m, m.clamp_current), m.clamp, 5e-3);
    // Below the standoff voltage it does not conduct: 1 uA needs more than VRWM.
    EXPECT_GT(dc_voltage(m, 1e-6), m.standoff);
    if (m.bidirectional) {
      EXPECT_NEAR(dc_voltage(m, -m.clamp_current), -m.clamp, 5e-3);
    } else {
      // Forward: a plain junction, IS 1e-14 and RS: vt ln(1 mA / IS) + 1 mA RS.
      const double vt = 1.380649e-23 * 300.15 / 1.602176634e-19;
      EXPECT_NEAR(dc_voltage(m, -1e-3), -(vt * std::log(1e-3 / m.is + 1) + 1e-3 * m.rs), 2e-3);
    }
  }
}

TEST(Tvs, CapacitanceAtZeroVoltsIsTheDataSheets) {
  for (const Part* p : tvs_parts()) {
    SCOPED_TRACE(p->number);
    // 1 uA for 100 ns: 0.1 pC, 4 mV on 25 pF; the junctions barely move from 0 V (C within
    // 0.2 %) and the leakage (gmin, IS) carries under 1e-13 A.
    std::vector<Card> cards = {make_card('i', "iin", {"0", "line"}, {number_arg(1e-6)})};
    ASSERT_TRUE(add_tvs(cards, "dx", "line", "0", "tvs", p->tvs).ok());
    Circuit c;
    ASSERT_TRUE(add_cards(c, cards).ok());
    ASSERT_TRUE(c.finalize().ok());
    StatusOr<Probe> probe = parse_probe(c, "v(line)");
    ASSERT_TRUE(probe.ok());
    TransientOptions opt{.tstep = 1e-9, .tstop = 100e-9, .uic = true};
    StatusOr<Waveform> w = run_transient(c, opt, {*probe});
    ASSERT_TRUE(w.ok()) << w.status().message();
    const double v = w->value_at(0, 100e-9);
    EXPECT_NEAR(1e-6 * 100e-9 / v, p->tvs.capacitance, 0.005 * p->tvs.capacitance);
  }
}

TEST(Tvs, ClampBelowWhatTheJunctionsGiveIsRefusedNamingTheFigure) {
  const std::string text = R"(part: BAD1
maker: test
kind: tvs
polarity: bidirectional
standoff: {value: 24, source: x}
breakdown: {value: 28, current: 1m, source: x}
clamp: {value: 28.2, current: 5, source: x}
capacitance: {value: 25p, source: x}
)";
  StatusOr<std::vector<Part>> parts = read_parts_text(text, "bad.yaml");
  ASSERT_FALSE(parts.ok());
  EXPECT_NE(parts.status().message().find("bad.yaml:7:"), std::string::npos)
      << parts.status().message();
  EXPECT_NE(parts.status().message().find("tvs.clamp = 28.2"), std::string::npos);
  // A voltage without its current is refused too.
  std::string no_current = text;
  no_current.replace(no_current.find("28, current: 1m,"), 16, "28,");
  parts = read_parts_text(no_current, "bad.yaml");
  ASSERT_FALSE(parts.ok());
  EXPECT_NE(parts.status().message().find("missing key 'current'"), std::string::npos)
      << parts.status().message();
}

// A link spec's esd: a TVS part becomes diodes on both lines at the end it names, written with
// its .model into the netlist, which the reader takes back (export-spice, circuit keys).
TEST(Tvs, LinkSpecEsdPartBecomesDiodesAndRoundTripsThroughSpice) {
  StatusOr<LinkSpec> spec = read_link_spec_text(R"(name: tvs
tx: {device: bq79600}
rx: {device: bq7961x, isolation: {type: cap, esd: PESD2CAN}}
cable: {length: 2}
stimulus: {frames: ["stack-write reg=0x0100 data=02"], direction: down}
)",
                                                "tvs.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  EXPECT_EQ(spec->rx.isolation.esd_part, "PESD2CAN");
  EXPECT_EQ(nonlinear_parts(*spec).size(), 1u);
  EXPECT_NE(linear_only(*spec, "the worst case").find("rx.isolation.esd: TVS PESD2CAN"),
            std::string::npos);
  StatusOr<ExpandedLink> x = expand_link(*spec, builtin(), Direction::kDown);
  ASSERT_TRUE(x.ok()) << x.status().message();
  int diodes = 0;
  for (const Card& c : x->netlist.cards) diodes += c.letter == 'd';
  EXPECT_EQ(diodes, 4);  // two lines, two junctions each
  EXPECT_NE(x->rx_bom.find("TVS PESD2CAN"), std::string::npos) << x->rx_bom;
  const std::string text = write_spice(x->netlist);
  EXPECT_NE(text.find(".model tvs_pesd2can d("), std::string::npos);
  StatusOr<Netlist> back = read_spice_text(text, "back.cir");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(write_spice(*back), text);

  // An unknown part, and a part of another kind, are errors at the key.
  for (const char* bad : {"NOPE123", "HMU1228NL"}) {
    std::string t = "rx: {isolation: {type: cap, esd: " + std::string(bad) + "}}\n";
    StatusOr<LinkSpec> s = read_link_spec_text(t, "bad.yaml");
    ASSERT_TRUE(s.ok()) << s.status().message();
    StatusOr<ExpandedLink> e = expand_link(*s, builtin(), Direction::kDown);
    ASSERT_FALSE(e.ok());
    EXPECT_NE(e.status().message().find("bad.yaml:1:34: error: rx.isolation.esd"),
              std::string::npos)
        << e.status().message();
  }
}

TEST(Tvs, PinClampsAddRailDiodesAtBothEnds) {
  StatusOr<LinkSpec> spec = read_link_spec_text(
      "tx: {pin_clamps: rails}\nrx: {pin_clamps: rails}\ncable: {length: 1}\n", "c.yaml");
  ASSERT_TRUE(spec.ok()) << spec.status().message();
  StatusOr<ExpandedLink> x = expand_link(*spec, builtin(), Direction::kDown);
  ASSERT_TRUE(x.ok()) << x.status().message();
  std::vector<std::string> diodes;
  for (const Card& c : x->netlist.cards)
    if (c.letter == 'd') diodes.push_back(c.name + ":" + c.nodes[0] + ">" + c.nodes[1]);
  const std::vector<std::string> want = {
      "dtxhp:txp>tx_cvdd", "dtxlp:0>txp", "dtxhn:txn>tx_cvdd", "dtxln:0>txn",
      "drxhp:rxp>rx_cvdd", "drxlp:0>rxp", "drxhn:rxn>rx_cvdd", "drxln:0>rxn"};
  EXPECT_EQ(diodes, want);
  StatusOr<LinkSpec> bad = read_link_spec_text("rx: {pin_clamps: zener}\n", "c.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("c.yaml:1:18: error"), std::string::npos)
      << bad.status().message();
}

}  // namespace
}  // namespace isolink::link
