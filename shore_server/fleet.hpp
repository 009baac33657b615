#pragma once
/// \file
/// The fleet model: the latest state of every boat and wearable seen on the domain, thread-safe.
/// The DDS listener writes it, REST handlers and the live stream read it.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "telltale/fusion/alarm_engine.hpp"

namespace telltale::shore {

// The alarm engine is shared with the boats (fusion_core); the shore uses its names directly.
using fusion::AlarmEngine;
using fusion::AlarmEvent;
using fusion::AlarmLevel;
using fusion::AlarmPhase;
using fusion::AlarmQuantity;
using fusion::AlarmRule;
using fusion::parse_level;
using fusion::parse_phase;
using fusion::parse_quantity;
using fusion::to_string;

using SteadyTime = std::chrono::steady_clock::time_point;

/// The values of one attitude sample, in wire units: what the store keeps and reads back
/// (sample_fields.hpp kAttitudeFields), and the part of AttitudeSample a field is added to.
struct AttitudeRow {
  std::uint64_t t_utc_ns = 0;
  std::uint64_t seq = 0;
  double heel_deg = 0.0;
  double pitch_deg = 0.0;
  double heading_deg = 0.0;  ///< NaN when the boat has no heading source
  double heel_rate_deg_s = 0.0;
  double pitch_rate_deg_s = 0.0;
  double yaw_rate_deg_s = 0.0;
  double accel_weight = 0.0;  ///< a float on the wire
  double quality = 0.0;       ///< a float on the wire
};

/// One boat's latest attitude as it arrived: its values, and what only the live path has.
struct AttitudeSample : AttitudeRow {
  std::string boat_id;
  std::uint8_t leds[4] = {0, 0, 0, 0};  ///< left, right, up, down
  std::uint8_t led_count = 0;
  std::uint64_t boot_id = 0;  ///< the boat node's run; seq restarts with a new one
};

/// One boat's GNSS fix, in wire units.
struct FixSample {
  std::string boat_id;
  std::uint64_t seq = 0;
  std::uint64_t t_utc_ns = 0;     ///< boat clock when the fix was read
  std::uint64_t gnss_utc_ns = 0;  ///< the receiver's time of the fix; 0 when none
  double lat_deg = 0.0;           ///< NaN without a fix
  double lon_deg = 0.0;
  double sog_m_s = 0.0;           ///< NaN when unknown
  double cog_deg = 0.0;           ///< NaN when unknown or meaningless (slow)
  std::string fix = "none";       ///< "none", "2d", "3d", "dgnss"
  std::uint32_t satellites = 0;
  double hdop = 0.0;              ///< NaN when unknown
  std::uint64_t boot_id = 0;
};

/// The true wind at the boat, as a wind instrument gave it (a live boat's BoatWind, an imported
/// log's readings), made true by telltale/fusion/wind.hpp.
struct WindSample {
  std::string boat_id;
  std::uint64_t t_utc_ns = 0;
  double from_deg = 0.0;   ///< direction it blows from, clockwise from true north
  double speed_m_s = 0.0;  ///< NaN when the instrument gave none
  std::string source;      ///< "mwd", "mwd_magnetic", "mwv_true", "mwv_apparent", "vkx_apparent"
  std::uint64_t seq = 0;   ///< a live boat's counter (not stored)
  std::uint64_t boot_id = 0;  ///< a live boat's run (not stored)
};

/// A fix older than this is not shown as the boat's position (the receiver went quiet).
inline constexpr std::chrono::seconds kFixFreshFor{5};

struct NodeStatusInfo {
  std::string kind;  ///< "boat", "wearable", "shore"
  std::string software_version;
  double uptime_s = 0.0;
  std::uint32_t sensor_health = 0;
  std::string health_text;
  std::uint64_t samples_published = 0;
  std::string group;
};

struct BoatView {
  AttitudeSample last;
  SteadyTime last_arrival{};
  std::uint64_t arrival_utc_ns = 0;
  bool stale = false;
  std::string alarm_state = "normal";
  std::optional<NodeStatusInfo> status;
  std::uint64_t samples_received = 0;
  /// Arrival (shore clock) minus sample time (boat clock), the smallest over the last 10 s: the
  /// boat's clock offset plus the least network delay. NaN until the first sample.
  double clock_offset_ms = 0.0;
  double window_min_offset_ms = 0.0;
  SteadyTime window_start{};
  std::optional<FixSample> fix;  ///< the latest GNSS fix (any kind)
  SteadyTime fix_arrival{};
  bool fix_fresh = false;  ///< a fix came within kFixFreshFor (set by boats() / boat())
  /// Two nodes publishing under this boat's id: live samples of two runs (boot ids) alternate.
  /// A restart switches run once and never back; two nodes switch back within seconds, over and
  /// over. Set on the first switch back within kDuplicateSwitchWindow, cleared once no switch
  /// back has been seen for kDuplicateClearAfter (one node stopped or was renamed).
  bool duplicate_id = false;
  std::uint64_t duplicate_boot_id = 0;  ///< the other run seen under this id
  std::uint64_t previous_boot_id = 0;   ///< the run before the latest switch
  SteadyTime boot_switch{};             ///< when the run last switched
  SteadyTime duplicate_seen{};          ///< the latest switch back
};

/// See BoatView::duplicate_id.
inline constexpr std::chrono::seconds kDuplicateSwitchWindow{5};
inline constexpr std::chrono::seconds kDuplicateClearAfter{10};

/// One athlete's latest wearable motion, in wire units.
struct WearableSample {
  std::string athlete_id;
  std::uint64_t seq = 0;
  std::uint64_t t_utc_ns = 0;
  std::uint32_t steps = 0;
  double cadence_spm = 0.0;
  std::string gait;  ///< "still", "slow_walk", "walk", "fast_walk", "jog", "run", "unknown"
  std::string
      pose;  ///< "hand_held", "phone_call", "pocket", "arm_swing", "foot", "trunk", "unknown"
  double x_m = 0.0;  ///< east of the start
  double y_m = 0.0;  ///< north of the start
  double heading_deg = 0.0;
  double distance_m = 0.0;
};

struct AthleteView {
  WearableSample last;
  SteadyTime last_arrival{};
  bool stale = false;
};

/// Most boats (and, apart, most athletes) the fleet model holds: a new one beyond this evicts the
/// one silent the longest, so a publisher inventing ids cannot grow the shore without bound.
inline constexpr std::size_t kMaxFleetEntries = 4096;

/// A boat whose clock is off by more than this is flagged (clock_suspect in the API).
inline constexpr double kClockSuspectMs = 100.0;

class FleetModel {
 public:
  /// `stale_after`: a boat with no sample for this long is stale.
  explicit FleetModel(std::chrono::milliseconds stale_after) : stale_after_(stale_after) {}

