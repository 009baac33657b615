#pragma once
/// \file
/// A boat sailing a windward-leeward race, for `--source sim`: the GNSS side of the simulator.
/// The wind shifts (two slow oscillations, +-8 deg) and gusts; the boat beats at 42 deg to the
/// true wind, tacking on the layline to the windward mark, and runs at 150 deg, gybing on the
/// layline to the leeward mark; speed from a simple polar scaled by a per-boat factor, halved
/// through a tack or gybe and recovering over ~8 s. Every boat differs by its seed: start line
/// position, speed factor, wind phase as it sees it, first tack.
///
/// Known gap: the IMU simulator beside it runs its own scenario; heel and pitch do not yet
/// follow the tacks of this course.

#include <cstdint>
#include <random>

#include "nmea_gnss.hpp"

namespace telltale::boat {

struct CourseSimParams {
  double origin_lat_deg = 54.3440;  ///< leeward mark (Kiel outer fjord: open water)
  double origin_lon_deg = 10.1900;
  double leg_m = 600.0;             ///< leeward to windward mark
  double wind_from_deg = 255.0;     ///< mean true wind direction
  double wind_m_s = 6.0;            ///< mean true wind speed
};

class CourseSim {
 public:
  CourseSim(std::uint64_t seed, CourseSimParams p = {});
  /// Advances to `t_s` (seconds since start, increasing) and returns the receiver's epoch then.
  sensors::GnssReading at(double t_s, std::uint64_t utc_ns);
  /// True wind direction now, degrees: for tests.
  [[nodiscard]] double wind_from_deg() const { return wind_from_deg_; }
  [[nodiscard]] bool upwind() const { return upwind_; }
  [[nodiscard]] int tacks() const { return tacks_; }

 private:
  void step(double dt);
  CourseSimParams p_;
  std::mt19937_64 rng_;
  double t_s_ = 0.0;
  double x_m_ = 0.0, y_m_ = 0.0;  ///< east, north of the leeward mark
  double heading_deg_ = 0.0;
  double speed_m_s_ = 0.0;
  double factor_ = 1.0;
  double phase1_ = 0.0, phase2_ = 0.0;
  double gust_ = 0.0;
  double wind_from_deg_ = 0.0;
  bool upwind_ = true;
  double corridor_deg_ = 20.0;    ///< how far off the axis the mark may bear before a tack
  int side_ = 1;                  ///< +1 starboard tack (wind over the starboard side), -1 port
  double manoeuvre_s_ = 1e9;      ///< time since the last tack or gybe
  int tacks_ = 0;
  double last_fix_s_ = 0.0;
  double err_e_m_ = 0.0, err_n_m_ = 0.0;  ///< the receiver's slowly wandering position error
};

}  // namespace telltale::boat
