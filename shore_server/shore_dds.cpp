#include "shore_dds.hpp"

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <algorithm>

#include "dds_security.hpp"
#include "shutdown.hpp"
#include "telltalePubSubTypes.h"

namespace telltale::shore {

namespace fdds = eprosima::fastdds::dds;

namespace {

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
  s.accel_weight = m.accel_weight();
  s.quality = m.quality();
  s.leds[0] = m.leds().left_leds();
  s.leds[1] = m.leds().right_leds();
  s.leds[2] = m.leds().up_leds();
  s.leds[3] = m.leds().down_leds();
  s.led_count = m.leds().led_count();
  s.boot_id = m.boot_id();
  return s;
}

const char* kind_name(msg::NodeKind kind) {
  switch (kind) {
    case msg::NODE_KIND_BOAT:
      return "boat";
    case msg::NODE_KIND_WEARABLE:
      return "wearable";
    case msg::NODE_KIND_SHORE:
      return "shore";
  }
  return "unknown";
}

const char* gait_name(msg::Gait g) {
  switch (g) {
    case msg::GAIT_STILL:
      return "still";
    case msg::GAIT_SLOW_WALK:
      return "slow_walk";
    case msg::GAIT_WALK:
      return "walk";
    case msg::GAIT_FAST_WALK:
      return "fast_walk";
    case msg::GAIT_JOG:
      return "jog";
    case msg::GAIT_RUN:
      return "run";
    case msg::GAIT_UNKNOWN:
      break;
  }
  return "unknown";
}

const char* pose_name(msg::Pose p) {
  switch (p) {
    case msg::POSE_HAND_HELD:
      return "hand_held";
    case msg::POSE_PHONE_CALL:
      return "phone_call";
    case msg::POSE_POCKET:
      return "pocket";
    case msg::POSE_ARM_SWING:
      return "arm_swing";
    case msg::POSE_FOOT:
      return "foot";
    case msg::POSE_UNKNOWN:
      break;
  }
  return "unknown";
}

}  // namespace

class ShoreDds::Listener : public fdds::DataReaderListener {
 public:
  Listener(const FleetCallbacks& cb, WriterCheck* check) : cb_(cb), check_(check) {}

  /// Unsecured: every sample. Secured: only a sample whose id is its writer's (writer_check.hpp).
  bool accept(const fdds::SampleInfo& info, const std::string& claimed_id) {
    return info.valid_data && (!check_ || check_->allowed(info.publication_handle, claimed_id));
  }

  // Readers are told apart by topic name: a callback may arrive before the constructor below has
  // stored the reader pointers.
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    const std::string& topic = reader->get_topicdescription()->get_name();
    if (topic == dds::kTopicBoatAttitude || topic == dds::kTopicBoatBackfill) {
      const auto& sink = topic == dds::kTopicBoatAttitude ? cb_.on_attitude : cb_.on_backfill;
      msg::BoatAttitude m;
      while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
        if (sink && accept(info, m.boat_id().to_string())) sink(from_wire(m));
      }
    } else if (topic == dds::kTopicWearableMotion) {
      msg::WearableMotion m;
      while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
        if (!cb_.on_wearable || !accept(info, m.athlete_id().to_string())) continue;
        WearableSample w;
        w.athlete_id = m.athlete_id().to_string();
        w.seq = m.seq();
        w.t_utc_ns = m.t_utc_ns();
        w.steps = m.steps();
        w.cadence_spm = m.cadence_spm();
        w.gait = gait_name(m.gait());
        w.pose = pose_name(m.pose());
        w.x_m = m.x_m();
        w.y_m = m.y_m();
        w.heading_deg = m.heading_deg();
        w.distance_m = m.distance_m();
        cb_.on_wearable(w);
      }
    } else if (topic == dds::kTopicNodeStatus) {
      msg::NodeStatus m;
      while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
        if (!cb_.on_status || !accept(info, m.node_id().to_string())) continue;
        NodeStatusInfo s;
        s.kind = kind_name(m.kind());
        s.software_version = m.software_version().to_string();
        s.uptime_s = m.uptime_s();
        s.sensor_health = m.sensor_health();
        s.health_text = m.health_text().to_string();
        s.samples_published = m.samples_published();
        s.group = m.group().to_string();
        cb_.on_status(m.node_id().to_string(), s);
      }
    }
  }

  void on_requested_deadline_missed(fdds::DataReader* reader,
                                    const fdds::RequestedDeadlineMissedStatus& status) override {
    if (reader->get_topicdescription()->get_name() != dds::kTopicBoatAttitude ||
        !cb_.on_deadline_missed)
      return;
    msg::BoatAttitude key_holder;
    if (reader->get_key_value(&key_holder, status.last_instance_handle) ==
        ReturnCode_t::RETCODE_OK)
      cb_.on_deadline_missed(key_holder.boat_id().to_string());
  }

 private:
  using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
  const FleetCallbacks& cb_;
  WriterCheck* check_;
};

