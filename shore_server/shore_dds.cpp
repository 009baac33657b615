#include "shore_dds.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <set>

#include "dds_security.hpp"
#include "shutdown.hpp"
#include "telltalePubSubTypes.h"
#include "wire.hpp"

namespace telltale::shore {

namespace fdds = eprosima::fastdds::dds;

class ShoreDds::Listener : public fdds::DataReaderListener {
 public:
  Listener(const FleetCallbacks& cb, Ingest& ingest, WriterCheck* check)
      : cb_(cb), ingest_(ingest), check_(check) {}

  /// Unsecured: every sample. Secured: only a sample whose id is its writer's (writer_check.hpp).
  bool accept(const fdds::SampleInfo& info, const std::string& claimed_id) {
    return info.valid_data && (!check_ || check_->allowed(info.publication_handle, claimed_id));
  }

  // Readers are told apart by topic name: a callback may arrive before the constructor below has
  // stored the reader pointers. Every sample goes through the door (ingest.hpp): nothing off the
  // contract reaches the fleet model, the store or the dashboards, and nothing thrown escapes
  // into Fast DDS's thread.
  void on_data_available(fdds::DataReader* reader) override {
    try {
      take_all(reader);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shore_server: sample dropped: %s\n", e.what());
    } catch (...) {
      std::fprintf(stderr, "shore_server: sample dropped\n");
    }
  }

  void take_all(fdds::DataReader* reader) {
    const std::string& topic = reader->get_topicdescription()->get_name();
    if (topic == dds::kTopicBoatAttitude || topic == dds::kTopicBoatBackfill) {
      const bool backfill = topic == dds::kTopicBoatBackfill;
      take<msg::BoatAttitude>(
          reader, backfill ? Topic::kBackfill : Topic::kAttitude,
          [](const auto& m) { return m.boat_id().to_string(); },
          [&](const auto& m) { (void)ingest_.attitude(m, backfill); });
    } else if (topic == dds::kTopicWearableMotion) {
      take<msg::WearableMotion>(
          reader, Topic::kWearable, [](const auto& m) { return m.athlete_id().to_string(); },
          [&](const auto& m) { (void)ingest_.wearable(m); });
    } else if (topic == dds::kTopicBoatFix || topic == dds::kTopicBoatFixBackfill) {
      const bool backfill = topic == dds::kTopicBoatFixBackfill;
      take<msg::BoatFix>(
          reader, backfill ? Topic::kFixBackfill : Topic::kFix,
          [](const auto& m) { return m.boat_id().to_string(); },
          [&](const auto& m) { (void)ingest_.fix(m, backfill); });
    } else if (topic == dds::kTopicBoatWind) {
      take<msg::BoatWind>(
          reader, Topic::kWind, [](const auto& m) { return m.boat_id().to_string(); },
          [&](const auto& m) { (void)ingest_.wind(m); });
    } else if (topic == dds::kTopicNodeStatus) {
      take<msg::NodeStatus>(
          reader, Topic::kStatus, [](const auto& m) { return m.node_id().to_string(); },
          [&](const auto& m) { (void)ingest_.status(m); });
    }
  }

  template <class Msg, class IdOf, class Sink>
  void take(fdds::DataReader* reader, Topic t, IdOf id_of, Sink sink) {
    Msg m;
    fdds::SampleInfo info;
    while (reader->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      note_instance(static_cast<std::size_t>(t), reader, info);
      if (accept(info, id_of(m))) sink(m);
    }
  }

