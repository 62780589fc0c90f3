// Part library: every built-in part loads with a source per figure, and the models reproduce the
// data sheets' figures in simulated measurements (AC analysis): each choke's common-mode
// impedance at its rated frequency, common- and differential-mode inductance, the resonance;
// each transformer's OCL (open test) and leakage (short test). Plus loader errors and user
// folders.
#include "netlists/link/parts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "builtin_library.h"
#include "netlists/link/cards.h"
#include "solver/ac.h"

namespace isolink::link {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

using testing::builtin;

// |V| / 1 A at node "in" (I source "iin" from ground into "in") of cards plus the source.
class Impedance {
 public:
  explicit Impedance(std::vector<Card> cards) {
    cards.push_back(make_card('i', "iin", {"0", "in"}, {number_arg(0)}));
    Status s = add_cards(circuit_, cards);
    EXPECT_TRUE(s.ok()) << s.message();
    s = circuit_.finalize();
    EXPECT_TRUE(s.ok()) << s.message();
    auto ac = AcAnalysis::create(circuit_);
    EXPECT_TRUE(ac.ok()) << ac.status().message();
    if (ac) ac_ = std::make_unique<AcAnalysis>(std::move(*ac));
    auto p = parse_probe(circuit_, "v(in)");
    EXPECT_TRUE(p.ok());
    if (p) probe_ = *p;
  }
  std::complex<double> at(double f) {
    if (!ac_) return {};
    auto x = ac_->solve("iin", f);
    EXPECT_TRUE(x.ok()) << x.status().message();
    return x ? x->voltage(probe_) : std::complex<double>{};
  }
  std::complex<double> voltage(double f, const std::string& probe) {
    auto p = parse_probe(circuit_, probe);
    EXPECT_TRUE(p.ok()) << probe;
    auto x = ac_->solve("iin", f);
    return x && p ? x->voltage(*p) : std::complex<double>{};
  }

