#pragma once
/// \file
/// What heel does to speed: the coach's question of heel ("which heel is fast?"), answered from
/// a session's attitude and GNSS fixes. Pure functions, no store, no HTTP.
///
/// Points of sailing need the wind, which the boat does not measure. It is read from the track:
/// a boat sailing upwind holds courses 30-55 deg either side of the wind, so the wind direction
/// is the one that puts the most sailing time in that band on both sides. That alone cannot
/// tell upwind from downwind (gybing angles are the same band seen from 180 deg away), so the
/// heel decides: upwind, a boat heels to leeward, away from the side the wind comes over; the
/// direction whose "upwind" time shows that agreement more strongly wins. A coach who knows the
/// wind passes it instead (`wind_from_deg`).

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

namespace telltale::shore {

/// One attitude sample joined with the fix current at its time.
struct SailingPoint {
  double dt_s = 0.0;      ///< time this sample stands for (gap-capped like the heel bands)
  double heel_deg = 0.0;  ///< + starboard down
  double sog_m_s = 0.0;   ///< NaN: no fix at that time
  double cog_deg = 0.0;   ///< NaN: no fix or too slow for a course
};

/// Minimum speed for a point of sailing: below it the boat is drifting or stopped.
inline constexpr double kSailingMinSog_m_s = 0.5;

/// The wind direction read from the points (see the file comment); nothing when less than a
/// fifth of the sailing time is in the upwind band of any direction (no beat in the session).
[[nodiscard]] std::optional<double> estimate_wind_from_deg(const std::vector<SailingPoint>& pts);

struct HeelSpeedBand {
  double from_deg = 0.0, to_deg = 0.0;
  double seconds = 0.0;
  double mean_sog_m_s = 0.0;  ///< NaN when no time in the band
};

/// Heel bands (5 deg, -30..30, the outer bands open-ended) per point of sailing and tack.
struct HeelSpeed {
  static constexpr std::array<double, 15> kEdges = {-90, -30, -25, -20, -15, -10, -5, 0,
                                                    5,   10,  15,  20,  25,  30,  90};
  using Bands = std::array<HeelSpeedBand, kEdges.size() - 1>;
  std::optional<double> wind_from_deg;  ///< what the split used; none: no split was possible
  bool wind_estimated = false;
  Bands upwind_port{}, upwind_starboard{}, downwind_port{}, downwind_starboard{};
  double reaching_s = 0.0;  ///< 70-110 deg off the wind
  double slow_s = 0.0;      ///< below kSailingMinSog_m_s, or no course
  double no_fix_s = 0.0;    ///< no GNSS fix at the time
  double unsplit_s = 0.0;   ///< sailing, but no wind to split by
  double total_s = 0.0;     ///< every point's dt: the sum of all the above
};

/// The table. `wind_from_deg`: the coach's wind; none: estimated from the points.
[[nodiscard]] HeelSpeed heel_speed(const std::vector<SailingPoint>& pts,
                                   std::optional<double> wind_from_deg);

}  // namespace telltale::shore
