// Across the wire: what a node publishes (boat_node/boat_wire.hpp) is what the shore reads
// (shore_server/wire.hpp), field by field, for every value of every enum a node writes; a record
// read back from the boat's session log goes on the wire exactly as it went live.
#include "boat_wire.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "session_log.hpp"
#include "wire.hpp"

namespace telltale {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint64_t kT = 1795300000ULL * 1000000000ULL;
constexpr std::uint64_t kRun = 0xFEDCBA9876543210ULL;  // above INT64_MAX: kept whole

::testing::AssertionResult same(double a, double b) {
  if ((std::isnan(a) && std::isnan(b)) || a == b) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " != " << b;
}

TEST(BoatWire, AttitudeAsTheShoreReadsIt) {
  boat::LogRecord r;
  r.seq = 42;
  r.t_utc_ns = kT + 40000000;
  r.heel_deg = -14.25;
  r.pitch_deg = 3.5;
  r.heel_rate_deg_s = 11.0;
  r.pitch_rate_deg_s = -2.5;
  r.yaw_rate_deg_s = 19.75;
  r.accel_weight = 0.5f;
  r.quality = 0.75f;
  r.leds[0] = 5, r.leds[1] = 0, r.leds[2] = 2, r.leds[3] = 1;
  r.led_count = 6;
  r.level = 2;
  for (const double heading : {kNaN, 0.0, 271.5}) {
    r.heading_deg = heading;
    msg::BoatAttitude m;
    boat::to_wire(r, "gbr-7", kRun, m);
    const shore::AttitudeSample s = shore::from_wire(m);
    EXPECT_EQ(s.boat_id, "gbr-7");
    EXPECT_EQ(s.boot_id, kRun);
    EXPECT_EQ(s.seq, r.seq);
    EXPECT_EQ(s.t_utc_ns, r.t_utc_ns);
    EXPECT_TRUE(same(s.heel_deg, r.heel_deg));
    EXPECT_TRUE(same(s.pitch_deg, r.pitch_deg));
    EXPECT_TRUE(same(s.heading_deg, heading));
    EXPECT_TRUE(same(s.heel_rate_deg_s, r.heel_rate_deg_s));
    EXPECT_TRUE(same(s.pitch_rate_deg_s, r.pitch_rate_deg_s));
    EXPECT_TRUE(same(s.yaw_rate_deg_s, r.yaw_rate_deg_s));
    EXPECT_TRUE(same(s.accel_weight, r.accel_weight));
    EXPECT_TRUE(same(s.quality, r.quality));
    for (int i = 0; i < 4; ++i) EXPECT_EQ(s.leds[i], r.leds[i]) << "led bar " << i;
    EXPECT_EQ(s.led_count, r.led_count);
    // The boat's own alarm colour is on the wire (its LED panel); the shore judges its own.
    EXPECT_EQ(m.leds().level(), msg::ALARM_LEVEL_ALARM);
  }
}

TEST(BoatWire, EveryFixKindAsTheShoreReadsIt) {
  for (const auto& row : shore::kFixKinds) {
    boat::FixRecord r;
    r.seq = 9;
    r.t_utc_ns = kT;
    r.gnss_utc_ns = kT - 120000000;
    r.lat_deg = row.wire == msg::FIX_KIND_NONE ? kNaN : 54.3440125;
    r.lon_deg = row.wire == msg::FIX_KIND_NONE ? kNaN : 10.1900375;
    r.sog_m_s = 3.25;
    r.cog_deg = kNaN;  // meaningless when slow: stays unknown
    r.fix = static_cast<std::uint8_t>(row.wire);
    r.satellites = 14;
    r.hdop = 0.75f;
    msg::BoatFix m;
    boat::to_wire(r, "gbr-7", kRun, m);
    const shore::FixSample f = shore::from_wire(m);
    EXPECT_EQ(f.boat_id, "gbr-7");
    EXPECT_EQ(f.boot_id, kRun);
    EXPECT_EQ(f.seq, r.seq);
    EXPECT_EQ(f.t_utc_ns, r.t_utc_ns);
    EXPECT_EQ(f.gnss_utc_ns, r.gnss_utc_ns);
    EXPECT_TRUE(same(f.lat_deg, r.lat_deg));
    EXPECT_TRUE(same(f.lon_deg, r.lon_deg));
    EXPECT_TRUE(same(f.sog_m_s, r.sog_m_s));
    EXPECT_TRUE(same(f.cog_deg, r.cog_deg));
    EXPECT_EQ(f.fix, row.shore);
    EXPECT_EQ(f.satellites, r.satellites);
    EXPECT_TRUE(same(f.hdop, r.hdop));
  }
}

// A wind instrument's reading: every member back on the shore (a missing speed stays NaN).
TEST(BoatWire, WindRoundTripsToTheShore) {
  const boat::WindRecord r{5, kT, 212.5, kNaN, "mwv_apparent"};
  msg::BoatWind m;
  boat::to_wire(r, "gbr-7", kRun, m);
  const shore::WindSample w = shore::from_wire(m);
  EXPECT_EQ(w.boat_id, "gbr-7");
  EXPECT_EQ(w.boot_id, kRun);
  EXPECT_EQ(w.seq, r.seq);
  EXPECT_EQ(w.t_utc_ns, r.t_utc_ns);
  EXPECT_EQ(w.from_deg, r.from_deg);
  EXPECT_TRUE(same(w.speed_m_s, r.speed_m_s));
  EXPECT_EQ(w.source, "mwv_apparent");
}

TEST(BoatWire, EveryGaitAndPoseAsTheShoreReadsIt) {
  struct Case {
    double cadence;
    int gait;
    fusion::PhonePose pose;
    boat::WearableMount mount;
    const char* want_gait;
    const char* want_pose;
  };
  const Case cases[] = {
      {0.0, 1, fusion::PhonePose::kHandHeld, boat::WearableMount::kCarried, "still", "hand_held"},
      {90.0, 0, fusion::PhonePose::kCall, boat::WearableMount::kCarried, "slow_walk", "phone_call"},
      {110.0, 1, fusion::PhonePose::kPocket, boat::WearableMount::kCarried, "walk", "pocket"},
      {125.0, 2, fusion::PhonePose::kArmSwing, boat::WearableMount::kCarried, "fast_walk",
       "arm_swing"},
      {150.0, 3, fusion::PhonePose::kHandHeld, boat::WearableMount::kFoot, "jog", "foot"},
      {175.0, 4, fusion::PhonePose::kHandHeld, boat::WearableMount::kCarried, "run", "hand_held"},
      {100.0, 1, fusion::PhonePose::kPocket, boat::WearableMount::kTrunk, "walk", "trunk"},
      {120.0, 9, fusion::PhonePose::kHandHeld, boat::WearableMount::kCarried, "unknown",
       "hand_held"},
  };
  for (const Case& c : cases) {
    boat::WearableRecord r;
    r.seq = 3;
    r.t_utc_ns = kT;
    r.pdr.steps = 123;
    r.pdr.cadence_spm = c.cadence;
    r.pdr.gait = c.gait;
    r.pdr.pose = c.pose;
    r.pdr.x_m = -12.5;
    r.pdr.y_m = 40.25;
    r.pdr.heading_deg = 181.5;
    r.pdr.distance_m = 88.0;
    r.mount = c.mount;
    msg::WearableMotion m;
    boat::to_wire(r, "ath-1", m);
    const shore::WearableSample w = shore::from_wire(m);
    EXPECT_EQ(w.athlete_id, "ath-1");
    EXPECT_EQ(w.seq, r.seq);
    EXPECT_EQ(w.t_utc_ns, r.t_utc_ns);
    EXPECT_EQ(w.steps, 123u);
    EXPECT_TRUE(same(w.cadence_spm, c.cadence));
    EXPECT_EQ(w.gait, c.want_gait) << "cadence " << c.cadence << " gait " << c.gait;
    EXPECT_EQ(w.pose, c.want_pose);
    EXPECT_TRUE(same(w.x_m, r.pdr.x_m));
    EXPECT_TRUE(same(w.y_m, r.pdr.y_m));
    EXPECT_TRUE(same(w.heading_deg, r.pdr.heading_deg));
    EXPECT_TRUE(same(w.distance_m, r.pdr.distance_m));
  }
}

}  // namespace
}  // namespace telltale
