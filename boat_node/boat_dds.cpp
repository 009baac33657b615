#include "boat_dds.hpp"

#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <mutex>
#include <set>

#include "dds_security.hpp"
#include "telltalePubSubTypes.h"

namespace telltale::boat {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

class BoatDds::Listener : public fdds::DataReaderListener {
 public:
  Listener(const std::string& boat_id, const BoatDdsCallbacks& cb) : boat_id_(boat_id), cb_(cb) {}

  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    const std::string& topic = reader->get_topicdescription()->get_name();
    if (topic == dds::kTopicShoreAck || topic == dds::kTopicShoreFixAck) {
      const bool fixes = topic == dds::kTopicShoreFixAck;
      const auto& on_ack = fixes ? cb_.on_fix_ack : cb_.on_ack;
      auto& writers = fixes ? fix_ack_writers_ : ack_writers_;
      msg::ShoreAck m;
      while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK)
        if (info.valid_data && m.boat_id().to_string() == boat_id_ && on_ack) {
          const bool new_shore = writers.insert(info.sample_identity.writer_guid()).second;
          on_ack(m.boot_id(), m.acked_seq(), new_shore);
        }
    } else if (topic == dds::kTopicAlarmRules) {
      msg::AlarmRule m;
      bool changed = false;
      while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
        changed = true;
        const std::string id = m.rule_id().to_string();
        if (!info.valid_data) {  // disposed: the shore removed the rule
          rules_.erase(id);
          continue;
        }
        fusion::AlarmRule r;
        r.id = id;
        r.scope = m.scope().to_string();
        r.quantity = m.quantity() == msg::ALARM_QUANTITY_PITCH ? fusion::AlarmQuantity::kPitch
                                                               : fusion::AlarmQuantity::kHeel;
        r.min_deg = m.min_deg();
        r.max_deg = m.max_deg();
        r.hold_s = m.hold_s();
        r.hysteresis_deg = m.hysteresis_deg();
        r.level = m.level() == msg::ALARM_LEVEL_ALARM ? fusion::AlarmLevel::kAlarm
                                                      : fusion::AlarmLevel::kWarn;
        r.enabled = m.enabled();
        if (r.validate().empty()) rules_[id] = r;  // a malformed rule from the wire is ignored
      }
      if (changed && cb_.on_rules) {
        std::vector<fusion::AlarmRule> all;
        for (const auto& [id, r] : rules_) all.push_back(r);
        cb_.on_rules(std::move(all));
      }
    } else if (topic == dds::kTopicAlarmEvents) {
      msg::AlarmEvent m;
      while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK)
        if (info.valid_data && m.boat_id().to_string() == boat_id_ && cb_.on_event) cb_.on_event(m);
    }
  }

 private:
  std::string boat_id_;
  const BoatDdsCallbacks& cb_;
  std::map<std::string, fusion::AlarmRule> rules_;          ///< listener thread only
  std::set<eprosima::fastrtps::rtps::GUID_t> ack_writers_;  ///< shore writers heard; listener only
  std::set<eprosima::fastrtps::rtps::GUID_t> fix_ack_writers_;
};

BoatDds::BoatDds(const dds::DdsOptions& options, const std::string& boat_id,
                 BoatDdsCallbacks callbacks)
    : options_(options),
      boat_id_(boat_id),
      callbacks_(std::move(callbacks)),
      listener_(std::make_unique<Listener>(boat_id_, callbacks_)) {
  dds::use_node_partitions(options_, boat_id_);  // secured: publish only in this boat's partition
  join();
  domain_ = participant_->domain();
}

void BoatDds::join() {
  participant_ = std::make_unique<dds::Participant>(options_, "boat_node " + boat_id_);
  auto* attitude = participant_->topic(dds::kTopicBoatAttitude,
                                       fdds::TypeSupport(new msg::BoatAttitudePubSubType()));
  attitude_writer_ = participant_->writer(attitude, "attitude_writer");
  backfill_writer_ = participant_->writer(
      participant_->topic(dds::kTopicBoatBackfill,
                          fdds::TypeSupport(new msg::BoatAttitudePubSubType())),
      "backfill_writer");
  fix_writer_ = participant_->writer(
      participant_->topic(dds::kTopicBoatFix, fdds::TypeSupport(new msg::BoatFixPubSubType())),
      "fix_writer");
  fix_backfill_writer_ =
      participant_->writer(participant_->topic(dds::kTopicBoatFixBackfill,
                                               fdds::TypeSupport(new msg::BoatFixPubSubType())),
                           "fix_backfill_writer");
  // The wind shares the fix's QoS profile: keyed by boat, best effort, the latest per boat.
  wind_writer_ = participant_->writer(
      participant_->topic(dds::kTopicBoatWind, fdds::TypeSupport(new msg::BoatWindPubSubType())),
      "fix_writer");
  status_writer_ =
      participant_->writer(participant_->topic(dds::kTopicNodeStatus,
                                               fdds::TypeSupport(new msg::NodeStatusPubSubType())),
                           "status_writer");
  participant_->reader(
      participant_->topic(dds::kTopicShoreAck, fdds::TypeSupport(new msg::ShoreAckPubSubType())),
      "ack_reader", listener_.get());
  participant_->reader(
      participant_->topic(dds::kTopicShoreFixAck, fdds::TypeSupport(new msg::ShoreAckPubSubType())),
      "fix_ack_reader", listener_.get());
  participant_->reader(
      participant_->topic(dds::kTopicAlarmRules, fdds::TypeSupport(new msg::AlarmRulePubSubType())),
      "alarm_reader", listener_.get());
  participant_->reader(participant_->topic(dds::kTopicAlarmEvents,
                                           fdds::TypeSupport(new msg::AlarmEventPubSubType())),
                       "alarm_reader", listener_.get());
}

BoatDds::~BoatDds() { participant_.reset(); }

void BoatDds::rejoin() {
  std::unique_lock lock(mutex_);
  participant_.reset();  // its readers go first: no callback runs during the swap
  attitude_writer_ = backfill_writer_ = status_writer_ = fix_writer_ = fix_backfill_writer_ =
      wind_writer_ = nullptr;
  try {
    join();
  } catch (const dds::DdsError&) {
    participant_.reset();
    attitude_writer_ = backfill_writer_ = status_writer_ = fix_writer_ = fix_backfill_writer_ =
        wind_writer_ = nullptr;
  }
}

bool BoatDds::publish(msg::BoatAttitude& sample) {
  std::shared_lock lock(mutex_);
  return attitude_writer_ && attitude_writer_->write(&sample);
}
bool BoatDds::backfill(msg::BoatAttitude& sample) {
  std::shared_lock lock(mutex_);
  return backfill_writer_ && backfill_writer_->write(&sample);
}
bool BoatDds::publish(msg::BoatFix& fix) {
  std::shared_lock lock(mutex_);
  return fix_writer_ && fix_writer_->write(&fix);
}
bool BoatDds::backfill(msg::BoatFix& fix) {
  std::shared_lock lock(mutex_);
  return fix_backfill_writer_ && fix_backfill_writer_->write(&fix);
}
bool BoatDds::publish(msg::BoatWind& wind) {
  std::shared_lock lock(mutex_);
  return wind_writer_ && wind_writer_->write(&wind);
}
bool BoatDds::publish(msg::NodeStatus& status) {
  std::shared_lock lock(mutex_);
  return status_writer_ && status_writer_->write(&status);
}

}  // namespace telltale::boat
