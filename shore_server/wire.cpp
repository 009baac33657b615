#include "wire.hpp"

namespace telltale::shore {

bool known_fix_kind(std::string_view name) { return wire_of(kFixKinds, name).has_value(); }

AttitudeSample from_wire(const msg::BoatAttitude& m) {
  AttitudeSample s;
  s.boat_id = m.boat_id().to_string();
  s.seq = m.seq();
  s.t_utc_ns = m.t_utc_ns();
  s.heel_deg = m.heel_deg();
  s.pitch_deg = m.pitch_deg();
  s.heading_deg = m.heading_deg();
  s.heel_rate_deg_s = m.heel_rate_deg_s();
  s.pitch_rate_deg_s = m.pitch_rate_deg_s();
  s.yaw_rate_deg_s = m.yaw_rate_deg_s();
  s.accel_weight = static_cast<double>(m.accel_weight());  // exact: every float is a double
  s.quality = static_cast<double>(m.quality());
  s.leds[0] = m.leds().left_leds();
  s.leds[1] = m.leds().right_leds();
  s.leds[2] = m.leds().up_leds();
  s.leds[3] = m.leds().down_leds();
  s.led_count = m.leds().led_count();
  // m.leds().level() is not read, on purpose: the shore's alarm state is its own (wire.hpp).
  s.boot_id = m.boot_id();
  return s;
}

msg::BoatAttitude to_wire(const AttitudeSample& s) {
  msg::BoatAttitude m;
  m.boat_id(s.boat_id);
  m.seq(s.seq);
  m.t_utc_ns(s.t_utc_ns);
  m.heel_deg(s.heel_deg);
  m.pitch_deg(s.pitch_deg);
  m.heading_deg(s.heading_deg);
  m.heel_rate_deg_s(s.heel_rate_deg_s);
  m.pitch_rate_deg_s(s.pitch_rate_deg_s);
  m.yaw_rate_deg_s(s.yaw_rate_deg_s);
  m.accel_weight(static_cast<float>(s.accel_weight));
  m.quality(static_cast<float>(s.quality));
  m.leds().left_leds(s.leds[0]);
  m.leds().right_leds(s.leds[1]);
  m.leds().up_leds(s.leds[2]);
  m.leds().down_leds(s.leds[3]);
  m.leds().led_count(s.led_count);
  m.leds().level(msg::ALARM_LEVEL_NORMAL);
  m.boot_id(s.boot_id);
  return m;
}

FixSample from_wire(const msg::BoatFix& m) {
  FixSample f;
  f.boat_id = m.boat_id().to_string();
  f.seq = m.seq();
  f.t_utc_ns = m.t_utc_ns();
  f.gnss_utc_ns = m.gnss_utc_ns();
  f.lat_deg = m.lat_deg();
  f.lon_deg = m.lon_deg();
  f.sog_m_s = m.sog_m_s();
  f.cog_deg = m.cog_deg();
  f.fix = std::string(shore_of(kFixKinds, m.fix(), std::string_view("invalid")));
  f.satellites = m.satellites();
  f.hdop = static_cast<double>(m.hdop());
  f.boot_id = m.boot_id();
  return f;
}

msg::BoatFix to_wire(const FixSample& f) {
  msg::BoatFix m;
  m.boat_id(f.boat_id);
  m.seq(f.seq);
  m.t_utc_ns(f.t_utc_ns);
  m.gnss_utc_ns(f.gnss_utc_ns);
  m.lat_deg(f.lat_deg);
  m.lon_deg(f.lon_deg);
  m.sog_m_s(f.sog_m_s);
  m.cog_deg(f.cog_deg);
  m.fix(wire_of(kFixKinds, std::string_view(f.fix)).value_or(msg::FIX_KIND_NONE));
  m.satellites(static_cast<std::uint8_t>(f.satellites));
  m.hdop(static_cast<float>(f.hdop));
  m.boot_id(f.boot_id);
  return m;
}

WindSample from_wire(const msg::BoatWind& m) {
  WindSample w;
  w.boat_id = m.boat_id().to_string();
  w.t_utc_ns = m.t_utc_ns();
  w.from_deg = m.from_deg();
  w.speed_m_s = m.speed_m_s();
  w.source = m.source().to_string();
  w.seq = m.seq();
  w.boot_id = m.boot_id();
  return w;
}

WearableSample from_wire(const msg::WearableMotion& m) {
  WearableSample w;
  w.athlete_id = m.athlete_id().to_string();
  w.seq = m.seq();
  w.t_utc_ns = m.t_utc_ns();
  w.steps = m.steps();
  w.cadence_spm = m.cadence_spm();
  w.gait = std::string(shore_of(kGaits, m.gait(), std::string_view("unknown")));
  w.pose = std::string(shore_of(kPoses, m.pose(), std::string_view("unknown")));
  w.x_m = m.x_m();
  w.y_m = m.y_m();
  w.heading_deg = m.heading_deg();
  w.distance_m = m.distance_m();
  return w;
}

msg::WearableMotion to_wire(const WearableSample& w) {
  msg::WearableMotion m;
  m.athlete_id(w.athlete_id);
  m.seq(w.seq);
  m.t_utc_ns(w.t_utc_ns);
  m.steps(w.steps);
  m.cadence_spm(w.cadence_spm);
  m.gait(wire_of(kGaits, std::string_view(w.gait)).value_or(msg::GAIT_UNKNOWN));
  m.pose(wire_of(kPoses, std::string_view(w.pose)).value_or(msg::POSE_UNKNOWN));
  m.x_m(w.x_m);
  m.y_m(w.y_m);
  m.heading_deg(w.heading_deg);
  m.distance_m(w.distance_m);
  return m;
}

NodeStatusInfo from_wire(const msg::NodeStatus& m) {
  NodeStatusInfo s;
  s.kind = std::string(shore_of(kNodeKinds, m.kind(), std::string_view("unknown")));
  s.software_version = m.software_version().to_string();
  s.uptime_s = m.uptime_s();
  s.sensor_health = m.sensor_health();
  s.health_text = m.health_text().to_string();
  s.samples_published = m.samples_published();
  s.group = m.group().to_string();
  return s;
}

msg::NodeStatus to_wire(const std::string& node_id, const NodeStatusInfo& s,
                        std::uint64_t t_utc_ns) {
  msg::NodeStatus m;
  m.node_id(node_id);
  m.kind(wire_of(kNodeKinds, std::string_view(s.kind)).value_or(msg::NODE_KIND_BOAT));
  m.software_version(s.software_version);
  m.t_utc_ns(t_utc_ns);
  m.uptime_s(s.uptime_s);
  m.sensor_health(s.sensor_health);
  m.health_text(s.health_text);
  m.samples_published(s.samples_published);
  m.group(s.group);
  return m;
}

AlarmRule from_wire(const msg::AlarmRule& m) {
  AlarmRule r;
  r.id = m.rule_id().to_string();
  r.scope = m.scope().to_string();
  r.quantity = shore_of(kAlarmQuantities, m.quantity(), AlarmQuantity::kHeel);
  r.min_deg = m.min_deg();
  r.max_deg = m.max_deg();
  r.hold_s = m.hold_s();
  r.hysteresis_deg = m.hysteresis_deg();
  r.level = shore_of(kAlarmLevels, m.level(), AlarmLevel::kWarn);
  r.enabled = m.enabled();
  return r;
}

msg::AlarmRule to_wire(const AlarmRule& r, std::uint64_t revision) {
  msg::AlarmRule m;
  m.rule_id(r.id);
  m.scope(r.scope);
  m.quantity(wire_of(kAlarmQuantities, r.quantity).value_or(msg::ALARM_QUANTITY_HEEL));
  m.min_deg(r.min_deg);
  m.max_deg(r.max_deg);
  m.hold_s(r.hold_s);
  m.hysteresis_deg(r.hysteresis_deg);
  m.level(wire_of(kAlarmLevels, r.level).value_or(msg::ALARM_LEVEL_WARN));
  m.enabled(r.enabled);
  m.revision(revision);
  return m;
}

namespace {
/// The event's time of its phase `phase`, where from_wire puts the wire's t_utc_ns.
std::uint64_t AlarmEvent::*phase_time(AlarmPhase phase) {
  switch (phase) {
    case AlarmPhase::kAcknowledged:
      return &AlarmEvent::acknowledged_ns;
    case AlarmPhase::kSilenced:
      return &AlarmEvent::silenced_ns;
    case AlarmPhase::kCleared:
      return &AlarmEvent::cleared_ns;
    case AlarmPhase::kRaised:
      break;
  }
  return &AlarmEvent::raised_ns;
}
}  // namespace

AlarmEvent from_wire(const msg::AlarmEvent& m) {
  AlarmEvent e;
  e.id = m.event_id();
  e.boat_id = m.boat_id().to_string();
  e.rule_id = m.rule_id().to_string();
  e.level = shore_of(kAlarmLevels, m.level(), AlarmLevel::kWarn);
  e.phase = shore_of(kAlarmPhases, m.phase(), AlarmPhase::kRaised);
  e.*phase_time(e.phase) = m.t_utc_ns();
  e.value_deg = m.value_deg();
  e.message = m.message().to_string();
  return e;
}

msg::AlarmEvent to_wire(const AlarmEvent& e) {
  msg::AlarmEvent m;
  m.boat_id(e.boat_id);
  m.rule_id(e.rule_id);
  m.event_id(e.id);
  m.level(wire_of(kAlarmLevels, e.level).value_or(msg::ALARM_LEVEL_NORMAL));
  m.phase(wire_of(kAlarmPhases, e.phase).value_or(msg::ALARM_PHASE_RAISED));
  m.t_utc_ns(e.*phase_time(e.phase));
  m.value_deg(e.value_deg);
  m.message(e.message.substr(0, 128));
  return m;
}

Store::Ack from_wire(const msg::ShoreAck& m) {
  return {m.boat_id().to_string(), m.boot_id(), m.acked_seq()};
}

msg::ShoreAck to_wire(const Store::Ack& a, std::uint64_t t_utc_ns) {
  msg::ShoreAck m;
  m.boat_id(a.boat_id);
  m.boot_id(a.boot_id);
  m.acked_seq(a.acked_seq);
  m.t_utc_ns(t_utc_ns);
  return m;
}

}  // namespace telltale::shore