ShoreDds::ShoreDds(const dds::DdsOptions& options, FleetCallbacks callbacks)
    : callbacks_(std::move(callbacks)) {
  dds::DdsOptions opts = options;
  if (!opts.security_dir.empty()) {
    writer_check_ = std::make_unique<WriterCheck>(opts.security_dir);
    opts.listener = writer_check_.get();
    dds::use_shore_partitions(opts);
  }
  listener_ = std::make_unique<Listener>(callbacks_, writer_check_.get());
  participant_ = std::make_unique<dds::Participant>(opts, "shore_server");
  participant_->reader(
      participant_->topic(dds::kTopicBoatAttitude,
                          fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
      "attitude_reader", listener_.get());
  participant_->reader(participant_->topic(dds::kTopicBoatBackfill,
                                           fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
                       "backfill_reader", listener_.get());
  participant_->reader(participant_->topic(dds::kTopicWearableMotion,
                                           fdds::TypeSupport(new msg::WearableMotionPubSubType())),
                       "wearable_reader", listener_.get());
  participant_->reader(
      participant_->topic(dds::kTopicNodeStatus, fdds::TypeSupport(new msg::NodeStatusPubSubType())),
      "status_reader", listener_.get());
  rule_writer_ = participant_->writer(
      participant_->topic(dds::kTopicAlarmRules, fdds::TypeSupport(new msg::AlarmRulePubSubType())),
      "alarm_writer");
  event_writer_ = participant_->writer(
      participant_->topic(dds::kTopicAlarmEvents,
                          fdds::TypeSupport(new msg::AlarmEventPubSubType())),
      "alarm_writer");
  ack_writer_ = participant_->writer(
      participant_->topic(dds::kTopicShoreAck, fdds::TypeSupport(new msg::ShoreAckPubSubType())),
      "ack_writer");
}

void ShoreDds::publish_ack(const std::string& boat_id, std::uint64_t boot_id,
                           std::uint64_t acked_seq) {
  msg::ShoreAck m;
  m.boat_id(boat_id);
  m.boot_id(boot_id);
  m.acked_seq(acked_seq);
  m.t_utc_ns(utc_now_ns());
  std::lock_guard lock(write_mutex_);
  ack_writer_->write(&m);
}

// The participant (and its readers) go first, so no callback runs on a dead listener.
ShoreDds::~ShoreDds() { participant_.reset(); }

void ShoreDds::publish_rules(const std::vector<AlarmRule>& rules) {
  std::lock_guard lock(write_mutex_);
  ++rule_revision_;
  std::vector<std::string> ids;
  for (const auto& r : rules) {
    msg::AlarmRule m;
    m.rule_id(r.id);
    m.scope(r.scope);
    m.quantity(r.quantity == AlarmQuantity::kHeel ? msg::ALARM_QUANTITY_HEEL
                                                  : msg::ALARM_QUANTITY_PITCH);
    m.min_deg(r.min_deg);
    m.max_deg(r.max_deg);
    m.hold_s(r.hold_s);
    m.hysteresis_deg(r.hysteresis_deg);
    m.level(r.level == AlarmLevel::kAlarm ? msg::ALARM_LEVEL_ALARM : msg::ALARM_LEVEL_WARN);
    m.enabled(r.enabled);
    m.revision(rule_revision_);
    rule_writer_->write(&m);
    ids.push_back(r.id);
  }
  for (const auto& old : published_rule_ids_) {
    if (std::find(ids.begin(), ids.end(), old) != ids.end()) continue;
    msg::AlarmRule key;
    key.rule_id(old);
    rule_writer_->dispose(&key, rule_writer_->lookup_instance(&key));
  }
  published_rule_ids_ = std::move(ids);
}

void ShoreDds::publish_event(const AlarmEvent& e) {
  msg::AlarmEvent m;
  m.boat_id(e.boat_id);
  m.rule_id(e.rule_id);
  m.event_id(e.id);
  m.level(e.level == AlarmLevel::kAlarm  ? msg::ALARM_LEVEL_ALARM
          : e.level == AlarmLevel::kWarn ? msg::ALARM_LEVEL_WARN
                                         : msg::ALARM_LEVEL_NORMAL);
  switch (e.phase) {
    case AlarmPhase::kRaised:
      m.phase(msg::ALARM_PHASE_RAISED);
      m.t_utc_ns(e.raised_ns);
      break;
    case AlarmPhase::kAcknowledged:
      m.phase(msg::ALARM_PHASE_ACKNOWLEDGED);
      m.t_utc_ns(e.acknowledged_ns);
      break;
    case AlarmPhase::kSilenced:
      m.phase(msg::ALARM_PHASE_SILENCED);
      m.t_utc_ns(e.silenced_ns);
      break;
    case AlarmPhase::kCleared:
      m.phase(msg::ALARM_PHASE_CLEARED);
      m.t_utc_ns(e.cleared_ns);
      break;
  }
  m.value_deg(e.value_deg);
  m.message(e.message.substr(0, 128));
  std::lock_guard lock(write_mutex_);
  event_writer_->write(&m);
}

}  // namespace telltale::shore
