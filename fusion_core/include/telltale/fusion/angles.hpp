#pragma once
/// \file
/// Angles: the one definition of wrapping an angle and of the difference of two. Compass
/// angles (course, heading, wind direction) are degrees clockwise from north; the PDR's heading
/// is radians. A value that is not finite (NaN, +-Inf) comes back NaN from every function.

#include <cmath>

namespace telltale::fusion {

/// Angle wrapped to [0, 360). fmod keeps the sign of its argument; a tiny negative angle plus
/// 360 rounds to 360 itself, which is 0 here (a course of 360 is north, and [0, 360) holds it).
[[nodiscard]] inline double wrap_360_deg(double a_deg) {
  double w = std::fmod(a_deg, 360.0);
  if (w < 0.0) w += 360.0;
  return w >= 360.0 ? 0.0 : w;
}

/// Angle wrapped to [-180, 180).
[[nodiscard]] inline double wrap_180_deg(double a_deg) {
  double w = std::fmod(a_deg + 180.0, 360.0);
  if (w < 0.0) w += 360.0;
  return w - 180.0;
}

/// a - b wrapped to (-180, 180], for any a and b. std::remainder is exact (no rounding: the
/// result is a - b - 360 n exactly for the nearest integer n), so an unwrapped course many turns
/// from b (a day of 720s one way) still gives the right difference; the tie at -180 is 180.
[[nodiscard]] inline double diff_180_deg(double a_deg, double b_deg) {
  const double d = std::remainder(a_deg - b_deg, 360.0);
  return d == -180.0 ? 180.0 : d;
}

/// Angle wrapped to [0, 2 pi) (radians; the same rule as wrap_360_deg).
[[nodiscard]] inline double wrap_2pi(double a_rad) {
  double w = std::fmod(a_rad, 2.0 * M_PI);
  if (w < 0.0) w += 2.0 * M_PI;
  return w >= 2.0 * M_PI ? 0.0 : w;
}

}  // namespace telltale::fusion
