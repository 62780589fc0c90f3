#include "eye/rules.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace isolink::eye {
namespace {

constexpr double ns = 1e-9;

std::string msg(const StatusOr<Rules>& r) {
  return r.ok() ? "" : r.status().message();
}

TEST(Rules, ShippedNames) {
  EXPECT_EQ(builtin_rule_names(), (std::vector<std::string>{"bq79600", "bq7961x", "tone"}));
  EXPECT_FALSE(builtin_rule_text("bq7961x").empty());
  EXPECT_TRUE(builtin_rule_text("nope").empty());
}

TEST(Rules, Bq7961x) {
  StatusOr<Rules> r = load_rules("bq7961x");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_EQ(r->name, "bq7961x");
  EXPECT_EQ(r->source, "eye/rules/bq7961x.yaml");
  EXPECT_FALSE(r->tone);
  EXPECT_DOUBLE_EQ(r->vth, 1.2);
  EXPECT_NEAR(r->pulse_time, 250 * ns, 1e-18);
  EXPECT_NEAR(r->merge_gap, 100 * ns, 1e-18);
  EXPECT_NEAR(r->min_pulse, 100 * ns, 1e-18);
  EXPECT_NEAR(r->transition_gap, 200 * ns, 1e-18);
  EXPECT_NEAR(r->edge_max, 60 * ns, 1e-18);
  EXPECT_NEAR(r->vend_offset, 20 * ns, 1e-18);
  ASSERT_EQ(r->width.size(), 2u);
  EXPECT_EQ(r->width[0].k, 1);
  EXPECT_NEAR(r->width[0].min, 220 * ns, 1e-18);
  EXPECT_NEAR(r->width[0].max, 280 * ns, 1e-18);
  EXPECT_EQ(r->width[1].k, 2);
  EXPECT_NEAR(r->width[1].min, 470 * ns, 1e-18);
  EXPECT_NEAR(r->width[1].max, 530 * ns, 1e-18);
  EXPECT_EQ(r->amplitude, AmplitudeRule::kBq7961x);
  EXPECT_DOUBLE_EQ(r->vstart_required(1.35), 1.6);
  EXPECT_DOUBLE_EQ(r->vstart_required(1.3), 1.7);
  EXPECT_DOUBLE_EQ(r->vstart_required(1.2), 1.7);
  EXPECT_DOUBLE_EQ(r->vend_min, 1.2);
  EXPECT_DOUBLE_EQ(r->droop_max, 1.0);
  EXPECT_DOUBLE_EQ(r->idle_level, 0.4);
  EXPECT_NEAR(r->tblank, 4e-6, 1e-18);
  EXPECT_TRUE(r->frame.sof);
  EXPECT_EQ(r->frame.sof_value, 1);
  EXPECT_EQ(r->frame.bit_order, BitOrder::kLsbFirst);
  EXPECT_EQ(r->window(2), &r->width[1]);
  EXPECT_EQ(r->window(3), nullptr);
}

TEST(Rules, Bq79600IsTheBridgeFlavour) {
  StatusOr<Rules> r = load_rules("bq79600");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_EQ(r->amplitude, AmplitudeRule::kBridge);
  EXPECT_DOUBLE_EQ(r->vstart_min, 1.8);
  EXPECT_DOUBLE_EQ(r->vend_min, 1.2);
  EXPECT_DOUBLE_EQ(r->vstart_required(1.25), 1.8);
  EXPECT_DOUBLE_EQ(r->vstart_required(2.0), 1.8);
}

TEST(Rules, Tone) {
  StatusOr<Rules> r = load_rules("tone");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_TRUE(r->tone);
  EXPECT_NEAR(r->pulse_time, 1e-6, 1e-18);
  ASSERT_EQ(r->width.size(), 1u);
  EXPECT_NEAR(r->width[0].min, 920 * ns, 1e-18);  // 1 us - 8 %
  EXPECT_NEAR(r->width[0].max, 1080 * ns, 1e-18);
}

const char* kMinimal = R"(name: mine
kind: data
vth: 1.2
timing: {pulse_time: 250n, merge_gap: 100n, min_pulse: 100n, transition_gap: 200n, edge_max: 60n, vend_offset: 20n}
width:
  - {class: 1, min: 220n, max: 280n}
amplitude: {rule: bridge, vend_min: 1.2, vstart_min: 1.8, droop_max: 1}
idle: {level: 0.4, tblank: 4u}
decode: {sof: false, sof_value: 1, bit_order: msb}
)";