 private:
  Circuit circuit_;
  std::unique_ptr<AcAnalysis> ac_;
  Probe probe_;
};

// Common mode as data sheets measure it: both windings in parallel, inputs driven together,
// outputs together to ground.
Impedance choke_cm(const ChokeModel& m) {
  std::vector<Card> cards;
  EXPECT_TRUE(add_choke(cards, "x1", "in", "in", "0", "0", m).ok());
  return Impedance(cards);
}
// Differential mode: into one winding and back through the other, output ends joined.
Impedance choke_dm(const ChokeModel& m) {
  std::vector<Card> cards;
  EXPECT_TRUE(add_choke(cards, "x1", "in", "0", "j", "j", m).ok());
  return Impedance(cards);
}

std::vector<const Part*> of_kind(PartKind kind) {
  std::vector<const Part*> out;
  for (const Part& p : builtin().parts())
    if (p.kind == kind) out.push_back(&p);
  return out;
}

TEST(Parts, EveryBuiltinPartLoadsWithASourcePerFigure) {
  const PartLibrary& lib = builtin();
  for (const char* number : {"HMU1228NL", "HM2147NL", "SM91502AL", "CDEP99-102",
                             "ACT45B-510-2P-TL003", "ACT45B-101-2P-TL003", "744242471",
                             "1206J2K00222KXR", "PESD2CAN", "ESD24VS2U", "ESDCAN24-2BLY"})
    EXPECT_NE(lib.find(number), nullptr) << number;
  EXPECT_EQ(lib.parts().size(), 11u);
  EXPECT_TRUE(lib.notes().empty());
  EXPECT_EQ(of_kind(PartKind::Choke).size(), 3u);
  EXPECT_EQ(of_kind(PartKind::Transformer).size(), 4u);
  EXPECT_EQ(of_kind(PartKind::Capacitor).size(), 1u);
  EXPECT_EQ(of_kind(PartKind::Tvs).size(), 3u);
  EXPECT_EQ(PartLibrary::builtin_files().size(), 9u);
  for (const Part& p : lib.parts()) {
    EXPECT_FALSE(p.maker.empty()) << p.number;
    EXPECT_TRUE(p.loc.valid() && p.loc.line > 0) << p.number;
    EXPECT_FALSE(p.figures.empty()) << p.number;
    for (const Figure& f : p.figures) {
      EXPECT_FALSE(f.source.empty()) << p.number << " " << f.key;
      EXPECT_GT(f.value, 0) << p.number << " " << f.key;
    }
    if (p.kind == PartKind::Choke) {
      EXPECT_TRUE(p.choke.validate().ok()) << p.number;
      EXPECT_TRUE(p.cm_impedance && p.cm_frequency) << p.number;
    }
    if (p.kind == PartKind::Transformer) {
      EXPECT_TRUE(p.transformer.validate().ok()) << p.number;
    }
  }
  // Figures as the data files give them.
  const Part* cdep = lib.find("cdep99-102");  // case-insensitive
  ASSERT_NE(cdep, nullptr);
  EXPECT_DOUBLE_EQ(cdep->transformer.inductance, 618e-6);
  EXPECT_DOUBLE_EQ(cdep->transformer.leakage, 28.6e-6);
  EXPECT_DOUBLE_EQ(cdep->transformer.dcr, 1.34);
  EXPECT_DOUBLE_EQ(cdep->transformer.centre_tap_c, 51e-12);
  EXPECT_NEAR(cdep->transformer.k(), std::sqrt(1 - 28.6 / 618), 1e-15);
  EXPECT_DOUBLE_EQ(*cdep->rated_current, 0.31);
  EXPECT_DOUBLE_EQ(*cdep->isolation_voltage, 2500);
  const Part* hmu = lib.find("HMU1228NL");
  const Figure* ocl = hmu->figure("inductance");
  ASSERT_NE(ocl, nullptr);
  EXPECT_DOUBLE_EQ(*ocl->min, 150e-6);
  EXPECT_DOUBLE_EQ(*ocl->max, 370e-6);
  const Part* act = lib.find("ACT45B-510-2P-TL003");
  EXPECT_DOUBLE_EQ(act->choke.inductance, 51e-6);
  EXPECT_NEAR(act->choke.k, 1 - 0.15 / (2 * 51), 1e-15);  // stray = 2 L (1 - k)
  EXPECT_DOUBLE_EQ(*act->cm_impedance, 2800);
  EXPECT_DOUBLE_EQ(*act->cm_frequency, 10e6);
  EXPECT_TRUE(act->figure("loss_r")->fitted);
  const Part* cap = lib.find("1206J2K00222KXR");
  EXPECT_DOUBLE_EQ(cap->capacitor.capacitance, 2.2e-9);
  EXPECT_DOUBLE_EQ(cap->capacitor.tolerance, 0.1);
  EXPECT_DOUBLE_EQ(cap->capacitor.voltage_rating, 2000);
  EXPECT_NEAR(*cap->figure("capacitance")->min, 1.98e-9, 1e-21);
}

TEST(Parts, ChokeCommonModeImpedanceMatchesTheDataSheet) {
  for (const Part* p : of_kind(PartKind::Choke)) {
    Impedance z = choke_cm(p->choke);
    const double model = std::abs(z.at(*p->cm_frequency));
    std::printf("[ zcm ] %-20s |Zcm(%g MHz)| model %.1f ohm, data sheet %.1f ohm (%+.2f %%)\n",
                p->number.c_str(), *p->cm_frequency / 1e6, model, *p->cm_impedance,
                100 * (model / *p->cm_impedance - 1));
    EXPECT_NEAR(model, *p->cm_impedance, 0.2 * *p->cm_impedance) << p->number;
    // The fit is exact up to the solver's rounding.
    EXPECT_NEAR(model, *p->cm_impedance, 1e-6 * *p->cm_impedance) << p->number;
  }
}

TEST(Parts, ChokeCommonModeIsLOnePlusKAndDifferentialLOneMinusK) {
  // At 100 kHz the winding C and loss R are negligible: per line (equal currents) the common
  // mode sees L(1+k) (paralleled windings: half of it), the differential loop 2 L(1-k).
  const double f = 100e3, w = 2 * kPi * f;
  for (const Part* p : of_kind(PartKind::Choke)) {
    const ChokeModel& m = p->choke;
    const double lcm_line = 2 * choke_cm(m).at(f).imag() / w;
    const double ldm_line = choke_dm(m).at(f).imag() / w / 2;
    std::printf(
        "[ lcm ] %-20s CM per line %.4g uH (L(1+k) %.4g), DM per line %.4g nH "
        "(L(1-k) %.4g)\n",
        p->number.c_str(), lcm_line * 1e6, m.inductance * (1 + m.k) * 1e6, ldm_line * 1e9,
        m.inductance * (1 - m.k) * 1e9);
    EXPECT_NEAR(lcm_line, m.inductance * (1 + m.k), 0.01 * m.inductance * (1 + m.k)) << p->number;
    EXPECT_NEAR(ldm_line, m.inductance * (1 - m.k), 0.02 * m.inductance * (1 - m.k)) << p->number;
    // The data sheet's stray (differential) inductance is the loop: 2 L (1 - k).
    if (const Figure* lk = p->figure("leakage"); lk && lk->measured == "differential") {
      EXPECT_NEAR(2 * ldm_line, lk->value, 0.02 * lk->value) << p->number;
    }
    // DC: each winding is its DCR; the paralleled pair half of it.
    EXPECT_NEAR(choke_cm(m).at(0).real(), m.dcr / 2, 1e-3 * m.dcr) << p->number;
  }
}

TEST(Parts, ChokeImpedancePeaksAtSelfResonanceAndFallsPastIt) {
  for (const Part* p : of_kind(PartKind::Choke)) {
    const ChokeModel& m = p->choke;
    Impedance z = choke_cm(m);
    const double f0 = 1 / (2 * kPi * std::sqrt(m.inductance * (1 + m.k) / 2 * 2 * m.winding_c));
    double peak = 0, f_peak = 0;
    std::vector<std::pair<double, double>> sweep;
    for (double f = f0 / 30; f <= f0 * 30; f *= std::pow(10.0, 0.02)) {
      const double mag = std::abs(z.at(f));
      sweep.push_back({f, mag});
      if (mag > peak) peak = mag, f_peak = f;
    }
    std::printf("[ srf ] %-20s peak %.0f ohm at %.2f MHz (f0 %.2f MHz); %.0f ohm at 10 f0\n",
                p->number.c_str(), peak, f_peak / 1e6, f0 / 1e6, std::abs(z.at(10 * f0)));
    EXPECT_NEAR(f_peak, f0, 0.06 * f0) << p->number;
    // Below resonance it rises, past it it falls (capacitive, 1/f): strictly monotonic.
    for (size_t i = 1; i < sweep.size(); ++i) {
      if (sweep[i].first < 0.9 * f_peak) {
        EXPECT_GT(sweep[i].second, sweep[i - 1].second);
      }
      if (sweep[i - 1].first > 1.1 * f_peak) {
        EXPECT_LT(sweep[i].second, sweep[i - 1].second);
      }
    }
    EXPECT_LT(std::abs(z.at(10 * f0)), peak / 3) << p->number;  // low Q: ferrite loss
    EXPECT_NEAR(std::abs(z.at(100 * f0)) * 100 * 2 * kPi * f0 * 2 * m.winding_c, 1.0, 0.01)
        << p->number << ": far past resonance |Z| = 1 / (w 2 Cw)";
  }
}

// Open test: the primary's inductance with the secondary open; short test: with the secondary
// shorted. L = Im(Z) / w (the DCR is real).
TEST(Parts, TransformerOpenAndShortTestsGiveOclAndLeakage) {
  const double f = 100e3, w = 2 * kPi * f;
  for (const Part* p : of_kind(PartKind::Transformer)) {
    const TransformerModel& m = p->transformer;
    std::vector<Card> open, shorted;
    ASSERT_TRUE(add_transformer(open, "t1", "in", "0", "sp", "sn", m).ok());
    ASSERT_TRUE(add_transformer(shorted, "t1", "in", "0", "s", "s", m).ok());
    const double ocl = Impedance(open).at(f).imag() / w;
    const double leak = Impedance(shorted).at(f).imag() / w;
    std::printf(
        "[ xfmr ] %-12s OCL model %.2f uH vs %.2f uH (%+.3f %%); leakage %.4f uH vs "
        "%.4f uH (%+.3f %%)\n",
        p->number.c_str(), ocl * 1e6, m.inductance * 1e6, 100 * (ocl / m.inductance - 1),
        leak * 1e6, m.leakage * 1e6, 100 * (leak / m.leakage - 1));
    EXPECT_NEAR(ocl, m.inductance, 0.01 * m.inductance) << p->number;
    EXPECT_NEAR(leak, m.leakage, 0.02 * m.leakage) << p->number;
    // The data file's figures themselves (the model is built from them).
    EXPECT_NEAR(ocl, p->figure("inductance")->value, 0.01 * p->figure("inductance")->value);
    if (p->figure("leakage")->measured == "shorted") {
      EXPECT_NEAR(leak, p->figure("leakage")->value, 0.02 * p->figure("leakage")->value);
    }
  }
}

TEST(Parts, TransformerIsOneToOneAndTheCentreTapSitsInTheMiddle) {
  // Secondary open and grounded at sn: V(sp) / V(in) = M / L = k; the centre tap at half of it.
  const Part* p = builtin().find("CDEP99-102");
  ASSERT_NE(p, nullptr);
  TransformerModel m = p->transformer;
  m.winding_c = 0;
  m.dcr = 0;
  m.centre_tap_c = 1e-18;  // keeps the tap, loads it with nothing
  std::vector<Card> cards;
  ASSERT_TRUE(add_transformer(cards, "t1", "in", "0", "sp", "0", m).ok());
  Impedance z(cards);
  const double f = 100e3;
  const std::complex<double> vin = z.at(f);
  const std::complex<double> ratio = z.voltage(f, "v(sp)") / vin;
  EXPECT_NEAR(ratio.real(), m.k(), 1e-6);
  EXPECT_NEAR(ratio.imag(), 0, 1e-6);
  EXPECT_NEAR(std::abs(z.voltage(f, "v(t1.ct)") / vin), m.k() / 2, 1e-3);
}

TEST(Parts, BuildersEmitSpiceStyleCards) {
  const ChokeModel m{51e-6, 0.998, 0.5, 1e-12, 6e3};
  std::vector<Card> cards;
  ASSERT_TRUE(add_choke(cards, "LC1", "AP", "an", "bp", "bn", m).ok());
  ASSERT_EQ(cards.size(), 9u);
  for (const Card& c : cards) {
    EXPECT_EQ(c.letter, c.name[c.name.find('.') + 1]) << c.name;
    EXPECT_EQ(c.node_locs.size(), c.nodes.size());
    EXPECT_EQ(c.ref_locs.size(), c.refs.size());
  }
  EXPECT_EQ(cards[0].name, "lc1.lp");
  EXPECT_EQ(cards[0].nodes, (std::vector<std::string>{"ap", "lc1.mp"}));
  const Card& k = cards.back();
  EXPECT_EQ(k.letter, 'k');
  EXPECT_EQ(k.refs, (std::vector<std::string>{"lc1.lp", "lc1.ln"}));
  EXPECT_DOUBLE_EQ(k.args.at(0).number, 0.998);
  // Bad models are refused with the field named.
  Status s = add_choke(cards, "x", "a", "b", "c", "d", ChokeModel{51e-6, 1.0, 0, 0, 0});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("choke.k = 1: must satisfy 0 < k < 1"), std::string::npos)
      << s.message();
  s = add_transformer(cards, "t", "a", "b", "c", "d", TransformerModel{100e-6, 100e-6, 0, 0, 0});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("transformer.leakage"), std::string::npos) << s.message();
  std::vector<Card> ct;
  ASSERT_TRUE(
      add_transformer(ct, "t", "a", "b", "c", "d", builtin().find("CDEP99-102")->transformer).ok());
  int inductors = 0, couplings = 0;
  for (const Card& c : ct) inductors += c.letter == 'l', couplings += c.letter == 'k';
  EXPECT_EQ(inductors, 3);  // primary and two secondary halves
  EXPECT_EQ(couplings, 3);
}

