// Pack specs: hops from files and inline, overrides merged key by key, repeat, the pack's traffic
// replacing the hops', devices filled in or checked, and errors at the right file:line:col.
#include "analysis/pack_spec.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace isolink::analysis {
namespace {

namespace fs = std::filesystem;

// A folder with a module spec; packs are written next to it.
class PackSpecTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = ::testing::TempDir() + "/pack_spec_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    write("module.yaml",
          "name: module\n"
          "tx: {device: bq7961x, isolation: {type: cap, cap: 2.2n}}\n"
          "rx: {isolation: {type: cap, cap: 2.2n}}\n"
          "cable: {length: 2, gauge: 24}\n"
          "stimulus: {frames: [\"stack-write reg=0x0100 data=02\"]}\n");
    write("bridge.yaml",
          "tx: {isolation: {type: transformer, part: HMU1228NL}}\n"
          "cable: {length: 0.5}\n");
  }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ + "/" + name) << text;
  }
  StatusOr<PackSpec> read(const std::string& text) {
    write("pack.yaml", text);
    return read_pack_spec_file(dir_ + "/pack.yaml");
  }
  std::string dir_;
};

TEST_F(PackSpecTest, HopsOverridesRepeatAndDevices) {
  StatusOr<PackSpec> p = read(
      "name: p\n"
      "hops:\n"
      "  - {spec: bridge.yaml}\n"
      "  - {spec: module.yaml, cable: {length: 2.5}, rx: {isolation: {cap: 4.7n}}}\n"
      "  - {spec: module.yaml, repeat: 3}\n"
      "  - spec: {tx: {isolation: {type: none}}, cable: {length: 0.05}}\n");
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_EQ(p->hops.size(), 6u);
  EXPECT_EQ(p->devices(), 6);
  EXPECT_FALSE(p->ring);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(p->hops[k].index, k + 1);
    EXPECT_EQ(p->hops[k].from, k);
    EXPECT_EQ(p->hops[k].to, k + 1);
  }
  // Hop 1 starts at the bridge: the spec leaves the device out, the pack fills it in.
  EXPECT_EQ(p->hops[0].spec.tx.device, "bq79600");
  EXPECT_EQ(p->hops[0].spec.rx.device, "bq7961x");
  EXPECT_EQ(p->hops[0].spec.tx.isolation.type, "transformer");
  // Overrides merge: the length and the rx cap change, the rest of the module stays.
  const link::LinkSpec& h2 = p->hops[1].spec;
  EXPECT_DOUBLE_EQ(h2.cable.length, 2.5);
  EXPECT_EQ(h2.cable.gauge, 24);
  EXPECT_DOUBLE_EQ(h2.rx.isolation.cap, 4.7e-9);
  EXPECT_EQ(h2.rx.isolation.type, "cap");
  EXPECT_DOUBLE_EQ(h2.tx.isolation.cap, 2.2e-9);
  EXPECT_EQ(h2.name, "module");
  EXPECT_EQ(p->hops[1].file, fs::path(dir_ + "/module.yaml").lexically_normal().string());
  // repeat: 3 identical hops, unchanged module length.
  for (int k = 2; k < 5; ++k) EXPECT_DOUBLE_EQ(p->hops[k].spec.cable.length, 2.0);
  // Inline: stack devices at both ends, its own cable.
  EXPECT_EQ(p->hops[5].spec.tx.device, "bq7961x");
  EXPECT_EQ(p->hops[5].spec.tx.isolation.type, "none");
  EXPECT_DOUBLE_EQ(p->hops[5].spec.cable.length, 0.05);
  EXPECT_TRUE(p->hops[5].file.empty());
}

TEST_F(PackSpecTest, RepeatedFirstHopHasTheBridgeOnlyOnce) {
  StatusOr<PackSpec> p = read("hops: [{spec: {cable: {length: 1}}, repeat: 3}]\n");
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_EQ(p->hops.size(), 3u);
  EXPECT_EQ(p->hops[0].spec.tx.device, "bq79600");
  EXPECT_EQ(p->hops[1].spec.tx.device, "bq7961x");
  EXPECT_EQ(p->hops[2].spec.tx.device, "bq7961x");
}

TEST_F(PackSpecTest, PackStimulusReplacesTheHopsTrafficAndRingReturn) {
  StatusOr<PackSpec> p = read(
      "stimulus: {frames: [\"single-read dev=2 reg=0x0215 n=2\"], direction: down}\n"
      "hops: [{spec: bridge.yaml}, {spec: module.yaml, stimulus: {direction: up}}]\n"
      "ring: true\n"
      "ring_return: {spec: bridge.yaml, cable: {length: 3}}\n"
      "timing: {timeout: 500u, device_delay: 4u}\n");
  ASSERT_TRUE(p.ok()) << p.status().message();
  ASSERT_EQ(p->hops.size(), 3u);
  EXPECT_EQ(p->devices(), 2);
  EXPECT_TRUE(p->ring);
  for (const HopSpec& h : p->hops) {
    ASSERT_EQ(h.spec.stimulus.frames.size(), 1u);
    EXPECT_EQ(h.spec.stimulus.frames[0], "single-read dev=2 reg=0x0215 n=2");
  }
  // The hop's own override still applies on top of the pack's traffic.
  EXPECT_EQ(p->hops[0].spec.stimulus.directions,
            std::vector<link::Direction>{link::Direction::kDown});
  EXPECT_EQ(p->hops[1].spec.stimulus.directions,
            std::vector<link::Direction>{link::Direction::kUp});
  const HopSpec& r = p->hops[2];
  EXPECT_TRUE(r.ring_return);
  EXPECT_EQ(r.index, 3);
  EXPECT_EQ(r.from, 0);
  EXPECT_EQ(r.to, 2);
  EXPECT_EQ(r.spec.tx.device, "bq79600");
  EXPECT_DOUBLE_EQ(r.spec.cable.length, 3.0);
  ASSERT_TRUE(p->timing.timeout.has_value());
  EXPECT_DOUBLE_EQ(*p->timing.timeout, 500e-6);
  EXPECT_DOUBLE_EQ(p->timing.device_delay, 4e-6);
  EXPECT_DOUBLE_EQ(p->timing.bridge_delay, 12e-6);
}

