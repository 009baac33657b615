#pragma once
/// \file
/// The boat's GNSS gate: what a receiver epoch must be before it goes on the wire as a fix.
/// Pure logic (no devices), one instance per receiver, not thread-safe.
///
/// Rules, each from what a boat and a receiver can physically do:
/// - No fix (or a fix without a position) goes out flagged FIX_KIND_NONE with NaN position, so
///   the shore shows "no fix", never the last good position as if it were new.
/// - A jump: the distance from the last accepted position is more than a boat can sail in the
///   time between (max_speed_m_s, 30 m/s: faster than any foiling dinghy or coach RIB) plus the
///   receiver's own scatter (noise_sigma_m x max(1, HDOP), 6 sigma: 3 for each of the two
///   positions). Also a reported speed above max_speed_m_s. Rejected and counted. When
///   `reanchor_after` rejected fixes in a row agree with each other (each step passes the same
///   rule), the earlier anchor was the outlier or the receiver really moved (a boat carried on a
///   trailer while switched off): the new track is accepted and counted as a re-anchor.
/// - COG below min_cog_speed_m_s (0.3 m/s) is NaN: a receiver's velocity noise is ~0.05-0.1 m/s,
///   so there the course is mostly noise (tens of degrees).
/// - A repeat: an epoch with the same GNSS time as the last accepted fix is the same fix reported
///   again (gpsd sends a report per sentence of an epoch); dropped and counted.
/// - GNSS time: the receiver's time of day with RMC's date, or with the boat clock's date when
///   only GGA/GNS came (the day that puts it nearest the boat clock). The offset boat - GNSS is
///   what the boat's clock is wrong by (plus the sentence's latency, tens of ms).

#include <cstdint>
#include <limits>
#include <optional>

#include "nmea_gnss.hpp"
#include "telltale/fusion/geo.hpp"

namespace telltale::boat {

struct GnssGateParams {
  double max_speed_m_s = 30.0;
  double noise_sigma_m = 2.5;
  double min_cog_speed_m_s = 0.3;
  int reanchor_after = 3;
};

struct GnssFix {
  double lat_deg = 0.0;  ///< NaN without a fix
  double lon_deg = 0.0;
  double sog_m_s = 0.0;
  double cog_deg = 0.0;
  sensors::GnssFixKind fix = sensors::GnssFixKind::kNone;
  int satellites = 0;
  double hdop = 0.0;
  std::uint64_t gnss_utc_ns = 0;  ///< 0 when the receiver gave no time
  std::uint64_t t_boat_ns = 0;    ///< the boat clock at the epoch's arrival: the record's time
};

struct GnssGateStats {
  std::uint64_t epochs = 0;    ///< every epoch seen
  std::uint64_t fixes = 0;     ///< accepted with a position
  std::uint64_t no_fix = 0;    ///< passed on as "no fix"
  std::uint64_t jumps = 0;     ///< rejected: faster than a boat
  std::uint64_t reanchors = 0;
  std::uint64_t repeats = 0;   ///< the same epoch again
};

class GnssGate {
 public:
  explicit GnssGate(GnssGateParams p = {}) : p_(p) {}
  /// One epoch received at `t_s` (monotonic seconds) when the boat clock (the node's RunClock)
  /// read `boat_utc_ns`, which becomes the fix's time. Returns the fix to publish, or nothing
  /// when the epoch is rejected.
  std::optional<GnssFix> on_epoch(const sensors::GnssReading& r, double t_s,
                                  std::uint64_t boat_utc_ns);
  [[nodiscard]] const GnssGateStats& stats() const { return stats_; }
  /// Boat clock minus GNSS time at the last epoch with a time, seconds; NaN before one.
  [[nodiscard]] double clock_offset_s() const { return clock_offset_s_; }

 private:
  struct Point {
    double lat_deg, lon_deg, t_s, hdop;
  };
  [[nodiscard]] bool plausible(const Point& from, const Point& to) const;
  GnssGateParams p_;
  GnssGateStats stats_;
  std::optional<Point> anchor_;
  Point pending_[8]{};
  int n_pending_ = 0;
  double clock_offset_s_ = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t last_gnss_utc_ns_ = 0;  ///< of the last accepted fix
};

/// Great-circle distance (fusion_core's geo.hpp, the one definition).
using fusion::distance_m;

/// UTC nanoseconds of a receiver's time of day; the date from RMC (ddmmyy) when given, else the
/// day that puts it nearest `near_utc_ns`. 0 when time_of_day_s is NaN.
[[nodiscard]] std::uint64_t gnss_utc_ns(double time_of_day_s, int date_ddmmyy,
                                        std::uint64_t near_utc_ns);

}  // namespace telltale::boat
