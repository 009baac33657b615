#pragma once
/// \file
/// Positions on the water: the one place a latitude/longitude pair becomes metres (the boat's
/// GNSS gate, the importer's speed and course from positions). A sphere of the Earth's mean
/// radius: under 0.5 % from the ellipsoid, far inside any receiver's error over the distances a
/// boat sails between two fixes.

#include <algorithm>
#include <cmath>

namespace telltale::fusion {

inline constexpr double kEarthRadiusM = 6371008.8;  ///< mean radius (IUGG)

/// Great-circle distance, metres (haversine).
[[nodiscard]] inline double distance_m(double lat1_deg, double lon1_deg, double lat2_deg,
                                       double lon2_deg) {
  constexpr double kRad = M_PI / 180.0;
  const double p1 = lat1_deg * kRad, p2 = lat2_deg * kRad;
  const double dp = p2 - p1, dl = (lon2_deg - lon1_deg) * kRad;
  const double a = std::sin(dp / 2) * std::sin(dp / 2) +
                   std::cos(p1) * std::cos(p2) * std::sin(dl / 2) * std::sin(dl / 2);
  return 2.0 * kEarthRadiusM * std::asin(std::min(1.0, std::sqrt(a)));
}

/// Where the second position lies from the first, metres east and north, on the plane touching
/// the sphere between them (exact to millimetres over the few hundred metres between fixes);
/// across the antimeridian too.
struct EastNorth {
  double east_m = 0.0;
  double north_m = 0.0;
};
[[nodiscard]] inline EastNorth offset_m(double lat1_deg, double lon1_deg, double lat2_deg,
                                        double lon2_deg) {
  constexpr double kRad = M_PI / 180.0;
  double dlon = lon2_deg - lon1_deg;
  dlon -= 360.0 * std::round(dlon / 360.0);
  const double mid = 0.5 * (lat1_deg + lat2_deg) * kRad;
  return {dlon * kRad * kEarthRadiusM * std::cos(mid), (lat2_deg - lat1_deg) * kRad * kEarthRadiusM};
}

}  // namespace telltale::fusion
