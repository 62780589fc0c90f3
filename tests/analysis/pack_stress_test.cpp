// isolink stress on a pack (analysis/pack_stress.h): the chain after a fault that stops a hop,
// against the ring's break cases and the timing formulas worked by hand (README, "Packs").
#include "analysis/pack_stress.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace isolink::analysis {
namespace {

using V = std::vector<int>;

// Four devices on 1 m hops of a cable with explicit per-metre l and c (velocity
// 1 / sqrt(500n * 50p) = 2e8 m/s: 5 ns per hop), a ring return of 1 m when ring.
StatusOr<PackSpec> four_devices(bool ring) {
  std::string text = "stimulus: {frames: [\"stack-write reg=0x0100 data=02\"]}\nhops:\n";
  for (int k = 0; k < 4; ++k) text += "  - spec: {cable: {length: 1, l: 500n, c: 50p}}\n";
  if (ring) text += "ring: true\nring_return: {spec: {cable: {length: 1, l: 500n, c: 50p}}}\n";
  return read_pack_spec_text(text, ::testing::TempDir() + "/pack_stress.yaml");
}

// Hop 2 stops: device 1 stays on the normal side; the ring reaches 4, 3, 2 round the other way.
// A command reaches device k after 12 us + 3 us per device before it + 5 ns per hop on the way:
// normally 12 + 3 (k - 1) us + 5k ns, reversed 12 + 3 (4 - k) us + 5 (5 - k) ns. Device 2 is
// the one the re-route delays: reversed 18.015 us against 15.010 us normally, 3.005 us more.
TEST(PackStress, RerouteAroundABrokenHopIsTheHandWorkedTiming) {
  StatusOr<PackSpec> p = four_devices(true);
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok()) << t.status().message();
  const HopFault f = reroute_of(*p, *t, 2);
  EXPECT_TRUE(f.breaks_hop);
  EXPECT_EQ(f.reroute.broken, 2);
  EXPECT_EQ(f.reroute.normal_side, V{1});
  EXPECT_EQ(f.reroute.reverse_side, (V{4, 3, 2}));
  EXPECT_TRUE(f.unreached.empty());
  EXPECT_NEAR(f.reroute_delay_s, 3.005e-6, 1e-12);
  // The top hop: device 4 alone goes the other way, and gets its command earlier (12.005 us
  // against 21.020 us): the re-route costs nothing.
  EXPECT_NEAR(reroute_of(*p, *t, 4).reroute_delay_s, 0.0, 1e-15);
}

TEST(PackStress, WithoutARingTheDevicesPastTheFaultAreUnreached) {
  StatusOr<PackSpec> p = four_devices(false);
  ASSERT_TRUE(p.ok()) << p.status().message();
  StatusOr<PackTiming> t = pack_timing(*p);
  ASSERT_TRUE(t.ok());
  const HopFault f = reroute_of(*p, *t, 3);
  EXPECT_EQ(f.reroute.normal_side, (V{1, 2}));
  EXPECT_TRUE(f.reroute.reverse_side.empty());
  EXPECT_EQ(f.unreached, (V{3, 4}));
  EXPECT_EQ(f.reroute_delay_s, 0.0);
}

TEST(PackStress, OnlyWireFaultsApplyToAPack) {
  StatusOr<PackSpec> p = four_devices(false);
  ASSERT_TRUE(p.ok());
  StatusOr<link::PartLibrary> parts = link::PartLibrary::load({});
  ASSERT_TRUE(parts.ok());
  StressOptions o;
  o.only = {"esd"};
  StatusOr<PackStressResult> r = run_pack_stress(*p, *parts, o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("--only must include 'wire' (got esd)"), std::string::npos)
      << r.status().message();
}

}  // namespace
}  // namespace isolink::analysis
