#pragma once
/// \file
/// The alarm engine: rules per boat, per group and fleet-wide; states normal/warn/alarm; hold
/// time and hysteresis; events with a lifecycle (raised -> acknowledged/silenced -> cleared).
/// Pure logic, thread-safe; persistence and distribution are the caller's. The shore runs it for
/// the fleet (and stores and pushes every changed event); a boat runs the same rules for its own
/// LED panel and buzzer when no shore is there.
///
/// A rule watches heel or pitch of every boat in its scope. The angle is in band when
/// min_deg <= value <= max_deg. Outside the band continuously for hold_s (boat clock) raises an
/// event at the rule's level; the event clears once the angle is back inside the band narrowed by
/// hysteresis_deg on both sides. A cleared rule raises again only after a new hold period.

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace telltale::fusion {

enum class AlarmLevel { kNormal = 0, kWarn = 1, kAlarm = 2 };
enum class AlarmQuantity { kHeel, kPitch };
enum class AlarmPhase { kRaised, kAcknowledged, kSilenced, kCleared };

[[nodiscard]] const char* to_string(AlarmLevel level);
[[nodiscard]] const char* to_string(AlarmQuantity quantity);
[[nodiscard]] const char* to_string(AlarmPhase phase);
[[nodiscard]] std::optional<AlarmLevel> parse_level(const std::string& s);
[[nodiscard]] std::optional<AlarmQuantity> parse_quantity(const std::string& s);
[[nodiscard]] std::optional<AlarmPhase> parse_phase(const std::string& s);

struct AlarmRule {
  std::string id;                 ///< [A-Za-z0-9_-]{1,32}
  std::string scope = "fleet";    ///< "fleet", "group:NAME" or "boat:ID"
  AlarmQuantity quantity = AlarmQuantity::kHeel;
  double min_deg = -90.0;
  double max_deg = 90.0;
  double hold_s = 0.0;
  double hysteresis_deg = 0.0;
  AlarmLevel level = AlarmLevel::kWarn;  ///< kWarn or kAlarm
  bool enabled = true;

  /// Empty when the rule is valid, else why not.
  [[nodiscard]] std::string validate() const;
  [[nodiscard]] bool applies_to(const std::string& boat_id, const std::string& group) const;
  bool operator==(const AlarmRule&) const = default;
};

struct AlarmEvent {
  std::uint64_t id = 0;
  std::string boat_id;
  std::string rule_id;
  AlarmLevel level = AlarmLevel::kWarn;
  AlarmPhase phase = AlarmPhase::kRaised;
  std::uint64_t raised_ns = 0;
  std::uint64_t acknowledged_ns = 0;  ///< 0: not yet
  std::uint64_t silenced_ns = 0;
  std::uint64_t cleared_ns = 0;
  double value_deg = 0.0;             ///< the angle when it was raised
  std::string message;
};

class AlarmEngine {
 public:
  /// Replaces the rule set. Active events of rules that are gone, disabled or changed are
  /// cleared at `now_ns` and returned.
  std::vector<AlarmEvent> set_rules(std::vector<AlarmRule> rules, std::uint64_t now_ns);
  [[nodiscard]] std::vector<AlarmRule> rules() const;

  /// Feeds one live sample; returns the events that were raised or cleared by it.
  std::vector<AlarmEvent> evaluate(const std::string& boat_id, const std::string& group,
                                   std::uint64_t t_ns, double heel_deg, double pitch_deg);

  /// Acknowledge or silence an active event; nothing if the id is unknown or already cleared.
  std::optional<AlarmEvent> acknowledge(std::uint64_t event_id, std::uint64_t now_ns);
  std::optional<AlarmEvent> silence(std::uint64_t event_id, std::uint64_t now_ns);

  /// Worst level among a boat's active events.
  [[nodiscard]] AlarmLevel level_of(const std::string& boat_id) const;
  [[nodiscard]] std::vector<AlarmEvent> active() const;

  /// After a restart: the stored rules, the active events and the next event id.
  void restore(std::vector<AlarmRule> rules, std::vector<AlarmEvent> active_events,
               std::uint64_t next_event_id);

 private:
  struct Track {
    std::optional<std::uint64_t> outside_since_ns;
    std::optional<std::uint64_t> active_event;  ///< id into active_
  };
  using TrackKey = std::pair<std::string, std::string>;  // (boat, rule)

  std::optional<AlarmEvent> change_phase(std::uint64_t event_id, AlarmPhase phase,
                                         std::uint64_t now_ns);

  mutable std::mutex mutex_;
  std::vector<AlarmRule> rules_;
  std::map<TrackKey, Track> tracks_;
  std::map<std::uint64_t, AlarmEvent> active_;
  std::uint64_t next_id_ = 1;
};

}  // namespace telltale::fusion
