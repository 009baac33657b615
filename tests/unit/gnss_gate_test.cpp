// The boat's GNSS gate (boat_node/gnss_gate.hpp): what may go on the wire as a fix.
#include "gnss_gate.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace telltale::boat;
using telltale::sensors::GnssFixKind;
using telltale::sensors::GnssReading;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint64_t kNow = 1796215200ull * 1000000000ull;  // 2026-12-02T12:40:00Z

/// A reading `north_m` metres north of 54.34 N 10.19 E, with a receiver time `north_m` s after
/// 12:40 (each reading its own epoch).
GnssReading at(double north_m, double sog = 3.0, double cog = 0.0) {
  GnssReading r;
  r.lat_deg = 54.34 + north_m / 111195.0;
  r.lon_deg = 10.19;
  r.sog_m_s = sog;
  r.cog_deg = cog;
  r.fix = GnssFixKind::k3D;
  r.satellites = 10;
  r.hdop = 1.0;
  r.time_of_day_s = 12 * 3600 + 40 * 60 + north_m;
  r.date_ddmmyy = 21226;
  return r;
}
}  // namespace

TEST(GnssGate, DistanceIsRightOnTheGround) {
  // One minute of latitude is one nautical mile.
  EXPECT_NEAR(distance_m(54.0, 10.0, 54.0 + 1.0 / 60.0, 10.0), 1852.0, 5.0);
  EXPECT_NEAR(distance_m(0.0, 0.0, 0.0, 1.0), 111195.0, 1.0);
}

TEST(GnssGate, AJumpFasterThanABoatIsRejectedAndCountedTheTrackGoesOn) {
  GnssGate gate;
  double t = 0.0;
  for (int i = 0; i < 10; ++i, t += 0.1) ASSERT_TRUE(gate.on_epoch(at(0.3 * i), t, kNow));
  // 500 m in 0.1 s: a multipath glitch, not a boat.
  EXPECT_FALSE(gate.on_epoch(at(500.0), t, kNow));
  t += 0.1;
  EXPECT_TRUE(gate.on_epoch(at(3.3), t, kNow));
  EXPECT_EQ(gate.stats().jumps, 1u);
  EXPECT_EQ(gate.stats().fixes, 11u);
  // A reported 60 m/s is not a boat either.
  EXPECT_FALSE(gate.on_epoch(at(3.6, 60.0), t + 0.1, kNow));
  EXPECT_EQ(gate.stats().jumps, 2u);
}

TEST(GnssGate, ARealMoveThatPersistsIsTakenAfterThreeAgreeingFixes) {
  GnssGate gate;
  ASSERT_TRUE(gate.on_epoch(at(0), 0.0, kNow));
  // The receiver was wrong first (or the boat was towed while the node slept): 2 km away, and
  // the fixes after agree with each other.
  EXPECT_FALSE(gate.on_epoch(at(2000.0), 0.1, kNow));
  EXPECT_FALSE(gate.on_epoch(at(2000.3), 0.2, kNow));
  EXPECT_TRUE(gate.on_epoch(at(2000.6), 0.3, kNow));
  EXPECT_EQ(gate.stats().reanchors, 1u);
  EXPECT_TRUE(gate.on_epoch(at(2000.9), 0.4, kNow));
}

TEST(GnssGate, NoFixGoesOutFlaggedWithNoPosition) {
  GnssGate gate;
  GnssReading r = at(0);
  r.fix = GnssFixKind::kNone;
  const auto f = gate.on_epoch(r, 0.0, kNow);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fix, GnssFixKind::kNone);
  EXPECT_TRUE(std::isnan(f->lat_deg) && std::isnan(f->lon_deg) && std::isnan(f->sog_m_s));
  // A "fix" with a NaN or impossible position is no fix either.
  r = at(0);
  r.lat_deg = kNaN;
  EXPECT_EQ(gate.on_epoch(r, 0.1, kNow)->fix, GnssFixKind::kNone);
  r = at(0);
  r.lon_deg = 200.0;
  EXPECT_EQ(gate.on_epoch(r, 0.2, kNow)->fix, GnssFixKind::kNone);
  EXPECT_EQ(gate.stats().no_fix, 3u);
  EXPECT_EQ(gate.stats().fixes, 0u);
}

TEST(GnssGate, CourseAtStandstillIsMarkedMeaningless) {
  GnssGate gate;
  EXPECT_TRUE(std::isnan(gate.on_epoch(at(0, 0.1, 123.0), 0.0, kNow)->cog_deg));
  EXPECT_DOUBLE_EQ(gate.on_epoch(at(0.1, 2.0, 123.0), 0.1, kNow)->cog_deg, 123.0);
}

TEST(GnssGate, GnssTimeGivesTheBoatClockOffset) {
  GnssGate gate;
  // The same epoch reported twice (gpsd: one report per sentence) goes out once.
  {
    GnssGate g;
    EXPECT_TRUE(g.on_epoch(at(1.0), 0.0, kNow));
    EXPECT_FALSE(g.on_epoch(at(1.0), 0.01, kNow));
    EXPECT_EQ(g.stats().repeats, 1u);
  }
  // The receiver says 12:40:00.000 on 2026-12-02; the boat clock is 2.5 s fast.
  const auto f = gate.on_epoch(at(0), 0.0, kNow + 2500000000ull);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->gnss_utc_ns, kNow);
  EXPECT_NEAR(gate.clock_offset_s(), 2.5, 1e-9);
  // GGA only (no date): the day nearest the boat clock, across midnight too.
  EXPECT_EQ(gnss_utc_ns(12 * 3600 + 40 * 60, -1, kNow + 1000000000ull), kNow);
  const std::uint64_t midnight = 1796256000ull * 1000000000ull;  // 2026-12-03T00:00:00Z
  EXPECT_EQ(gnss_utc_ns(86399.5, -1, midnight + 200000000ull), midnight - 500000000ull);
  EXPECT_EQ(gnss_utc_ns(kNaN, -1, kNow), 0u);
}

TEST(GnssGate, TheFixIsTimedByTheBoatClockItArrivedAtWithOrWithoutAPosition) {
  GnssGate gate;
  EXPECT_EQ(gate.on_epoch(at(0), 0.0, kNow)->t_boat_ns, kNow);
  GnssReading none = at(1.0);
  none.fix = GnssFixKind::kNone;
  EXPECT_EQ(gate.on_epoch(none, 0.1, kNow + 100000000ull)->t_boat_ns, kNow + 100000000ull);
}
