// The shore's wire module: every topic type's to_wire and from_wire give
// each other's input back, for every value of every enum, NaN staying NaN; every enum table has
// each wire literal once, in the IDL's order.
#include "wire.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

namespace telltale::shore {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint64_t kT = 1795300000ULL * 1000000000ULL;

/// Equal, or both NaN.
::testing::AssertionResult same(double a, double b) {
  if ((std::isnan(a) && std::isnan(b)) || a == b) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " != " << b;
}

template <class Wire, class Shore, std::size_t N>
void expect_table(const std::array<EnumRow<Wire, Shore>, N>& table) {
  std::set<Shore> seen;
  for (std::size_t i = 0; i < N; ++i) {
    // Each literal once, in the IDL's order (the generated enum counts from 0).
    EXPECT_EQ(static_cast<std::size_t>(table[i].wire), i);
    EXPECT_TRUE(seen.insert(table[i].shore).second) << "row " << i << " repeats a shore value";
    EXPECT_EQ(wire_of(table, table[i].shore), table[i].wire);
  }
}

TEST(WireTest, EveryEnumTableHasEachLiteralOnceInOrder) {
  expect_table(kNodeKinds);
  expect_table(kFixKinds);
  expect_table(kGaits);
  expect_table(kPoses);
  expect_table(kAlarmLevels);
  expect_table(kAlarmQuantities);
  expect_table(kAlarmPhases);
}

void expect_same(const AttitudeSample& a, const AttitudeSample& b) {
  EXPECT_EQ(a.boat_id, b.boat_id);
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_EQ(a.t_utc_ns, b.t_utc_ns);
  EXPECT_TRUE(same(a.heel_deg, b.heel_deg));
  EXPECT_TRUE(same(a.pitch_deg, b.pitch_deg));
  EXPECT_TRUE(same(a.heading_deg, b.heading_deg));
  EXPECT_TRUE(same(a.heel_rate_deg_s, b.heel_rate_deg_s));
  EXPECT_TRUE(same(a.pitch_rate_deg_s, b.pitch_rate_deg_s));
  EXPECT_TRUE(same(a.yaw_rate_deg_s, b.yaw_rate_deg_s));
  EXPECT_TRUE(same(a.accel_weight, b.accel_weight));
  EXPECT_TRUE(same(a.quality, b.quality));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(a.leds[i], b.leds[i]) << "led bar " << i;
  EXPECT_EQ(a.led_count, b.led_count);
  EXPECT_EQ(a.boot_id, b.boot_id);
}

TEST(WireTest, AttitudeRoundTripsAndNaNStaysNaN) {
  AttitudeSample s;
  s.boat_id = "b-1";
  s.seq = 7;
  s.t_utc_ns = kT;
  s.heel_deg = 12.5;
  s.pitch_deg = -3.25;
  s.heel_rate_deg_s = 1.5;
  s.pitch_rate_deg_s = -0.5;
  s.yaw_rate_deg_s = 2.75;
  s.accel_weight = 0.25f;
  s.quality = 0.875f;
  s.leds[0] = 1;
  s.leds[1] = 2;
  s.leds[2] = 3;
  s.leds[3] = 4;
  s.led_count = 9;
  s.boot_id = 0xFEDCBA9876543210ULL;  // above INT64_MAX: kept whole
  for (const double heading : {kNaN, 0.0, 359.5}) {
    s.heading_deg = heading;
    expect_same(from_wire(to_wire(s)), s);
  }
}

TEST(WireTest, TheBoatsOwnAlarmLevelIsNotCarried) {
  AttitudeSample s;
  s.boat_id = "b1";
  s.t_utc_ns = kT;
  EXPECT_EQ(to_wire(s).leds().level(), msg::ALARM_LEVEL_NORMAL);
  for (const auto& row : kAlarmLevels) {
    msg::BoatAttitude m = to_wire(s);
    m.leds().level(row.wire);
    expect_same(from_wire(m), s);
  }
}

TEST(WireTest, FixRoundTripsForEveryKind) {
  for (const auto& row : kFixKinds) {
    FixSample f;
    f.boat_id = "b1";
    f.seq = 3;
    f.t_utc_ns = kT;
    f.gnss_utc_ns = kT + 40;
    f.fix = std::string(row.shore);
    const bool none = row.wire == msg::FIX_KIND_NONE;
    f.lat_deg = none ? kNaN : 41.5;
    f.lon_deg = none ? kNaN : -2.25;
    f.sog_m_s = none ? kNaN : 3.5;
    f.cog_deg = kNaN;  // slower than 0.3 m/s or no fix
    f.satellites = 11;
    f.hdop = none ? kNaN : 0.75;
    f.boot_id = 0x8000000000000001ULL;
    const FixSample g = from_wire(to_wire(f));
    EXPECT_EQ(g.boat_id, f.boat_id);
    EXPECT_EQ(g.seq, f.seq);
    EXPECT_EQ(g.t_utc_ns, f.t_utc_ns);
    EXPECT_EQ(g.gnss_utc_ns, f.gnss_utc_ns);
    EXPECT_TRUE(same(g.lat_deg, f.lat_deg));
    EXPECT_TRUE(same(g.lon_deg, f.lon_deg));
    EXPECT_TRUE(same(g.sog_m_s, f.sog_m_s));
    EXPECT_TRUE(same(g.cog_deg, f.cog_deg));
    EXPECT_EQ(g.fix, f.fix);
    EXPECT_EQ(g.satellites, f.satellites);
    EXPECT_TRUE(same(g.hdop, f.hdop));
    EXPECT_EQ(g.boot_id, f.boot_id);
  }
}

TEST(WireTest, AFixKindOffTheEnumReadsAsInvalid) {
  msg::BoatFix m;
  m.fix(static_cast<msg::FixKind>(kFixKinds.size()));
  EXPECT_EQ(from_wire(m).fix, "invalid");
  EXPECT_FALSE(known_fix_kind("invalid"));
  for (const auto& row : kFixKinds) EXPECT_TRUE(known_fix_kind(row.shore));
}

TEST(WireTest, WearableRoundTripsForEveryGaitAndPose) {
  for (const auto& gait : kGaits) {
    for (const auto& pose : kPoses) {
      WearableSample w;
      w.athlete_id = "a_1";
      w.seq = 5;
      w.t_utc_ns = kT;
      w.steps = 1234;
      w.cadence_spm = 110.5;
      w.gait = std::string(gait.shore);
      w.pose = std::string(pose.shore);
      w.x_m = kNaN;  // no position before the first step
      w.y_m = kNaN;
      w.heading_deg = kNaN;
      w.distance_m = 12.25;
      const WearableSample v = from_wire(to_wire(w));
      EXPECT_EQ(v.athlete_id, w.athlete_id);
      EXPECT_EQ(v.seq, w.seq);
      EXPECT_EQ(v.t_utc_ns, w.t_utc_ns);
      EXPECT_EQ(v.steps, w.steps);
      EXPECT_TRUE(same(v.cadence_spm, w.cadence_spm));
      EXPECT_EQ(v.gait, w.gait);
      EXPECT_EQ(v.pose, w.pose);
      EXPECT_TRUE(same(v.x_m, w.x_m));
      EXPECT_TRUE(same(v.y_m, w.y_m));
      EXPECT_TRUE(same(v.heading_deg, w.heading_deg));
      EXPECT_TRUE(same(v.distance_m, w.distance_m));
    }
  }
}

TEST(WireTest, StatusRoundTripsForEveryNodeKind) {
  for (const auto& row : kNodeKinds) {
    NodeStatusInfo s;
    s.kind = std::string(row.shore);
    s.software_version = "1.2.3";
    s.uptime_s = 42.5;
    s.sensor_health = msg::SENSOR_LOG_FAILING | msg::SENSOR_NO_DATA;
    s.health_text = "log failing";
    s.samples_published = 99;
    s.group = "ILCA7";
    const msg::NodeStatus m = to_wire("n1", s, kT);
    EXPECT_EQ(m.node_id().to_string(), "n1");
    EXPECT_EQ(m.t_utc_ns(), kT);
    const NodeStatusInfo t = from_wire(m);
    EXPECT_EQ(t.kind, s.kind);
    EXPECT_EQ(t.software_version, s.software_version);
    EXPECT_TRUE(same(t.uptime_s, s.uptime_s));
    EXPECT_EQ(t.sensor_health, s.sensor_health);
    EXPECT_EQ(t.health_text, s.health_text);
    EXPECT_EQ(t.samples_published, s.samples_published);
    EXPECT_EQ(t.group, s.group);
  }
}

TEST(WireTest, RuleRoundTripsForEveryQuantityAndLevel) {
  for (const auto& q : kAlarmQuantities) {
    for (const auto& level : kAlarmLevels) {
      AlarmRule r;
      r.id = "r1";
      r.scope = "group:ILCA7";
      r.quantity = q.shore;
      r.min_deg = -25.0;
      r.max_deg = 30.5;
      r.hold_s = 2.5;
      r.hysteresis_deg = 1.5;
      r.level = level.shore;
      r.enabled = false;
      const msg::AlarmRule m = to_wire(r, 17);
      EXPECT_EQ(m.revision(), 17u);
      EXPECT_EQ(from_wire(m), r);
    }
  }
}

TEST(WireTest, EventRoundTripsForEveryPhaseAndLevel) {
  for (const auto& phase : kAlarmPhases) {
    for (const auto& level : kAlarmLevels) {
      AlarmEvent e;
      e.id = 12;
      e.boat_id = "b1";
      e.rule_id = "r1";
      e.level = level.shore;
      e.phase = phase.shore;
      // The wire carries the time of the current phase only.
      switch (phase.shore) {
        case AlarmPhase::kRaised:
          e.raised_ns = kT;
          break;
        case AlarmPhase::kAcknowledged:
          e.acknowledged_ns = kT;
          break;
        case AlarmPhase::kSilenced:
          e.silenced_ns = kT;
          break;
        case AlarmPhase::kCleared:
          e.cleared_ns = kT;
          break;
      }
      e.value_deg = -31.5;
      e.message = "heel beyond 30";
      const AlarmEvent g = from_wire(to_wire(e));
      EXPECT_EQ(g.id, e.id);
      EXPECT_EQ(g.boat_id, e.boat_id);
      EXPECT_EQ(g.rule_id, e.rule_id);
      EXPECT_EQ(g.level, e.level);
      EXPECT_EQ(g.phase, e.phase);
      EXPECT_EQ(g.raised_ns, e.raised_ns);
      EXPECT_EQ(g.acknowledged_ns, e.acknowledged_ns);
      EXPECT_EQ(g.silenced_ns, e.silenced_ns);
      EXPECT_EQ(g.cleared_ns, e.cleared_ns);
      EXPECT_TRUE(same(g.value_deg, e.value_deg));
      EXPECT_EQ(g.message, e.message);
    }
  }
}

TEST(WireTest, AckRoundTrips) {
  const Store::Ack a{"b1", 0xFFFFFFFFFFFFFFFFULL, 4096};
  const msg::ShoreAck m = to_wire(a, kT);
  EXPECT_EQ(m.t_utc_ns(), kT);
  const Store::Ack b = from_wire(m);
  EXPECT_EQ(b.boat_id, a.boat_id);
  EXPECT_EQ(b.boot_id, a.boot_id);
  EXPECT_EQ(b.acked_seq, a.acked_seq);
}

}  // namespace
}  // namespace telltale::shore