TEST_F(PackSpecTest, ErrorsNameThePackFileForOverrides) {
  StatusOr<PackSpec> p = read(
      "hops:\n"
      "  - {spec: bridge.yaml}\n"
      "  - {spec: module.yaml, cable: {lenght: 2.5}}\n");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("pack.yaml:3:33: error: unknown key 'cable.lenght'"),
            std::string::npos)
      << p.status().message();
  p = read("hops: [{spec: bridge.yaml}, {spec: module.yaml, cable: {length: -1}}]\n");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("pack.yaml:1:65: error: key 'cable.length'"),
            std::string::npos)
      << p.status().message();
}

TEST_F(PackSpecTest, ErrorsNameTheHopSpecForItsOwnKeys) {
  write("bad.yaml", "name: bad\ncable: {length: 2, colour: red}\n");
  StatusOr<PackSpec> p = read("hops: [{spec: bridge.yaml}, {spec: bad.yaml}]\n");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("bad.yaml:2:20: error: unknown key 'cable.colour'"),
            std::string::npos)
      << p.status().message();
}

TEST_F(PackSpecTest, DeviceThatContradictsThePackIsAnError) {
  // module.yaml names bq7961x at its tx end: not the bridge.
  StatusOr<PackSpec> p = read("hops: [{spec: module.yaml}]\n");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("module.yaml:2:14: error: key 'tx.device' = bq7961x: hop 1 "
                                      "starts at the bridge; its tx end is bq79600"),
            std::string::npos)
      << p.status().message();
}

TEST_F(PackSpecTest, StructuralErrors) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"hops: []\n", "pack.yaml:1:7: error: key 'hops': a list of hops"},
      {"hops: [{cable: {length: 1}}]\n", "pack.yaml:1:8: error: hops[0]: key 'spec' is missing"},
      {"hops: [{spec: nothere.yaml}]\n",
       "pack.yaml:1:15: error: hops[0]: key 'spec': cannot "
       "open the link spec"},
      {"hops: [{spec: bridge.yaml}]\nring: true\n",
       "pack.yaml:2:7: error: key 'ring' is true: give the return hop under 'ring_return'"},
      {"hops: [{spec: bridge.yaml}]\nring_return: {spec: bridge.yaml}\n",
       "pack.yaml:2:14: error: key 'ring_return' needs 'ring: true'"},
      {"hops: [{spec: bridge.yaml, repeat: 0}]\n", "pack.yaml:1:36: error: key 'hops[0].repeat'"},
      {"stack: bq79600\nhops: [{spec: bridge.yaml}]\n", "pack.yaml:1:8: error: key 'stack'"},
      {"hops: [{spec: bridge.yaml}]\ntiming: {timeout: 5}\n", ""},  // 5 s is valid
      {"hops: [{spec: bridge.yaml}]\ntiming: {timeout: 5V}\n",
       "pack.yaml:2:19: error: key 'timing.timeout'"},
  };
  for (const Case& c : cases) {
    StatusOr<PackSpec> p = read(c.text);
    if (*c.message == 0) {
      EXPECT_TRUE(p.ok()) << c.text << p.status().message();
      continue;
    }
    EXPECT_FALSE(p.ok()) << c.text;
    if (p.ok()) continue;
    EXPECT_NE(p.status().message().find(c.message), std::string::npos) << c.text << "\n"
                                                                       << p.status().message();
  }
}

TEST(PackSpecExample, SixteenModulesWithARing) {
  StatusOr<PackSpec> p =
      read_pack_spec_file(std::string(ISOLINK_EXAMPLES_DIR) + "/pack/pack_16.yaml");
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_EQ(p->devices(), 16);
  EXPECT_TRUE(p->ring);
  ASSERT_EQ(p->hops.size(), 17u);
  EXPECT_TRUE(p->hops[16].ring_return);
  EXPECT_DOUBLE_EQ(p->hops[0].spec.cable.length, 0.5);
  EXPECT_DOUBLE_EQ(p->hops[1].spec.cable.length, 0.05);  // on one PCB
  EXPECT_DOUBLE_EQ(p->hops[2].spec.cable.length, 0.3);   // jumper
  EXPECT_DOUBLE_EQ(p->hops[8].spec.cable.length, 2.5);   // rack to rack
  EXPECT_DOUBLE_EQ(p->hops[16].spec.cable.length, 4.0);  // the ring's return
  for (const HopSpec& h : p->hops) EXPECT_EQ(h.spec.stimulus.frames.size(), 2u);
}

}  // namespace
}  // namespace isolink::analysis