  // Fast DDS keeps one instance per id and frees it only once no writer holds it; a sample of a
  // new id beyond the reader's max_instances is dropped before any listener sees it (Fast DDS
  // 2.9 reports no rejection). So the shore counts the live ids each reader holds, from the
  // instance handles of what it takes: once they fill the table, the next new boat would be
  // refused without a word, and the reader is marked for replacement.
  void note_instance(std::size_t t, fdds::DataReader* reader, const fdds::SampleInfo& info) {
    InstanceTable& table = tables_[t];
    std::array<std::uint8_t, 16> key{};
    const std::uint8_t* handle = info.instance_handle.value;
    std::copy(handle, handle + key.size(), key.begin());
    std::lock_guard lock(table.mutex);
    if (info.instance_state != fdds::ALIVE_INSTANCE_STATE) {
      table.handles.erase(key);  // no writer holds it any more: Fast DDS may reuse its slot
      return;
    }
    if (!table.handles.insert(key).second) return;
    const auto limit = reader->get_qos().resource_limits().max_instances;
    if (limit > 0 && table.handles.size() >= static_cast<std::size_t>(limit)) full_[t].store(true);
  }

  /// Takes the "reader full" mark of topic `t`, forgetting the ids counted for its reader (the
  /// caller replaces it with an empty one), and counts it as "reader_full" in /healthz.
  bool take_full(std::size_t t) {
    if (!full_[t].exchange(false)) return false;
    std::lock_guard lock(tables_[t].mutex);
    tables_[t].handles.clear();
    ingest_.counters().count(static_cast<Topic>(t), Reject::kReaderFull);
    return true;
  }

  /// DDS topic names in the order of ingest.hpp's Topic.
  static constexpr std::array<const char*, kTopics> kReaderTopics = {
      dds::kTopicBoatAttitude,   dds::kTopicBoatBackfill, dds::kTopicNodeStatus,
      dds::kTopicWearableMotion, dds::kTopicBoatFix,      dds::kTopicBoatFixBackfill,
      dds::kTopicBoatWind};

