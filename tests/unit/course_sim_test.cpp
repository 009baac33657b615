// The simulated race course (boat_node/course_sim.hpp): a fleet that sails, not one at a dock.
#include "course_sim.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "gnss_gate.hpp"

using namespace telltale::boat;

TEST(CourseSim, BoatsBeatTackRoundTheMarksAndDifferFromEachOther) {
  CourseSimParams p;
  std::vector<double> finals;
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    CourseSim sim(seed, p);
    GnssGate gate;
    double max_up_m = 0.0, min_up_m = 1e9, dist = 0.0;
    double prev_lat = 0, prev_lon = 0;
    int upwind_legs = 0;
    bool was_up = true;
    for (int i = 0; i <= 20 * 60 * 10; ++i) {  // 20 min at 10 Hz
      const double t = i * 0.1;
      const auto r = sim.at(t, 0);
      const auto f = gate.on_epoch(r, t, 0);
      ASSERT_TRUE(f) << "the simulator never jumps, t=" << t;
      // Progress along the wind axis (north-east of the leeward mark, wind from 255).
      const double n = (r.lat_deg - p.origin_lat_deg) * 111195.0;
      const double e = (r.lon_deg - p.origin_lon_deg) * 111195.0 * std::cos(p.origin_lat_deg * M_PI / 180);
      const double up = e * std::sin(p.wind_from_deg * M_PI / 180) + n * std::cos(p.wind_from_deg * M_PI / 180);
      max_up_m = std::max(max_up_m, up);
      if (i > 3000) min_up_m = std::min(min_up_m, up);
      if (i > 0) dist += distance_m(prev_lat, prev_lon, r.lat_deg, r.lon_deg);
      prev_lat = r.lat_deg;
      prev_lon = r.lon_deg;
      if (sim.upwind() && !was_up) ++upwind_legs;
      was_up = sim.upwind();
      EXPECT_LT(r.sog_m_s, 8.0);
    }
    EXPECT_GT(max_up_m, p.leg_m - 20.0) << "reached the windward mark, seed " << seed;
    EXPECT_LT(min_up_m, 30.0) << "came back down to the leeward mark, seed " << seed;
    EXPECT_GE(upwind_legs, 1) << "rounded the leeward mark, seed " << seed;
    EXPECT_GE(sim.tacks(), 4) << "tacked and gybed, seed " << seed;
    // Speeds of a dinghy: 20 min between 2 and 6 m/s on average.
    EXPECT_GT(dist / 1200.0, 2.0);
    EXPECT_LT(dist / 1200.0, 6.0);
    finals.push_back(prev_lat);
  }
  for (std::size_t i = 1; i < finals.size(); ++i) EXPECT_NE(finals[i], finals[0]);
}
