#pragma once
/// \file
/// A wind instrument's reading made the true wind: the one conversion the boat node (live, from
/// its NMEA line) and the shore's importer (NMEA logs, VKX) share.
///
/// The true wind here is the ground wind: how the air moves over the ground, the frame of the
/// course-over-ground bisectors the manoeuvre analysis estimates the wind from, and of every GPS
/// tool's wind. A current makes it differ from the wind over the water by the current's velocity.
///  - kTrueDirection (NMEA MWD): a direction, as given.
///  - kMagneticDirection (MWD without its true field): made true with the declination.
///  - kTrueOffBow (NMEA MWV T): the instrument's true wind angle off the bow, turned to the
///    compass by the heading; without a heading the COG stands in (the few degrees of leeway read
///    as wind direction).
///  - kApparent (NMEA MWV R, VKX wind rows): the air moves past the boat at -AWS along (heading +
///    AWA); adding the boat's own velocity over the ground leaves how the air moves over the
///    ground. Below 0.3 m/s a boat has no meaningful COG and its velocity is taken as zero.
/// NaN direction when the inputs do not suffice (no heading and no course, a wind too light to
/// have one).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>

namespace telltale::fusion {

enum class WindRef : std::uint8_t { kApparent, kTrueOffBow, kMagneticDirection, kTrueDirection };

/// One reading: `angle_deg` off the bow (clockwise, 0..360) for kApparent and kTrueOffBow, the
/// direction it blows from for the others; `speed_m_s` NaN when the instrument gave none.
struct WindReading {
  WindRef ref = WindRef::kApparent;
  double angle_deg = std::numeric_limits<double>::quiet_NaN();
  double speed_m_s = std::numeric_limits<double>::quiet_NaN();
};

/// Which of two readings of one instant to keep: a direction needs nothing of the boat, a true
/// angle needs the heading, an apparent one the heading and the velocity.
[[nodiscard]] constexpr int wind_rank(WindRef r) {
  switch (r) {
    case WindRef::kTrueDirection: return 3;
    case WindRef::kMagneticDirection: return 2;
    case WindRef::kTrueOffBow: return 1;
    case WindRef::kApparent: return 0;
  }
  return 0;
}

/// "mwd", "mwd_magnetic", "mwv_true", "mwv_apparent": the stored source of an NMEA reading.
[[nodiscard]] const char* nmea_wind_source(WindRef r);

struct TrueWind {
  double from_deg = std::numeric_limits<double>::quiet_NaN();  ///< [0, 360), true north
  double speed_m_s = std::numeric_limits<double>::quiet_NaN();
};

/// The true (ground) wind of a reading on a boat heading `heading_deg` (true; NaN: none) and
/// moving over the ground at `sog_m_s` towards `cog_deg`; `declination_deg` east positive (NaN:
/// unknown) for a magnetic direction.
[[nodiscard]] TrueWind true_wind(const WindReading& r, double heading_deg, double sog_m_s,
                                 double cog_deg, double declination_deg);

/// A wind instrument's direction over a stretch of readings: the circular mean moved by the
/// median of the readings' differences from it (a median, so a few readings taken head to wind or
/// in a knockdown do not pull it), and the spread as the circular standard deviation
/// sqrt(-2 ln R). Fewer than kMinWindReadings (a few seconds of an instrument), or readings all
/// round the compass: nullopt.
inline constexpr std::size_t kMinWindReadings = 10;
struct WindMean {
  double from_deg = 0.0;
  double spread_deg = 0.0;
};
[[nodiscard]] std::optional<WindMean> wind_mean(std::span<const double> from_deg);

}  // namespace telltale::fusion
