#include "netlists/link/link_spec.h"

#include <gtest/gtest.h>

namespace isolink::link {
namespace {

const char* kIssueExample = R"(name: xfmr-12m
tx: {device: bq79600, series_r: 49, bypass_c: 100p, termination: 1k,
     isolation: {type: transformer, part: HMU1228NL}}
rx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}
cable: {length: 12, material: pp, gauge: 24}
stimulus: {frames: ["stack-write reg=0x0100 data=02B778BC"]}
)";

TEST(LinkSpec, ReadsTheIssueExample) {
  auto s = read_link_spec_text(kIssueExample, "xfmr.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->name, "xfmr-12m");
  EXPECT_EQ(s->tx.device, "bq79600");
  EXPECT_DOUBLE_EQ(*s->tx.series_r, 49);
  EXPECT_DOUBLE_EQ(*s->tx.bypass_c, 100e-12);
  EXPECT_DOUBLE_EQ(*s->tx.termination, 1e3);
  EXPECT_EQ(s->tx.isolation.type, "transformer");
  EXPECT_EQ(s->tx.isolation.part, "HMU1228NL");
  EXPECT_EQ(s->rx.device, "bq7961x");
  EXPECT_EQ(s->rx.isolation.type, "cap");
  EXPECT_DOUBLE_EQ(s->rx.isolation.cap, 2.2e-9);
  EXPECT_DOUBLE_EQ(s->cable.length, 12);
  EXPECT_EQ(s->cable.material, "pp");
  EXPECT_EQ(s->cable.gauge, 24);
  ASSERT_EQ(s->stimulus.frames.size(), 1u);
  EXPECT_EQ(s->stimulus.to_script(), "stack-write reg=0x0100 data=02B778BC");
  // direction defaults to both: down first, then up.
  ASSERT_EQ(s->stimulus.directions.size(), 2u);
  EXPECT_EQ(s->stimulus.directions[0], Direction::kDown);
  EXPECT_EQ(s->stimulus.directions[1], Direction::kUp);
}

TEST(LinkSpec, AFiveLineSpecIsComplete) {
  auto s = read_link_spec_text("name: short\ncable: {length: 3}\n", "short.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->tx.device, "bq79600");  // the bridge drives the first hop
  EXPECT_EQ(s->rx.device, "bq7961x");
  EXPECT_EQ(s->tx.isolation.type, "cap");
  EXPECT_DOUBLE_EQ(s->tx.isolation.cap, 2.2e-9);  // docs/physics.md 4.2
  EXPECT_EQ(s->cable.material, "pp");
  EXPECT_EQ(s->cable.gauge, 24);
  EXPECT_DOUBLE_EQ(s->cable.temperature, 25);
  EXPECT_EQ(s->stimulus.to_script(), "stack-write reg=0x0100 data=02B778BC");
  EXPECT_DOUBLE_EQ(s->sim.tstep, 1e-9);
}

TEST(LinkSpec, StimulusItemsAndDirection) {
  auto s = read_link_spec_text(
      "stimulus:\n  tones: [wake]\n  frames: [\"single-read dev=2 reg=0x0215 bytes=12\"]\n"
      "  patterns: prbs7 bytes=4\n  direction: up\n",
      "st.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->stimulus.to_script(),
            "tone wake; single-read dev=2 reg=0x0215 bytes=12; pattern prbs7 bytes=4");
  ASSERT_EQ(s->stimulus.directions.size(), 1u);
  EXPECT_EQ(s->stimulus.directions[0], Direction::kUp);
}

// Each bad spec: the error names the file, line and column, and the key.
struct BadSpec {
  const char* text;
  const char* expect;
};

class LinkSpecErrors : public ::testing::TestWithParam<BadSpec> {};

TEST_P(LinkSpecErrors, NameFileLineAndKey) {
  auto s = read_link_spec_text(GetParam().text, "bad.yaml");
  ASSERT_FALSE(s.ok()) << GetParam().text;
  EXPECT_NE(s.status().message().find(GetParam().expect), std::string::npos)
      << s.status().message();
}

INSTANTIATE_TEST_SUITE_P(
    All, LinkSpecErrors,
    ::testing::Values(
        BadSpec{"name: a\ncabel: {length: 3}\n",
                "bad.yaml:2:1: error: unknown key 'cabel' in the top level"},
        BadSpec{"cable: {length: -3}\n",
                "bad.yaml:1:17: error: key 'cable.length' = -3: must be > 0"},
        BadSpec{"cable: {length: 3km}\n",
                "key 'cable.length': expected a number in m, found '3km'"},
        BadSpec{"rx: {isolation: {type: cap, cap: 2.2nH}}\n",
                "bad.yaml:1:34: error: key 'rx.isolation.cap': expected a value in F"},
        BadSpec{"tx: {device: bq76952}\n",
                "key 'tx.device': expected bq79600 | bq7961x | bq79606a, found 'bq76952'"},
        BadSpec{"tx:\n  isolation:\n    type: cap\n    part: HMU1228NL\n",
                "bad.yaml:4:11: error: key 'tx.isolation.part': only for a transformer"},
        BadSpec{"rx: {isolation: {type: capchoke, chokes: [a, b, c]}}\n",
                "key 'rx.isolation.chokes': one or two chokes, found 3"},
        BadSpec{"cable: {gauge: 40}\n", "key 'cable.gauge' = 40: must be in 18..30"},
        BadSpec{"cable: {material: ptfe}\n", "key 'cable.material': expected pp | pvc"},
        BadSpec{"stimulus: {direction: sideways}\n",
                "key 'stimulus.direction': expected down | up | both"},
        BadSpec{"stimulus: {}\n", "key 'stimulus': give at least one of frames"},
        BadSpec{"name: a/b\n", "key 'name' = 'a/b'"},
        BadSpec{"- a\n- b\n", "a link spec is a YAML map"},
        BadSpec{"tx: {series_r: [1, 2]}\n", "key 'tx.series_r': expected a value in ohm"},
        BadSpec{"tx: {isolation: {type: cap\n", "bad.yaml:"}));

TEST(LinkSpec, StimulusGapsGiveTheIdleBeforeEachFrame) {
  auto s = read_link_spec_text(
      "name: g\nstimulus: {frames: [\"raw 5A nocrc\", \"raw 35 nocrc err\"], "
      "gaps: [1u, 3.85us], direction: down}\n",
      "g.yaml");
  ASSERT_TRUE(s.ok()) << s.status().message();
  ASSERT_EQ(s->stimulus.gaps.size(), 2u);
  EXPECT_DOUBLE_EQ(s->stimulus.gaps[1], 3.85e-6);
  EXPECT_EQ(s->stimulus.to_script(), "gap 1e-06; raw 5A nocrc; gap 3.85e-06; raw 35 nocrc err");
  auto bad =
      read_link_spec_text("name: g\nstimulus: {frames: [\"raw 5A\"], gaps: [1u, 2u]}\n", "g.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("g.yaml:2:"), std::string::npos) << bad.status().message();
  EXPECT_NE(bad.status().message().find("2 gaps for 1 frames"), std::string::npos);
  auto neg =
      read_link_spec_text("name: g\nstimulus: {frames: [\"raw 5A\"], gaps: [-1u]}\n", "g.yaml");
  ASSERT_FALSE(neg.ok());
  EXPECT_NE(neg.status().message().find("must be a time >= 0"), std::string::npos)
      << neg.status().message();
}

}  // namespace
}  // namespace isolink::link
