#pragma once
/// \file
/// The boat node's DDS role. Publishes BoatAttitude and BoatFix (live, best effort: the write
/// never blocks the sensor loop), the backfill of each (reliable, from the backfill threads only)
/// and NodeStatus; listens to the shore's receipts for this boat (attitude and fixes) and to the
/// alarm rules and events the shore pushes.
/// Constructor creates the entities and throws DdsError; destructor deletes them.

#include <functional>
#include <memory>
#include <shared_mutex>
#include <string>
#include <vector>

#include "dds_participant.hpp"
#include "telltale.h"
#include "telltale/fusion/alarm_engine.hpp"

namespace telltale::boat {

struct BoatDdsCallbacks {
  /// The shore's receipt for this boat (any run; the caller checks boot_id).
  /// `new_shore`: the first receipt from a shore writer not heard before (a restarted shore:
  /// whatever was in flight to the old one is gone).
  std::function<void(std::uint64_t boot_id, std::uint64_t acked_seq, bool new_shore)> on_ack;
  /// The same for the fixes ("telltale_shore_fix_ack": acked_seq is a fix seq).
  std::function<void(std::uint64_t boot_id, std::uint64_t acked_seq, bool new_shore)> on_fix_ack;
  /// The complete current rule set, whenever it changes.
  std::function<void(std::vector<fusion::AlarmRule>)> on_rules;
  /// An alarm event about this boat changed phase on the shore.
  std::function<void(const msg::AlarmEvent&)> on_event;
};

class BoatDds {
 public:
  BoatDds(const dds::DdsOptions& options, const std::string& boat_id, BoatDdsCallbacks callbacks);
  ~BoatDds();
  BoatDds(const BoatDds&) = delete;
  BoatDds& operator=(const BoatDds&) = delete;

  bool publish(msg::BoatAttitude& sample);
  /// Reliable; may block up to the profile's max_blocking_time when the shore is slow.
  bool backfill(msg::BoatAttitude& sample);
  bool publish(msg::BoatFix& fix);
  /// A fix resent from the log ("telltale_boat_fix_backfill"); reliable, like backfill().
  bool backfill(msg::BoatFix& fix);
  /// A wind instrument's reading (telltale_boat_wind, best effort like the fix).
  bool publish(msg::BoatWind& wind);
  bool publish(msg::NodeStatus& status);
  [[nodiscard]] int domain() const { return domain_; }

  /// Leaves the domain and joins it again with a new participant. For when the host's addresses
  /// changed: Fast DDS announces the addresses it found when the participant was created, so the
  /// shore's receipts and rules would keep going to an address the boat no longer has. Writes
  /// wait meanwhile (they return false if joining fails; the next rejoin() tries again).
  void rejoin();

 private:
  class Listener;
  void join();

  dds::DdsOptions options_;
  int domain_ = 0;
  std::shared_mutex mutex_;  ///< writers share it; rejoin() takes it alone
  std::string boat_id_;
  BoatDdsCallbacks callbacks_;
  std::unique_ptr<Listener> listener_;
  std::unique_ptr<dds::Participant> participant_;
  eprosima::fastdds::dds::DataWriter* attitude_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* backfill_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* status_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* fix_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* fix_backfill_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* wind_writer_ = nullptr;
};

}  // namespace telltale::boat
