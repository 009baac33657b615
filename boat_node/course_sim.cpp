// The simulated race course as receiver epochs (see course_sim.hpp).
#include "course_sim.hpp"

#include <limits>

namespace telltale::boat {

sensors::GnssReading CourseSim::at(double t_s, std::uint64_t utc_ns) {
  const fusion::sim::CourseState s = race_->fix_at(t_s);
  sensors::GnssReading r;
  r.lat_deg = s.lat_deg;
  r.lon_deg = s.lon_deg;
  r.sog_m_s = s.sog_m_s;
  r.cog_deg = s.cog_deg;
  r.fix = sensors::GnssFixKind::k3D;
  r.satellites = 12;
  r.hdop = 0.8;
  r.time_of_day_s = std::numeric_limits<double>::quiet_NaN();
  r.utc_ns = utc_ns;
  return r;
}

}  // namespace telltale::boat