TEST(Rules, ParsesAFullUserFile) {
  StatusOr<Rules> r = parse_rules(kMinimal, "mine.yaml");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_EQ(r->name, "mine");
  EXPECT_FALSE(r->frame.sof);
  EXPECT_EQ(r->frame.bit_order, BitOrder::kMsbFirst);
  EXPECT_EQ(r->width.size(), 1u);
  EXPECT_NEAR(r->tblank, 4e-6, 1e-18);
}

TEST(Rules, BaseOverridesOnlyTheKeysGiven) {
  StatusOr<Rules> r =
      parse_rules("base: bq7961x\namplitude:\n  vstart_min: 1.65\n", "x/strict.yaml");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_EQ(r->name, "strict");
  EXPECT_DOUBLE_EQ(r->vstart_min, 1.65);
  EXPECT_DOUBLE_EQ(r->vstart_min_low_vend, 1.7);
  EXPECT_NEAR(r->edge_max, 60 * ns, 1e-18);
  EXPECT_EQ(r->source, "x/strict.yaml");
}

TEST(Rules, SpiceSuffixesAndUnits) {
  StatusOr<Rules> r = parse_rules(
      "base: bq7961x\ntiming: {edge_max: 55ns, pulse_time: 2.5e-7}\nvth: 1.1V\n", "s.yaml");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_NEAR(r->edge_max, 55 * ns, 1e-18);
  EXPECT_NEAR(r->pulse_time, 250 * ns, 1e-18);
  EXPECT_DOUBLE_EQ(r->vth, 1.1);
}

// Rule files go through config's YAML reader: units are checked (a time in volts is refused), a
// key given twice is an error, and errors show the source line with a caret.
TEST(Rules, SharedYamlReaderRules) {
  StatusOr<Rules> r =
      parse_rules("base: bq7961x\ntiming: {edge_max: 55 ns}\nvth: 1100mV\n", "s.yaml");
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_EQ(r->edge_max, 55e-9);
  EXPECT_EQ(r->vth, 1.1);
  r = parse_rules("base: bq7961x\ntiming: {edge_max: 60nV}\n", "bad.yaml");
  EXPECT_NE(msg(r).find("bad.yaml:2:20: error: key 'timing.edge_max': expected a value in s"),
            std::string::npos)
      << msg(r);
  r = parse_rules("base: bq7961x\nvth: 1.1\nvth: 1.3\n", "bad.yaml");
  EXPECT_NE(msg(r).find("bad.yaml:3:1: error: key 'vth' is given twice (first at line 2)"),
            std::string::npos)
      << msg(r);
  r = parse_rules("base: bq7961x\nvth: -1\n", "bad.yaml");
  EXPECT_EQ(msg(r), "bad.yaml:2:1: error: vth = -1: must be > 0\n vth: -1\n ^");
}

TEST(Rules, LoadsAUserFileFromDisk) {
  const auto path = std::filesystem::temp_directory_path() / "isolink_eye_rules_test.yaml";
  {
    std::ofstream out(path);
    out << kMinimal;
  }
  StatusOr<Rules> r = load_rules(path.string());
  ASSERT_TRUE(r.ok()) << msg(r);
  EXPECT_EQ(r->name, "mine");
  std::filesystem::remove(path);
  StatusOr<Rules> missing = load_rules("no_such_rules");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(msg(missing).find("no_such_rules: error: no such rule set"), std::string::npos);
  EXPECT_NE(msg(missing).find("(bq79600, bq7961x, tone)"), std::string::npos);
  // A name longer than NAME_MAX: std::filesystem::exists threw out of load_rules before.
  const std::string long_name(300, 'r');
  StatusOr<Rules> too_long = load_rules(long_name);
  ASSERT_FALSE(too_long.ok());
  EXPECT_NE(msg(too_long).find(long_name + ": error: no such rule set"), std::string::npos);
}

struct BadCase {
  std::string yaml;
  std::string expect;  // substring of the message, which starts "bad.yaml:LINE:COL: error: "
};

