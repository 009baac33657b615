// The nodes' side of the wire (see boat_wire.hpp).
#include "boat_wire.hpp"

namespace telltale::boat {
namespace {

msg::Gait gait_of(const fusion::PdrOutput& p) {
  if (p.cadence_spm <= 0.0) return msg::GAIT_STILL;
  switch (p.gait) {
    case 0: return msg::GAIT_SLOW_WALK;
    case 1: return msg::GAIT_WALK;
    case 2: return msg::GAIT_FAST_WALK;
    case 3: return msg::GAIT_JOG;
    case 4: return msg::GAIT_RUN;
    default: return msg::GAIT_UNKNOWN;
  }
}

msg::Pose pose_of(const fusion::PdrOutput& p, WearableMount mount) {
  if (mount == WearableMount::kFoot) return msg::POSE_FOOT;
  if (mount == WearableMount::kTrunk) return msg::POSE_TRUNK;
  switch (p.pose) {
    case fusion::PhonePose::kHandHeld: return msg::POSE_HAND_HELD;
    case fusion::PhonePose::kCall: return msg::POSE_PHONE_CALL;
    case fusion::PhonePose::kPocket: return msg::POSE_POCKET;
    case fusion::PhonePose::kArmSwing: return msg::POSE_ARM_SWING;
  }
  return msg::POSE_UNKNOWN;
}

}  // namespace

void to_wire(const LogRecord& r, const std::string& boat_id, std::uint64_t run,
             msg::BoatAttitude& m) {
  m.boat_id(boat_id);
  m.boot_id(run);
  m.seq(r.seq);
  m.t_utc_ns(r.t_utc_ns);
  m.heel_deg(r.heel_deg);
  m.pitch_deg(r.pitch_deg);
  m.heading_deg(r.heading_deg);
  m.heel_rate_deg_s(r.heel_rate_deg_s);
  m.pitch_rate_deg_s(r.pitch_rate_deg_s);
  m.yaw_rate_deg_s(r.yaw_rate_deg_s);
  m.accel_weight(r.accel_weight);
  m.quality(r.quality);
  m.leds().left_leds(r.leds[0]);
  m.leds().right_leds(r.leds[1]);
  m.leds().up_leds(r.leds[2]);
  m.leds().down_leds(r.leds[3]);
  m.leds().led_count(r.led_count);
  m.leds().level(static_cast<msg::AlarmLevel>(r.level));
}

void to_wire(const FixRecord& r, const std::string& boat_id, std::uint64_t run, msg::BoatFix& m) {
  m.boat_id(boat_id);
  m.boot_id(run);
  m.seq(r.seq);
  m.t_utc_ns(r.t_utc_ns);
  m.gnss_utc_ns(r.gnss_utc_ns);
  m.lat_deg(r.lat_deg);
  m.lon_deg(r.lon_deg);
  m.sog_m_s(r.sog_m_s);
  m.cog_deg(r.cog_deg);
  m.fix(static_cast<msg::FixKind>(r.fix));
  m.satellites(r.satellites);
  m.hdop(r.hdop);
}

void to_wire(const WindRecord& r, const std::string& boat_id, std::uint64_t run, msg::BoatWind& m) {
  m.boat_id(boat_id);
  m.boot_id(run);
  m.seq(r.seq);
  m.t_utc_ns(r.t_utc_ns);
  m.from_deg(r.from_deg);
  m.speed_m_s(r.speed_m_s);
  m.source(r.source);
}

void to_wire(const WearableRecord& r, const std::string& athlete_id, msg::WearableMotion& m) {
  m.athlete_id(athlete_id);
  m.seq(r.seq);
  m.t_utc_ns(r.t_utc_ns);
  m.steps(static_cast<std::uint32_t>(r.pdr.steps));
  m.cadence_spm(r.pdr.cadence_spm);
  m.gait(gait_of(r.pdr));
  m.pose(pose_of(r.pdr, r.mount));
  m.x_m(r.pdr.x_m);
  m.y_m(r.pdr.y_m);
  m.heading_deg(r.pdr.heading_deg);
  m.distance_m(r.pdr.distance_m);
}

}  // namespace telltale::boat