// Loader errors: file, line, column, the key and what is wrong.
std::string load_error(const std::string& text) {
  StatusOr<std::vector<Part>> r = read_parts_text(text, "bad.yaml");
  EXPECT_FALSE(r.ok()) << text;
  return r.ok() ? "" : r.status().message();
}

const char* kGoodChoke =
    "part: MY-CHOKE\n"
    "maker: Acme\n"
    "kind: choke\n"
    "inductance: 51u\n"
    "leakage: {value: 0.3u, measured: shorted, source: measured}\n"
    "dcr: 0.2\n"
    "winding_c: 2p\n"
    "loss_r: 3k\n";

TEST(Parts, LoadErrorsNameFileLineColumnAndKey) {
  StatusOr<std::vector<Part>> ok = read_parts_text(kGoodChoke, "good.yaml");
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_NEAR(ok->at(0).choke.k, std::sqrt(1 - 0.3 / 51), 1e-15);

  auto has = [](const std::string& msg, const std::string& want) {
    EXPECT_NE(msg.find(want), std::string::npos) << "want: " << want << "\nin:\n" << msg;
  };
  std::string base = kGoodChoke;
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  has(load_error(with("dcr: 0.2", "dcr: -0.2")),
      "bad.yaml:6:6: error: key 'dcr' = -0.2: must be >= 0");
  has(load_error(with("dcr: 0.2", "dcr: -0.2")), " dcr: -0.2\n      ^");  // caret under the value
  has(load_error(with("inductance: 51u", "inductance: 51uF")),
      "bad.yaml:4:13: error: key 'inductance': expected a value in H");
  has(load_error(base + "colour: blue\n"),
      "bad.yaml:9:1: error: unknown key 'colour' in the top level (known keys: part, maker");
  has(load_error(base + "capacitance: 1n\n"),
      "bad.yaml:9:1: error: key 'capacitance' does not apply to a choke");
  has(load_error(with("winding_c: 2p\n", "")),
      "bad.yaml:1:1: error: part 'MY-CHOKE': missing key 'winding_c'");
  has(load_error(with("kind: choke", "kind: chokes")),
      "bad.yaml:3:7: error: key 'kind': expected choke | transformer | capacitor | tvs, found "
      "'chokes'");
  has(load_error(with("measured: shorted, ", "")),
      "bad.yaml:5:10: error: key 'leakage': missing key 'measured'");
  has(load_error(with("leakage: {value: 0.3u,", "leakage: {value: 60u,")),
      "bad.yaml:5:10: error: key 'leakage' = 60 uH: must be below the inductance 51 uH");
  has(load_error(with("loss_r: 3k", "loss_r: fit")),
      "bad.yaml:8:9: error: key 'loss_r': 'fit' needs cm_impedance");
  has(load_error(base + "cm_impedance: {value: 2k, frequency: 10MHz, source: x}\n"),
      "bad.yaml:9:40: error: key 'cm_impedance.frequency': '10MHz' reads as milli");
  has(load_error(base + "cm_impedance: 2k\n"), "key 'cm_impedance': give {value: ..., frequency:");
  has(load_error(with("inductance: 51u", "inductance: {value: 51u, min: 60u}")),
      "bad.yaml:4:21: error: key 'inductance': value 51u is below its min 60u");
  has(load_error(
          std::string("- ") +
          "part: A\n  maker: B\n  kind: capacitor\n  capacitance: 1n\n"
          "- part: a\n  maker: B\n  kind: capacitor\n  capacitance: {value: 1n, tolerance: 10}\n"),
      "bad.yaml:8:39: error: key '[1].capacitance.tolerance': expected a percentage");
  has(load_error("- part: A\n  maker: B\n  kind: capacitor\n  capacitance: 1n\n"
                 "- part: a\n  maker: B\n  kind: capacitor\n  capacitance: 2n\n"),
      "bad.yaml:5:3: error: part 'a' is defined twice in this file (first at line 1)");
  has(load_error("part: [x\n"), "bad.yaml:");
  has(load_error("part: [x\n"), "YAML syntax");
  has(load_error("just text\n"), "bad.yaml:1:1: error: a part file is one part");
  // A winding capacitance too small to reach the data sheet's impedance cannot be fitted.
  has(load_error(with("loss_r: 3k", "loss_r: fit\ncm_impedance: {value: 50k, frequency: 10meg}")),
      "bad.yaml:8:9: error: key 'loss_r': cannot fit: without loss |Zcm| at 10 MHz is only");
}

