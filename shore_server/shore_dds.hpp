#pragma once
/// \file
/// The shore's DDS role: subscribes to the whole fleet (attitude, node status) and hands every
/// sample that passes the contract's checks (ingest.hpp) to the callbacks, on Fast DDS's listener
/// thread (callbacks must be quick and must not throw: they update the fleet model, the live hub
/// and the store queue); publishes the alarm rules and events to the boats (reliable, transient
/// local: a boat that joins late gets them).

#include <array>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dds_participant.hpp"
#include "fleet.hpp"
#include "ingest.hpp"
#include "telltale/fusion/alarm_engine.hpp"
#include "writer_check.hpp"

namespace telltale::shore {

struct FleetCallbacks {
  /// Live samples (best effort topic).
  std::function<void(const AttitudeSample&)> on_attitude;
  /// Samples a boat resends from its session log (reliable backfill topic).
  std::function<void(const AttitudeSample&)> on_backfill;
  std::function<void(const std::string& node_id, const NodeStatusInfo&)> on_status;
  /// An athlete's wearable motion.
  std::function<void(const WearableSample&)> on_wearable;
  /// A GNSS fix (any kind, "none" included).
  std::function<void(const FixSample&)> on_fix;
  /// Fixes a boat resends from its session log (reliable fix backfill topic).
  std::function<void(const FixSample&)> on_fix_backfill;
  /// A live boat's wind instrument readings.
  std::function<void(const WindSample&)> on_wind;
};

/// Receipt instances the shore's ack writer keeps registered at most (its profile allows 4096;
/// a 2000-boat fleet has a run each, and earlier runs delivering from their logs).
inline constexpr std::size_t kMaxAckInstances = 3000;

class ShoreDds {
 public:
  /// Creates the participant, readers and writers (throws dds::DdsError).
  ShoreDds(const dds::DdsOptions& options, FleetCallbacks callbacks);
  ~ShoreDds();
  ShoreDds(const ShoreDds&) = delete;
  ShoreDds& operator=(const ShoreDds&) = delete;

  /// Publishes the whole rule set; rules no longer in it are disposed. Thread-safe.
  void publish_rules(const std::vector<AlarmRule>& rules);
  /// Publishes one event's current phase. Thread-safe.
  void publish_event(const AlarmEvent& event);
  /// Tells a boat that every sample of run `boot_id` up to `acked_seq` is stored. Thread-safe.
  /// False when the writer refused it (it never should: see kMaxAckInstances).
  bool publish_ack(const std::string& boat_id, std::uint64_t boot_id, std::uint64_t acked_seq);
  /// The same for the fixes (acked_seq a fix seq), on "telltale_shore_fix_ack". Thread-safe.
  bool publish_fix_ack(const std::string& boat_id, std::uint64_t boot_id, std::uint64_t acked_seq);
  /// Receipt instances registered now (at most kMaxAckInstances).
  [[nodiscard]] std::size_t ack_instances() const;
  [[nodiscard]] int domain() const { return participant_->domain(); }
  [[nodiscard]] bool secured() const { return participant_->secured(); }
  /// What the door (ingest.hpp) let in and kept out.
  [[nodiscard]] const IngestCounters& ingest_counters() const { return ingest_->counters(); }

  /// Replaces every reader whose table of ids (instances) filled up, at most once per
  /// `min_interval` per reader; each replacement is counted as "reader_full" in /healthz. Fast DDS
  /// frees an instance only once no writer holds it, so ids a publisher invented in a burst would
  /// keep a new boat out for as long as that publisher lives; a new reader starts empty and the
  /// boats still sailing are back within a sample. Call from one thread (the shore's sweep);
  /// returns the topics replaced.
  std::vector<std::string> recycle_full_readers(std::chrono::seconds min_interval);

 private:
  class Listener;
  FleetCallbacks callbacks_;
  std::unique_ptr<Ingest> ingest_;
  std::unique_ptr<WriterCheck> writer_check_;  ///< secured mode only
  std::unique_ptr<Listener> listener_;
  std::unique_ptr<dds::Participant> participant_;
  /// The readers, by Topic (ingest.hpp): what recycle_full_readers() replaces.
  struct ReaderSlot {
    eprosima::fastdds::dds::Topic* topic = nullptr;
    const char* profile = "";
    eprosima::fastdds::dds::DataReader* reader = nullptr;
    std::chrono::steady_clock::time_point recycled{};
  };
  std::array<ReaderSlot, kTopics> readers_{};
  eprosima::fastdds::dds::DataWriter* rule_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* event_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* ack_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* fix_ack_writer_ = nullptr;
  using AckInstances =
      std::map<std::pair<std::string, std::uint64_t>, std::chrono::steady_clock::time_point>;
  /// Writes one receipt on `writer`, keeping its instances within kMaxAckInstances.
  bool publish_receipt(eprosima::fastdds::dds::DataWriter* writer, AckInstances& instances,
                       const std::string& boat_id, std::uint64_t boot_id, std::uint64_t acked_seq);
  mutable std::mutex write_mutex_;
  std::vector<std::string> published_rule_ids_;
  /// Receipt instances the ack writer holds, (boat, run) -> last written: at most
  /// kMaxAckInstances, the least recently written unregistered first (the writer's resource limit
  /// is 4096 instances; without this the 4097th run never got a receipt).
  AckInstances ack_instances_;
  AckInstances fix_ack_instances_;  ///< the same for the fix receipts
  std::uint64_t rule_revision_ = 0;
};

}  // namespace telltale::shore
