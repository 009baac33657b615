#include "telltale/fusion/wind.hpp"

#include <algorithm>
#include <vector>

#include "telltale/fusion/angles.hpp"

namespace telltale::fusion {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDegToRad = M_PI / 180.0;
constexpr double kStillM_s = 0.3;  // below it a GNSS course is noise (the boat's GNSS gate's)

}  // namespace

const char* nmea_wind_source(WindRef r) {
  switch (r) {
    case WindRef::kTrueDirection: return "mwd";
    case WindRef::kMagneticDirection: return "mwd_magnetic";
    case WindRef::kTrueOffBow: return "mwv_true";
    case WindRef::kApparent: return "mwv_apparent";
  }
  return "";
}

TrueWind true_wind(const WindReading& r, double heading_deg, double sog_m_s, double cog_deg,
                   double declination_deg) {
  if (!std::isfinite(r.angle_deg)) return {};
  const double speed = std::isfinite(r.speed_m_s) && r.speed_m_s >= 0.0 ? r.speed_m_s : kNaN;
  const double bow = std::isfinite(heading_deg) ? heading_deg : cog_deg;
  switch (r.ref) {
    case WindRef::kTrueDirection:
      return {wrap_360_deg(r.angle_deg), speed};
    case WindRef::kMagneticDirection:
      return {wrap_360_deg(r.angle_deg + declination_deg), speed};
    case WindRef::kTrueOffBow:
      return {wrap_360_deg(bow + r.angle_deg), speed};
    case WindRef::kApparent:
      break;
  }
  if (!std::isfinite(speed) || !std::isfinite(sog_m_s) || !std::isfinite(bow)) return {};
  const bool moving = sog_m_s >= kStillM_s;
  if (moving && !std::isfinite(cog_deg)) return {};
  const double a_from = (bow + r.angle_deg) * kDegToRad;
  // Air over the ground (north, east) = the air past the boat + the boat over the ground.
  double wn = -speed * std::cos(a_from), we = -speed * std::sin(a_from);
  if (moving) {
    wn += sog_m_s * std::cos(cog_deg * kDegToRad);
    we += sog_m_s * std::sin(cog_deg * kDegToRad);
  }
  const double ground = std::hypot(wn, we);
  if (ground < 0.05) return {kNaN, ground};  // the boat's own motion cancelled it: no direction
  return {wrap_360_deg(std::atan2(-we, -wn) / kDegToRad), ground};
}

std::optional<WindMean> wind_mean(std::span<const double> from_deg) {
  if (from_deg.size() < kMinWindReadings) return std::nullopt;
  double s = 0.0, c = 0.0;
  for (const double d : from_deg) {
    s += std::sin(d * kDegToRad);
    c += std::cos(d * kDegToRad);
  }
  const double r = std::hypot(s, c) / static_cast<double>(from_deg.size());
  if (r < 1e-6) return std::nullopt;
  const double mean = std::atan2(s, c) / kDegToRad;
  std::vector<double> off;
  off.reserve(from_deg.size());
  for (const double d : from_deg) off.push_back(std::remainder(d - mean, 360.0));
  const auto mid = off.begin() + static_cast<std::ptrdiff_t>(off.size() / 2);
  std::nth_element(off.begin(), mid, off.end());
  return WindMean{wrap_360_deg(mean + *mid),
                  std::sqrt(-2.0 * std::log(std::min(1.0, r))) / kDegToRad};
}

}  // namespace telltale::fusion
