#pragma once
/// \file
/// `boat_node --source sim`'s GNSS: the simulated windward-leeward race of the fusion core
/// (telltale/fusion/sim/course.hpp) as receiver epochs.
///
/// Known gap: the IMU simulator beside it runs its own scenario; heel and pitch do not yet
/// follow the tacks of this course.

#include <cstdint>

#include "nmea_gnss.hpp"
#include "telltale/fusion/sim/course.hpp"

namespace telltale::boat {

using CourseSimParams = fusion::sim::CourseParams;

class CourseSim {
 public:
  CourseSim(std::uint64_t seed, CourseSimParams p = {}) : sim_(seed, p) {}
  /// Advances to `t_s` (seconds since start, increasing) and returns the receiver's epoch then.
  sensors::GnssReading at(double t_s, std::uint64_t utc_ns);
  /// True wind direction now, degrees: for tests.
  [[nodiscard]] double wind_from_deg() const { return sim_.wind_from_deg(); }
  [[nodiscard]] bool upwind() const { return sim_.upwind(); }
  [[nodiscard]] int tacks() const { return sim_.tacks(); }

 private:
  fusion::sim::CourseSim sim_;
};

}  // namespace telltale::boat