  /// Records a sample and returns the boat's view after it.
  BoatView update(const AttitudeSample& sample, SteadyTime arrival, std::uint64_t arrival_utc_ns);
  void update_status(const std::string& node_id, const NodeStatusInfo& status);
  /// Records a GNSS fix of a known boat (a fix before the boat's first attitude is not shown
  /// live; the store keeps it). Returns the boat's view after it.
  std::optional<BoatView> update_fix(const FixSample& fix, SteadyTime arrival);
  /// Marks boats silent for longer than stale_after as stale; returns those that just went stale.
  std::vector<BoatView> sweep(SteadyTime now);

  /// Sets a boat's alarm state ("normal", "warn", "alarm"); its view if the boat is known.
  std::optional<BoatView> set_alarm_state(const std::string& boat_id, const std::string& state);

  /// Forgets boats and athletes silent for longer than `older_than` (a boat known only from a
  /// stored alarm, never heard, is kept); returns their ids. The model is bounded in time by
  /// this and in size by kMaxFleetEntries.
  std::vector<std::string> forget(SteadyTime now, std::chrono::seconds older_than);

  [[nodiscard]] std::vector<BoatView> boats() const;
  [[nodiscard]] std::optional<BoatView> boat(const std::string& boat_id) const;

  AthleteView update(const WearableSample& sample, SteadyTime arrival);
  /// Athletes silent for longer than stale_after that just went stale.
  std::vector<AthleteView> sweep_athletes(SteadyTime now);
  [[nodiscard]] std::vector<AthleteView> athletes() const;
  [[nodiscard]] std::optional<AthleteView> athlete(const std::string& athlete_id) const;

 private:
  std::map<std::string, AthleteView> athletes_;
  std::chrono::milliseconds stale_after_;
  mutable std::mutex mutex_;
  std::map<std::string, BoatView> boats_;
};

}  // namespace telltale::shore
