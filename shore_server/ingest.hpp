#pragma once
/// \file
/// The shore's door: every sample of every topic the shore reads is checked against the wire
/// contract (idl/README.md, "What the shore accepts") before anything believes it. A sample off
/// the contract is rejected and counted (GET /healthz, `ingest`), never stored, never shown,
/// never fatal: one hostile or broken publisher cannot crash the shore or poison the recording.
///
/// The checks, per sample:
/// - ids (boat_id, athlete_id, node_id): 1-32 characters of [A-Za-z0-9_-], exactly as sent (an id
///   the CDR string held longer than 32, or with a NUL inside, is rejected: Fast DDS's bounded
///   string would truncate it silently, so the strict types below look at the raw length);
/// - t_utc_ns: not before 2000-01-01 UTC and at most kMaxAheadNs ahead of the shore's clock;
/// - numbers: finite (heading_deg and the wearable's heading may be NaN, "no value"), angles in
///   range;
/// - texts (status texts): valid UTF-8 without control characters.
///
/// Thread-safety: Ingest's entry points may be called from any thread (the DDS listener, a
/// fuzzer); the counters are atomics.

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "fleet.hpp"
#include "telltalePubSubTypes.h"
#include "wire.hpp"

namespace telltale::shore {

/// 2000-01-01T00:00:00Z: no Telltale sample is older (a node with an unset clock reads 1970).
inline constexpr std::uint64_t kEarliestSampleNs = 946684800ULL * 1000000000ULL;
/// A sample may be this far ahead of the shore's clock (boat clocks drift; a day is absurd).
inline constexpr std::uint64_t kMaxAheadNs = 24ULL * 3600ULL * 1000000000ULL;

/// Why a sample was refused. kReaderFull is counted once each time a DDS reader's table of ids
/// (one instance per id) was found full and the reader replaced: Fast DDS drops a new id's samples
/// before the door meanwhile, without telling how many (shore_dds.hpp).
enum class Reject : std::uint8_t { kNone, kId, kTime, kValue, kText, kReaderFull };
inline constexpr std::size_t kRejectKinds = 6;
[[nodiscard]] const char* reject_name(Reject r);

/// The topics the shore reads.
enum class Topic : std::uint8_t {
  kAttitude,
  kBackfill,
  kStatus,
  kWearable,
  kFix,
  kFixBackfill,
  kWind
};
inline constexpr std::size_t kTopics = 7;
[[nodiscard]] const char* topic_name(Topic t);

/// Valid UTF-8 (shortest forms, no surrogates, at most U+10FFFF).
[[nodiscard]] bool valid_utf8(std::string_view text);
/// Valid UTF-8 with no control character (C0, DEL, C1): safe in JSON, CSV and logs.
[[nodiscard]] bool clean_text(std::string_view text);
/// Ids of boats, athletes and nodes on the wire: 1-32 of [A-Za-z0-9_-] (same as REST's valid_id).
[[nodiscard]] bool contract_id(std::string_view id);
/// t_utc_ns within [kEarliestSampleNs, shore_now_ns + kMaxAheadNs].
[[nodiscard]] bool contract_time(std::uint64_t t_utc_ns, std::uint64_t shore_now_ns);

[[nodiscard]] Reject check(const AttitudeSample& s, std::uint64_t shore_now_ns);
[[nodiscard]] Reject check(const WearableSample& s, std::uint64_t shore_now_ns);
/// A fix: position in range (or all of lat/lon/sog/cog NaN with fix "none"), SOG in [0, 100]
/// m/s or NaN, COG in [0, 360] or NaN, HDOP >= 0 or NaN, a known fix kind.
[[nodiscard]] Reject check(const FixSample& s, std::uint64_t shore_now_ns);
/// A wind reading: direction finite in [0, 360], speed in [0, 100] m/s or NaN, a known source.
[[nodiscard]] Reject check(const WindSample& s, std::uint64_t shore_now_ns);
[[nodiscard]] Reject check(const std::string& node_id, const NodeStatusInfo& s,
                           std::uint64_t t_utc_ns, std::uint64_t shore_now_ns);

/// What the door let in and kept out, per topic and reason.
class IngestCounters {
 public:
  void count(Topic topic, Reject reason, std::uint64_t n = 1);
  [[nodiscard]] std::uint64_t accepted(Topic topic) const;
  [[nodiscard]] std::uint64_t rejected(Topic topic, Reject reason) const;
  [[nodiscard]] std::uint64_t rejected_total() const;
  /// `{"accepted": {topic: n}, "rejected": {topic: {reason: n}}, "rejected_total": n,
  /// "last_rejected": "..."}` for /healthz.
  [[nodiscard]] nlohmann::json to_json() const;

 private:
  std::array<std::atomic<std::uint64_t>, kTopics> accepted_{};
  std::array<std::array<std::atomic<std::uint64_t>, kRejectKinds>, kTopics> rejected_{};
  mutable std::mutex last_mutex_;
  std::string last_rejected_;
};

/// Wire message -> checked shore sample -> the sinks (FleetCallbacks). The DDS listener and the
/// fuzzer call it alike.
struct IngestSinks {
  std::function<void(const AttitudeSample&)> on_attitude;
  std::function<void(const AttitudeSample&)> on_backfill;
  std::function<void(const std::string& node_id, const NodeStatusInfo&)> on_status;
  std::function<void(const WearableSample&)> on_wearable;
  std::function<void(const FixSample&)> on_fix;
  /// Fixes a boat resends from its session log: the same checks, another sink.
  std::function<void(const FixSample&)> on_fix_backfill;
  std::function<void(const WindSample&)> on_wind;
};

class Ingest {
 public:
  /// `clock`: the shore's UTC clock in ns (tests set it).
  explicit Ingest(IngestSinks sinks, std::function<std::uint64_t()> clock = {});

  /// Each returns what it decided (kNone: handed to the sink).
  Reject attitude(const msg::BoatAttitude& m, bool backfill);
  Reject status(const msg::NodeStatus& m);
  Reject wearable(const msg::WearableMotion& m);
  Reject fix(const msg::BoatFix& m, bool backfill = false);
  Reject wind(const msg::BoatWind& m);

  [[nodiscard]] const IngestCounters& counters() const { return counters_; }
  [[nodiscard]] IngestCounters& counters() { return counters_; }

 private:
  [[nodiscard]] std::uint64_t now() const;
  IngestSinks sinks_;
  std::function<std::uint64_t()> clock_;
  IngestCounters counters_;
};

/// The generated types, deserialising strictly: a key string longer than its bound (or with a
/// NUL inside) arrives as an empty id, which the checks reject, instead of a truncated one that
/// could merge two boats. The shore's readers use these.
class StrictBoatAttitudeType : public msg::BoatAttitudePubSubType {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
};
class StrictNodeStatusType : public msg::NodeStatusPubSubType {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
};
class StrictWearableMotionType : public msg::WearableMotionPubSubType {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
};
class StrictBoatFixType : public msg::BoatFixPubSubType {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
};
class StrictBoatWindType : public msg::BoatWindPubSubType {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
};

}  // namespace telltale::shore
