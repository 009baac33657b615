#pragma once
/// \file
/// Joining the Telltale DDS domain: the profile file, the domain id, topic names, and one RAII
/// participant that owns every entity it creates (Fast DDS example style: the constructor throws
/// on failure, the destructor deletes in reverse order).

#include <fastdds/dds/core/status/StatusMask.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace telltale::dds {

class JoinAnnouncer;

/// Topic names of the wire contract (idl/README.md).
inline constexpr const char* kTopicBoatAttitude = "telltale_boat_attitude";
inline constexpr const char* kTopicNodeStatus = "telltale_node_status";
inline constexpr const char* kTopicAlarmRules = "telltale_alarm_rules";
inline constexpr const char* kTopicAlarmEvents = "telltale_alarm_events";
inline constexpr const char* kTopicWearableMotion = "telltale_wearable_motion";
inline constexpr const char* kTopicBoatBackfill = "telltale_boat_backfill";
inline constexpr const char* kTopicShoreAck = "telltale_shore_ack";
inline constexpr const char* kTopicBoatFix = "telltale_boat_fix";
inline constexpr const char* kTopicBoatFixBackfill = "telltale_boat_fix_backfill";
inline constexpr const char* kTopicShoreFixAck = "telltale_shore_fix_ack";
inline constexpr const char* kTopicBoatWind = "telltale_boat_wind";

/// Setup failure (profile file, participant, topic, entity): main() prints it and exits non-zero.
class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where to find the domain and the profiles. Filled from flags, with environment fallbacks.
struct DdsOptions {
  std::optional<int> domain;  ///< flag; else TELLTALE_DOMAIN; else kDefaultDomain
  std::string profiles_file;  ///< flag; else TELLTALE_DDS_PROFILES; else the build's
  std::string participant_profile = "telltale_loopback";
  /// Unicast discovery peers (IPv4 addresses) added to the profile's initial peers: discovery on a
  /// network without multicast. Flag --dds-peer; else TELLTALE_DDS_PEERS (comma-separated).
  std::vector<std::string> peers;
  /// Applied to the participant QoS after the profile (fault injection in tests).
  std::function<void(eprosima::fastdds::dds::DomainParticipantQos&)> customize;
  /// Secured mode: a node folder of deploy/security/make_fleet_pki.sh (dds_security.hpp). Empty:
  /// unsecured, the default.
  std::string security_dir;
  /// Partitions of the participant's publisher and subscriber (empty: the default partition).
  std::vector<std::string> publisher_partitions;
  std::vector<std::string> subscriber_partitions;
  /// Discovery callbacks (on_publisher_discovery etc.); no status callbacks. Not owned.
  eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr;
  /// Announce this participant again shortly after another one joins (join_announcer.hpp): a
  /// newcomer that missed our first answer meets us in ~50 ms, not at our next periodic
  /// announcement (2 s). The shore sets it: every boat meets it.
  bool announce_on_join = false;
};

/// The domain of a binary started with neither `--domain` nor TELLTALE_DOMAIN: every Telltale
/// binary's default, so a shore and its boats started with no options meet.
inline constexpr int kDefaultDomain = 0;

/// The domain id from the flag, else TELLTALE_DOMAIN, else kDefaultDomain. Throws DdsError if the
/// value is not a number or is outside 0..232 (the range the RTPS port mapping allows).
[[nodiscard]] int resolve_domain(const std::optional<int>& flag);

/// The profiles XML from the flag, TELLTALE_DDS_PROFILES, or the deploy/ folder of this build.
[[nodiscard]] std::string resolve_profiles_file(const std::string& flag);

/// One participant on the Telltale domain with its publisher and subscriber.
class Participant {
 public:
  /// Loads the profiles file and creates the participant. Throws DdsError.
  Participant(const DdsOptions& options, const std::string& name);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  /// Registers `type` (once) and creates or returns the topic.
  eprosima::fastdds::dds::Topic* topic(const std::string& topic_name,
                                       eprosima::fastdds::dds::TypeSupport type);
  /// A writer with the named QoS profile of the profiles file. Throws DdsError.
  eprosima::fastdds::dds::DataWriter* writer(
      eprosima::fastdds::dds::Topic* topic, const std::string& profile,
      eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
  /// A reader with the named QoS profile. The listener gets every status (data, deadline,
  /// liveliness) and must outlive this participant: Fast DDS may call it until the reader is
  /// deleted by ~Participant. Throws DdsError.
  eprosima::fastdds::dds::DataReader* reader(eprosima::fastdds::dds::Topic* topic,
                                             const std::string& profile,
                                             eprosima::fastdds::dds::DataReaderListener* listener);

  /// Deletes a reader this participant created (its history and instances go with it).
  void delete_reader(eprosima::fastdds::dds::DataReader* reader);

  [[nodiscard]] int domain() const { return domain_; }
  [[nodiscard]] bool secured() const { return secured_; }
  [[nodiscard]] eprosima::fastdds::dds::DomainParticipant* get() const { return participant_; }

 private:
  int domain_ = 0;
  bool secured_ = false;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::unique_ptr<JoinAnnouncer> announcer_;  ///< the participant's listener when it announces
};

/// The fixed-size string of the IDL from a std::string; throws DdsError when it does not fit.
template <std::size_t N, class FixedString>
void assign_bounded(FixedString& dst, const std::string& src, const char* what) {
  if (src.size() > N) throw DdsError(std::string(what) + " longer than " + std::to_string(N));
  dst = src.c_str();
}

}  // namespace telltale::dds