 private:
  using ReturnCode_t = eprosima::fastrtps::types::ReturnCode_t;
  const FleetCallbacks& cb_;
  Ingest& ingest_;
  WriterCheck* check_;
  struct InstanceTable {
    std::mutex mutex;
    std::set<std::array<std::uint8_t, 16>> handles;
  };
  std::array<InstanceTable, kTopics> tables_;
  std::array<std::atomic<bool>, kTopics> full_{};
};

ShoreDds::ShoreDds(const dds::DdsOptions& options, FleetCallbacks callbacks)
    : callbacks_(std::move(callbacks)),
      ingest_(std::make_unique<Ingest>(IngestSinks{callbacks_.on_attitude, callbacks_.on_backfill,
                                                   callbacks_.on_status, callbacks_.on_wearable,
                                                   callbacks_.on_fix, callbacks_.on_fix_backfill,
                                                   callbacks_.on_wind})) {
  dds::DdsOptions opts = options;
  if (!opts.security_dir.empty()) {
    writer_check_ = std::make_unique<WriterCheck>(opts.security_dir);
    opts.listener = writer_check_.get();
    dds::use_shore_partitions(opts);
  }
  listener_ = std::make_unique<Listener>(callbacks_, *ingest_, writer_check_.get());
  participant_ = std::make_unique<dds::Participant>(opts, "shore_server");
  const auto add_reader = [&](Topic t, fdds::TopicDataType* type, const char* profile) {
    ReaderSlot& slot = readers_[static_cast<std::size_t>(t)];
    slot.topic = participant_->topic(Listener::kReaderTopics[static_cast<std::size_t>(t)],
                                     fdds::TypeSupport(type));
    slot.profile = profile;
    slot.reader = participant_->reader(slot.topic, profile, listener_.get());
  };
  add_reader(Topic::kAttitude, new StrictBoatAttitudeType(), "attitude_reader");
  add_reader(Topic::kBackfill, new StrictBoatAttitudeType(), "backfill_reader");
  add_reader(Topic::kWearable, new StrictWearableMotionType(), "wearable_reader");
  add_reader(Topic::kFix, new StrictBoatFixType(), "fix_reader");
  add_reader(Topic::kFixBackfill, new StrictBoatFixType(), "fix_backfill_reader");
  add_reader(Topic::kStatus, new StrictNodeStatusType(), "status_reader");
  // The wind shares the fix's profile (keyed by boat, best effort).
  add_reader(Topic::kWind, new StrictBoatWindType(), "fix_reader");
  rule_writer_ = participant_->writer(
      participant_->topic(dds::kTopicAlarmRules, fdds::TypeSupport(new msg::AlarmRulePubSubType())),
      "alarm_writer");
  event_writer_ =
      participant_->writer(participant_->topic(dds::kTopicAlarmEvents,
                                               fdds::TypeSupport(new msg::AlarmEventPubSubType())),
                           "alarm_writer");
  ack_writer_ = participant_->writer(
      participant_->topic(dds::kTopicShoreAck, fdds::TypeSupport(new msg::ShoreAckPubSubType())),
      "ack_writer");
  fix_ack_writer_ = participant_->writer(
      participant_->topic(dds::kTopicShoreFixAck, fdds::TypeSupport(new msg::ShoreAckPubSubType())),
      "fix_ack_writer");
}

std::vector<std::string> ShoreDds::recycle_full_readers(std::chrono::seconds min_interval) {
  std::vector<std::string> replaced;
  const auto now = std::chrono::steady_clock::now();
  for (std::size_t t = 0; t < kTopics; ++t) {
    ReaderSlot& slot = readers_[t];
    if (!slot.reader || now - slot.recycled < min_interval || !listener_->take_full(t)) continue;
    participant_->delete_reader(slot.reader);
    slot.reader = nullptr;
    slot.reader = participant_->reader(slot.topic, slot.profile, listener_.get());
    slot.recycled = now;
    replaced.emplace_back(Listener::kReaderTopics[t]);
  }
  return replaced;
}

bool ShoreDds::publish_ack(const std::string& boat_id, std::uint64_t boot_id,
                           std::uint64_t acked_seq) {
  return publish_receipt(ack_writer_, ack_instances_, boat_id, boot_id, acked_seq);
}

bool ShoreDds::publish_fix_ack(const std::string& boat_id, std::uint64_t boot_id,
                               std::uint64_t acked_seq) {
  return publish_receipt(fix_ack_writer_, fix_ack_instances_, boat_id, boot_id, acked_seq);
}

bool ShoreDds::publish_receipt(fdds::DataWriter* writer, AckInstances& instances,
                               const std::string& boat_id, std::uint64_t boot_id,
                               std::uint64_t acked_seq) {
  msg::ShoreAck m = to_wire(Store::Ack{boat_id, boot_id, acked_seq}, utc_now_ns());
  std::lock_guard lock(write_mutex_);
  const auto now = std::chrono::steady_clock::now();
  const auto key = std::make_pair(boat_id, boot_id);
  if (!instances.count(key)) {
    // Make room first: the least recently written receipt instance goes (its run is long
    // delivered or its boat gone; a receipt asked for again is registered anew).
    while (instances.size() >= kMaxAckInstances) {
      auto oldest = instances.begin();
      for (auto it = instances.begin(); it != instances.end(); ++it)
        if (it->second < oldest->second) oldest = it;
      msg::ShoreAck old;
      old.boat_id(oldest->first.first);
      old.boot_id(oldest->first.second);
      (void)writer->unregister_instance(&old, writer->lookup_instance(&old));
      instances.erase(oldest);
    }
  }
  instances[key] = now;
  return writer->write(&m);
}

std::size_t ShoreDds::ack_instances() const {
  std::lock_guard lock(write_mutex_);
  return ack_instances_.size();
}

// The participant (and its readers) go first, so no callback runs on a dead listener.
ShoreDds::~ShoreDds() { participant_.reset(); }

void ShoreDds::publish_rules(const std::vector<AlarmRule>& rules) {
  std::lock_guard lock(write_mutex_);
  ++rule_revision_;
  std::vector<std::string> ids;
  for (const auto& r : rules) {
    msg::AlarmRule m = to_wire(r, rule_revision_);
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
  msg::AlarmEvent m = to_wire(e);
  std::lock_guard lock(write_mutex_);
  event_writer_->write(&m);
}

}  // namespace telltale::shore
