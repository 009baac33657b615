#pragma once
/// \file
/// The shore's one wire module: every conversion between a topic type of idl/telltale.idl and the
/// shore's own record, both ways, and every enum's name table. Adding a member to a wire type (a
/// new type on a new topic, idl/README.md) is one edit here on the shore's side of the wire;
/// tests/unit/wire_test.cpp holds each pair to a round trip (to_wire, then from_wire, gives the
/// record back, for every enum value, NaN staying NaN).
///
/// What the shore does not carry, on purpose: `BoatAttitude.leds.level` (the boat's own alarm
/// colour). The shore evaluates the same rules on the same samples (AlarmService) and its state is
/// the one it shows and acknowledges; from_wire ignores the boat's level and to_wire writes
/// ALARM_LEVEL_NORMAL (idl/README.md, "What the shore reads of each type").

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fleet.hpp"
#include "store.hpp"
#include "telltale.h"

namespace telltale::shore {

/// One row of an enum's table: a wire literal and what the shore calls it.
template <class Wire, class Shore>
struct EnumRow {
  Wire wire;
  Shore shore;
};

/// Every wire enum the shore reads or writes, in the IDL's order, each literal once. The shore's
/// side is a name (JSON, SQL) or the alarm engine's enum (fusion_core).
inline constexpr std::array<EnumRow<msg::NodeKind, std::string_view>, 3> kNodeKinds = {{
    {msg::NODE_KIND_BOAT, "boat"},
    {msg::NODE_KIND_WEARABLE, "wearable"},
    {msg::NODE_KIND_SHORE, "shore"},
}};
inline constexpr std::array<EnumRow<msg::FixKind, std::string_view>, 4> kFixKinds = {{
    {msg::FIX_KIND_NONE, "none"},
    {msg::FIX_KIND_2D, "2d"},
    {msg::FIX_KIND_3D, "3d"},
    {msg::FIX_KIND_DGNSS, "dgnss"},
}};
inline constexpr std::array<EnumRow<msg::Gait, std::string_view>, 7> kGaits = {{
    {msg::GAIT_STILL, "still"},
    {msg::GAIT_SLOW_WALK, "slow_walk"},
    {msg::GAIT_WALK, "walk"},
    {msg::GAIT_FAST_WALK, "fast_walk"},
    {msg::GAIT_JOG, "jog"},
    {msg::GAIT_RUN, "run"},
    {msg::GAIT_UNKNOWN, "unknown"},
}};
inline constexpr std::array<EnumRow<msg::Pose, std::string_view>, 7> kPoses = {{
    {msg::POSE_HAND_HELD, "hand_held"},
    {msg::POSE_PHONE_CALL, "phone_call"},
    {msg::POSE_POCKET, "pocket"},
    {msg::POSE_ARM_SWING, "arm_swing"},
    {msg::POSE_FOOT, "foot"},
    {msg::POSE_UNKNOWN, "unknown"},
    {msg::POSE_TRUNK, "trunk"},
}};
inline constexpr std::array<EnumRow<msg::AlarmLevel, AlarmLevel>, 3> kAlarmLevels = {{
    {msg::ALARM_LEVEL_NORMAL, AlarmLevel::kNormal},
    {msg::ALARM_LEVEL_WARN, AlarmLevel::kWarn},
    {msg::ALARM_LEVEL_ALARM, AlarmLevel::kAlarm},
}};
inline constexpr std::array<EnumRow<msg::AlarmQuantity, AlarmQuantity>, 2> kAlarmQuantities = {{
    {msg::ALARM_QUANTITY_HEEL, AlarmQuantity::kHeel},
    {msg::ALARM_QUANTITY_PITCH, AlarmQuantity::kPitch},
}};
inline constexpr std::array<EnumRow<msg::AlarmPhase, AlarmPhase>, 4> kAlarmPhases = {{
    {msg::ALARM_PHASE_RAISED, AlarmPhase::kRaised},
    {msg::ALARM_PHASE_ACKNOWLEDGED, AlarmPhase::kAcknowledged},
    {msg::ALARM_PHASE_SILENCED, AlarmPhase::kSilenced},
    {msg::ALARM_PHASE_CLEARED, AlarmPhase::kCleared},
}};

/// The shore's side of a wire literal; `off_table` for a value no literal has (a hostile or newer
/// writer's).
template <class Wire, class Shore, std::size_t N>
[[nodiscard]] constexpr Shore shore_of(const std::array<EnumRow<Wire, Shore>, N>& table, Wire w,
                                       Shore off_table) {
  for (const auto& row : table)
    if (row.wire == w) return row.shore;
  return off_table;
}

/// The wire literal of a shore value; nullopt when the table has none.
template <class Wire, class Shore, std::size_t N>
[[nodiscard]] constexpr std::optional<Wire> wire_of(
    const std::array<EnumRow<Wire, Shore>, N>& table, const Shore& s) {
  for (const auto& row : table)
    if (row.shore == s) return row.wire;
  return std::nullopt;
}

/// A fix kind's name ("none", "2d", "3d", "dgnss") is one of the table's.
[[nodiscard]] bool known_fix_kind(std::string_view name);

// --- topic types, both ways ----------------------------------------------------------------------

/// BoatAttitude (topics telltale_boat_attitude and telltale_boat_backfill). leds.level: see above.
[[nodiscard]] AttitudeSample from_wire(const msg::BoatAttitude& m);
[[nodiscard]] msg::BoatAttitude to_wire(const AttitudeSample& s);

/// BoatFix. A kind off the enum reads as "invalid", which the door (ingest.hpp) refuses.
[[nodiscard]] FixSample from_wire(const msg::BoatFix& m);
[[nodiscard]] msg::BoatFix to_wire(const FixSample& f);

/// BoatWind (a live boat's wind instrument). seq and boot_id are read, not stored: a reading
/// is kept by its boat and time, like an imported one.
[[nodiscard]] WindSample from_wire(const msg::BoatWind& m);

/// WearableMotion. A gait or pose off the enum reads as "unknown".
[[nodiscard]] WearableSample from_wire(const msg::WearableMotion& m);
[[nodiscard]] msg::WearableMotion to_wire(const WearableSample& w);

/// NodeStatus: the record without its id and time (the door checks those apart).
[[nodiscard]] NodeStatusInfo from_wire(const msg::NodeStatus& m);
[[nodiscard]] msg::NodeStatus to_wire(const std::string& node_id, const NodeStatusInfo& s,
                                      std::uint64_t t_utc_ns);

/// AlarmRule, pushed by the shore with the rule set's revision.
[[nodiscard]] AlarmRule from_wire(const msg::AlarmRule& m);
[[nodiscard]] msg::AlarmRule to_wire(const AlarmRule& r, std::uint64_t revision);

/// AlarmEvent: the wire carries the time of the event's current phase only, in t_utc_ns;
/// from_wire sets that phase's time and leaves the others 0.
[[nodiscard]] AlarmEvent from_wire(const msg::AlarmEvent& m);
[[nodiscard]] msg::AlarmEvent to_wire(const AlarmEvent& e);

/// ShoreAck, the shore's receipt for one run of one boat, stamped with the shore's clock.
[[nodiscard]] Store::Ack from_wire(const msg::ShoreAck& m);
[[nodiscard]] msg::ShoreAck to_wire(const Store::Ack& a, std::uint64_t t_utc_ns);

}  // namespace telltale::shore