class TempDir {
 public:
  explicit TempDir(const std::string& tag = "a") {
    path_ = fs::temp_directory_path() /
            ("isolink_parts_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
             "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" + tag);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name) << text;
    return (path_ / name).string();
  }
  std::string str() const { return path_.string(); }

 private:
  fs::path path_;
};

TEST(Parts, UserFolderAddsPartsAndOverridesBuiltinOnes) {
  TempDir dir;
  const std::string file = dir.write(
      "mine.yaml",
      "- part: act45b-510-2p-tl003\n"  // same number, other case: overrides the built-in one
      "  maker: TDK\n"
      "  kind: choke\n"
      "  inductance: {value: 60u, source: our measurement}\n"
      "  leakage: {value: 0.2u, measured: differential, source: our measurement}\n"
      "  dcr: 0.8\n"
      "  winding_c: 1p\n"
      "  loss_r: fit\n"
      "  cm_impedance: {value: 3k, frequency: 10meg, source: our measurement}\n"
      "- part: MY-XFMR\n"
      "  maker: Acme\n"
      "  kind: transformer\n"
      "  inductance: 500u\n"
      "  leakage: {value: 2u, measured: shorted}\n"
      "  dcr: 1\n"
      "  winding_c: 5p\n");
  dir.write("notes.txt", "not a part file");
  StatusOr<PartLibrary> lib = PartLibrary::load({dir.str()});
  ASSERT_TRUE(lib.ok()) << lib.status().message();
  EXPECT_EQ(lib->parts().size(), 12u);
  const Part* act = lib->find("ACT45B-510-2P-TL003");
  ASSERT_NE(act, nullptr);
  EXPECT_DOUBLE_EQ(act->choke.inductance, 60e-6);
  EXPECT_EQ(act->loc.file->path, file);
  EXPECT_EQ(act->overrides.rfind("netlists/parts/tdk_act45b.yaml:", 0), 0u) << act->overrides;
  ASSERT_EQ(lib->notes().size(), 1u);
  EXPECT_NE(lib->notes()[0].find(file + ":1:3: note: part act45b-510-2p-tl003 overrides the one "
                                        "at netlists/parts/tdk_act45b.yaml:"),
            std::string::npos)
      << lib->notes()[0];
  EXPECT_NEAR(std::abs(choke_cm(act->choke).at(10e6)), 3000, 3e-3);
  EXPECT_NE(lib->find("my-xfmr"), nullptr);
  // A later folder overrides an earlier one; a single file works as well.
  TempDir second("b");
  second.write("z.yaml",
               "part: MY-XFMR\nmaker: Other\nkind: transformer\ninductance: 400u\n"
               "leakage: {value: 2u, measured: shorted}\ndcr: 1\nwinding_c: 5p\n");
  lib = PartLibrary::load({file, second.str()});
  ASSERT_TRUE(lib.ok()) << lib.status().message();
  EXPECT_EQ(lib->find("MY-XFMR")->maker, "Other");
  EXPECT_EQ(lib->notes().size(), 2u);
}

TEST(Parts, BadUserFolderOrFileIsAnError) {
  StatusOr<PartLibrary> lib = PartLibrary::load({"/nonexistent/isolink/parts"});
  ASSERT_FALSE(lib.ok());
  EXPECT_EQ(lib.status().message(),
            "/nonexistent/isolink/parts: error: no such part library folder (or file)");
  TempDir dir;
  std::string text = kGoodChoke;
  text.replace(text.find("dcr: 0.2"), 8, "dcr: -1");
  const std::string file = dir.write("bad.yaml", text);
  lib = PartLibrary::load({dir.str()});
  ASSERT_FALSE(lib.ok());
  EXPECT_EQ(lib.status().message().rfind(file + ":6:6: error: key 'dcr' = -1: must be >= 0", 0), 0u)
      << lib.status().message();
}

}  // namespace
}  // namespace isolink::link