TEST(Rules, BrokenFilesNameKeyAndLine) {
  const std::vector<BadCase> cases = {
      {"name: x\nkind: data\nvth: 1: 2\nidle: 1\n",
       "bad.yaml:3:7: error: YAML syntax: illegal map value"},
      {"base: bq7961x\ntiming:\n  edge_maxx: 60n\n",
       "bad.yaml:3:3: error: unknown key 'timing.edge_maxx'"},
      {"base: bq7961x\nvth: abc\n", "bad.yaml:2:6: error: key 'vth': expected a value in V"},
      {"base: bq7961x\ndecode:\n  sof: maybe\n",
       "bad.yaml:3:8: error: key 'decode.sof': expected true or false"},
      {"base: bq7961x\ndecode: {bit_order: middle}\n",
       "bad.yaml:2:21: error: key 'decode.bit_order': expected lsb | msb"},
      {"base: bq7961x\nwidth:\n  - {class: 1, min: 220n}\n",
       "bad.yaml:3:5: error: missing key 'width[0].max'"},
      {"base: bq9999\n", "bad.yaml:1:7: error: key 'base': 'bq9999' is not a shipped rule set"},
      {"base: tone\ndecode: {sof: true}\n", "bad.yaml:2:9: error: key 'decode': only data rules"},
      {"base: bq7961x\namplitude: {rule: bridge, vend_knee: 1.3}\n",
       "unknown key 'amplitude.vend_knee'"},
      {"- 1\n- 2\n", "bad.yaml:1:1: error: a rule file is a YAML map"},
  };
  for (const BadCase& c : cases) {
    StatusOr<Rules> r = parse_rules(c.yaml, "bad.yaml");
    ASSERT_FALSE(r.ok()) << c.yaml;
    EXPECT_NE(msg(r).find(c.expect), std::string::npos) << msg(r) << "\n  wanted: " << c.expect;
  }
  // a full file without base must name every key: drop one
  std::string no_edge = kMinimal;
  no_edge.replace(no_edge.find(" edge_max: 60n,"), 15, "");
  StatusOr<Rules> r = parse_rules(no_edge, "bad.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(msg(r).find("bad.yaml:4:9: error: missing key 'timing.edge_max'"), std::string::npos)
      << msg(r);
}

TEST(Rules, LimitsAreValidatedWithFieldValueAndRule) {
  const std::vector<BadCase> cases = {
      {"base: bq7961x\nvth: -1\n", "bad.yaml:2:1: error: vth = -1: must be > 0"},
      {"base: bq7961x\nwidth:\n  - {class: 1, min: 280n, max: 220n}\n",
       "bad.yaml:3:27: error: width[0]: min 2.8e-07 >= max 2.2e-07: a window needs min < max"},
      {"base: bq7961x\nwidth:\n  - {class: 1, min: 100n, max: 280n}\n",
       "must lie inside (1.25e-07, 3.75e-07)"},
      {"base: bq7961x\nwidth:\n  - {class: 1, min: 220n, max: 280n}\n  - {class: 1, min: 230n, "
       "max: 270n}\n",
       "bad.yaml:4:6: error: width[1].class = 1: class listed twice"},
      {"base: bq7961x\ntiming: {vend_offset: 150n}\n",
       "timing.vend_offset = 1.5e-07: must be >= 0 and < timing.min_pulse = 1e-07"},
      {"base: bq7961x\namplitude: {vend_knee: 1.1}\n",
       "bad.yaml:2:13: error: amplitude.vend_knee = 1.1: must be >= amplitude.vend_min = 1.2"},
      {"base: bq7961x\namplitude: {vstart_min_low_vend: 1.5}\n",
       "amplitude.vstart_min_low_vend = 1.5: must be >= amplitude.vstart_min = 1.6"},
      {"base: bq7961x\ndecode: {sof_value: 2}\n", "decode.sof_value = 2: must be 0 or 1"},
      {"base: bq7961x\nidle: {level: 1.5}\n", "idle.level = 1.5: must be below vth = 1.2"},
      {"base: bq7961x\ntiming: {edge_max: 0}\n", "timing.edge_max = 0: must be > 0"},
  };
  for (const BadCase& c : cases) {
    StatusOr<Rules> r = parse_rules(c.yaml, "bad.yaml");
    ASSERT_FALSE(r.ok()) << c.yaml;
    EXPECT_NE(msg(r).find(c.expect), std::string::npos) << msg(r) << "\n  wanted: " << c.expect;
  }
  Rules good = *load_rules("bq7961x");
  EXPECT_TRUE(validate_rules(good).ok());
  good.width[1].max = good.width[1].min;
  Status s = validate_rules(good);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(),
            "rules 'bq7961x': width[1]: min 4.7e-07 >= max 4.7e-07: a window needs min < max");
}

}  // namespace
}  // namespace isolink::eye
