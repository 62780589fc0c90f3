#include "config/yaml_reader.h"

#include <gtest/gtest.h>

namespace isolink::config {
namespace {

TEST(ParseQuantity, SuffixesAndUnits) {
  double v = 0;
  EXPECT_TRUE(parse_quantity("2.2n", Unit::kFarad, &v));
  EXPECT_DOUBLE_EQ(v, 2.2e-9);
  EXPECT_TRUE(parse_quantity("2.2nF", Unit::kFarad, &v));
  EXPECT_DOUBLE_EQ(v, 2.2e-9);
  EXPECT_TRUE(parse_quantity("49 ohm", Unit::kOhm, &v));
  EXPECT_DOUBLE_EQ(v, 49);
  EXPECT_TRUE(parse_quantity("10meg", Unit::kHertz, &v));
  EXPECT_DOUBLE_EQ(v, 10e6);
  EXPECT_TRUE(parse_quantity("1.5kohm", Unit::kOhm, &v));
  EXPECT_DOUBLE_EQ(v, 1500);
  EXPECT_TRUE(parse_quantity("150uH", Unit::kHenry, &v));
  EXPECT_DOUBLE_EQ(v, 150e-6);
  // Wrong unit, junk, and lengths without scale suffixes.
  EXPECT_FALSE(parse_quantity("2.2nH", Unit::kFarad, &v));
  EXPECT_FALSE(parse_quantity("abc", Unit::kOhm, &v));
  EXPECT_FALSE(parse_quantity("", Unit::kOhm, &v));
  EXPECT_TRUE(parse_quantity("12m", Unit::kMetre, &v));
  EXPECT_DOUBLE_EQ(v, 12);  // metres, never milli
  EXPECT_TRUE(parse_quantity("12 m", Unit::kMetre, &v));
  EXPECT_DOUBLE_EQ(v, 12);
  EXPECT_FALSE(parse_quantity("1.5k", Unit::kMetre, &v));
  EXPECT_FALSE(parse_quantity("12ft", Unit::kMetre, &v));
}

// The numbers come from the one scanner (base/si_number.h); the YAML rules stay on top of it.
TEST(ParseQuantity, SharedScannerWithYamlRules) {
  double v = 0;
  // A unit symbol that is also a scale letter reads as the unit: 2.2 F, not 2.2 femto.
  EXPECT_TRUE(parse_quantity("2.2f", Unit::kFarad, &v));
  EXPECT_EQ(v, 2.2);
  EXPECT_TRUE(parse_quantity("2.2ff", Unit::kFarad, &v));
  EXPECT_EQ(v, 2.2e-15);
  EXPECT_TRUE(parse_quantity("1s", Unit::kSecond, &v));
  EXPECT_EQ(v, 1.0);
  EXPECT_TRUE(parse_quantity("1ms", Unit::kSecond, &v));
  EXPECT_EQ(v, 1e-3);
  // The suffix set of the netlists: mil, t, RKM; the scale letters are exact decimals.
  EXPECT_TRUE(parse_quantity("4k7", Unit::kOhm, &v));
  EXPECT_EQ(v, 4700.0);
  EXPECT_TRUE(parse_quantity("2R2ohm", Unit::kOhm, &v));
  EXPECT_EQ(v, 2.2);
  EXPECT_TRUE(parse_quantity("3.8us", Unit::kSecond, &v));
  EXPECT_EQ(v, 3.8e-6);
  EXPECT_TRUE(parse_quantity("1t", Unit::kHertz, &v));
  EXPECT_EQ(v, 1e12);
  EXPECT_TRUE(parse_quantity("2 nF", Unit::kFarad, &v));  // a blank before the suffix
  EXPECT_EQ(v, 2e-9);
  EXPECT_TRUE(parse_quantity("-5V", Unit::kVolt, &v));
  EXPECT_EQ(v, -5.0);
  EXPECT_TRUE(parse_quantity(" +5 ", Unit::kVolt, &v));
  EXPECT_EQ(v, 5.0);
  // Still refused: a blank inside RKM or before an exponent, trailing junk, a bare 'e', no unit
  // words for plain numbers, scale suffixes on lengths and temperatures, infinities.
  EXPECT_FALSE(parse_quantity("4 k7", Unit::kOhm, &v));
  EXPECT_FALSE(parse_quantity("1 e5", Unit::kHertz, &v));
  EXPECT_FALSE(parse_quantity("1kohmx", Unit::kOhm, &v));
  EXPECT_FALSE(parse_quantity("2.2n f", Unit::kFarad, &v));
  EXPECT_FALSE(parse_quantity("1e", Unit::kNone, &v));
  EXPECT_FALSE(parse_quantity("1k", Unit::kNone, &v));
  EXPECT_TRUE(parse_quantity("1e3", Unit::kNone, &v));
  EXPECT_EQ(v, 1000.0);
  EXPECT_FALSE(parse_quantity("25m", Unit::kCelsius, &v));
  EXPECT_TRUE(parse_quantity("25 degc", Unit::kCelsius, &v));
  EXPECT_EQ(v, 25.0);
  EXPECT_FALSE(parse_quantity("1e400", Unit::kOhm, &v));
  EXPECT_FALSE(parse_quantity("inf", Unit::kOhm, &v));
  EXPECT_FALSE(parse_quantity("--1", Unit::kOhm, &v));
}

TEST(ReadMap, UnknownKeyNamesFileLineColumnAndKnownKeys) {
  auto doc = YamlDoc::from_text("cable:\n  length: 3\n  lenght: 4\n", "spec.yaml");
  ASSERT_TRUE(doc.ok());
  double length = 0;
  Status s = read_map(*doc, doc->root()["cable"], "cable",
                      {{"length", read_quantity(*doc, Unit::kMetre, Rule::kPositive, &length)}});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("spec.yaml:3:3: error: unknown key 'cable.lenght'"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("known keys: length"), std::string::npos);
  EXPECT_NE(s.message().find("   lenght: 4\n   ^"), std::string::npos) << s.message();
}

TEST(ReadMap, ValuesRulesAndChoices) {
  auto doc = YamlDoc::from_text("a: -1\nb: pvcx\nc: 2.2nH\nd: [x, y]\ne: 31\n", "t.yaml");
  ASSERT_TRUE(doc.ok());
  double a = 0, c = 0;
  std::string b;
  std::vector<std::string> d;
  int e = 0;
  auto one = [&](const char* key, FieldReader r) { return r(doc->root()[key], key); };
  Status sa = one("a", read_quantity(*doc, Unit::kMetre, Rule::kPositive, &a));
  EXPECT_NE(sa.message().find("t.yaml:1:4: error: key 'a' = -1: must be > 0"), std::string::npos)
      << sa.message();
  Status sb = one("b", read_choice(*doc, {"pp", "pvc"}, &b));
  EXPECT_NE(sb.message().find("key 'b': expected pp | pvc, found 'pvcx'"), std::string::npos);
  Status sc = one("c", read_quantity(*doc, Unit::kFarad, Rule::kPositive, &c));
  EXPECT_NE(sc.message().find("key 'c': expected a value in F"), std::string::npos) << sc.message();
  EXPECT_TRUE(one("d", read_text_list(*doc, &d)).ok());
  EXPECT_EQ(d, (std::vector<std::string>{"x", "y"}));
  Status se = one("e", read_int(*doc, 18, 30, &e));
  EXPECT_NE(se.message().find("key 'e' = 31: must be in 18..30"), std::string::npos);
}

TEST(YamlDoc, SyntaxErrorHasItsPosition) {
  auto doc = YamlDoc::from_text("a: [1, 2\nb: 3\n", "bad.yaml");
  ASSERT_FALSE(doc.ok());
  EXPECT_NE(doc.status().message().find("bad.yaml:"), std::string::npos);
  EXPECT_NE(doc.status().message().find("YAML syntax"), std::string::npos);
}

TEST(YamlDoc, MissingFileIsAnError) {
  auto doc = YamlDoc::load_file("/nonexistent/spec.yaml");
  ASSERT_FALSE(doc.ok());
  EXPECT_NE(doc.status().message().find("/nonexistent/spec.yaml: error: cannot open"),
            std::string::npos);
}

// An alias of a map or list inside its own anchor made the key check recurse until the stack
// overflowed (tests/fuzz), and nested aliases multiply the nodes to walk; both are refused where
// the alias is. Aliases of single values still read as the value.
TEST(YamlDoc, AliasOfAMapOrListIsRefusedWhereItIs) {
  auto cyclic = YamlDoc::from_text("name: x\nloop: &self {a: 1, b: *self}\n", "cyc.yaml");
  ASSERT_FALSE(cyclic.ok());
  EXPECT_NE(
      cyclic.status().message().find("cyc.yaml:2:23: error: '*self' is an alias of a map or list"),
      std::string::npos)
      << cyclic.status().message();
  // The fuzzer's input: the root map's anchor used inside it.
  auto fuzz = YamlDoc::from_text("&.0\nix: &.:\nd: 6.0\niz &.ix: *.0\n.0c", "fuzz.yaml");
  ASSERT_FALSE(fuzz.ok());
  EXPECT_NE(fuzz.status().message().find("'*.0' is an alias of a map or list"), std::string::npos)
      << fuzz.status().message();
  // 30 levels of doubling: 2^30 nodes if walked.
  std::string laughs = "l0: &l0 [x, x]\n";
  for (int i = 1; i < 30; ++i)
    laughs += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [*l" +
              std::to_string(i - 1) + ", *l" + std::to_string(i - 1) + "]\n";
  auto big = YamlDoc::from_text(laughs, "laughs.yaml");
  ASSERT_FALSE(big.ok());
  EXPECT_NE(big.status().message().find("laughs.yaml:2:10: error: '*l0' is an alias"),
            std::string::npos)
      << big.status().message();
  auto scalar = YamlDoc::from_text("r: &r 100\ns: *r\n", "ok.yaml");
  ASSERT_TRUE(scalar.ok()) << scalar.status().message();
  EXPECT_EQ(scalar->root()["s"].Scalar(), "100");
}

}  // namespace
}  // namespace isolink::config
