#pragma once
/// \file
/// `boat_node --source sim`'s GNSS: the simulated windward-leeward race of the fusion core
/// (telltale/fusion/sim/course.hpp) as receiver epochs, one per 0.05 s step of the course.
/// Sharing its RaceCourse with the IMU's race scenario (make_imu_source) makes the fixes and the
/// attitude one boat's: the node then feeds these fixes' speed and course to the attitude filter
/// as it does a real receiver's.

#include <cstdint>
#include <memory>

#include "nmea_gnss.hpp"
#include "telltale/fusion/sim/race.hpp"

namespace telltale::boat {

using CourseSimParams = fusion::sim::CourseParams;

class CourseSim {
 public:
  /// The race of `seed` on its own.
  CourseSim(std::uint64_t seed, CourseSimParams p = {})
      : race_(std::make_shared<fusion::sim::RaceCourse>(seed, p)) {}
  /// The race a race scenario sails (the same boat).
  explicit CourseSim(std::shared_ptr<fusion::sim::RaceCourse> race) : race_(std::move(race)) {}
  /// The receiver's epoch at `t_s` (seconds since start, increasing): the course's last step
  /// at or before it.
  sensors::GnssReading at(double t_s, std::uint64_t utc_ns);
  /// True wind direction now, degrees: for tests.
  [[nodiscard]] double wind_from_deg() const { return race_->course().wind_from_deg(); }
  [[nodiscard]] bool upwind() const { return race_->course().upwind(); }
  [[nodiscard]] int tacks() const { return race_->course().tacks(); }

 private:
  std::shared_ptr<fusion::sim::RaceCourse> race_;
};

}  // namespace telltale::boat
