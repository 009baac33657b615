// Speed and course from positions for logs without them (course_from_positions.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "course_from_positions.hpp"
#include "import_support.hpp"

namespace telltale::shore::import {
namespace {

using namespace test;

constexpr std::uint64_t kT0 = 1770548200ULL * 1000000000ULL;
constexpr double kLat = 39.4, kMPerDegLat = 6371008.8 * M_PI / 180.0;

ImportPoint at(double t_s, double east_m, double north_m) {
  ImportPoint p;
  p.t_utc_ns = kT0 + static_cast<std::uint64_t>(std::llround(t_s * 1e9));
  p.lat_deg = kLat + north_m / kMPerDegLat;
  p.lon_deg = 2.5 + east_m / (kMPerDegLat * std::cos(kLat * M_PI / 180.0));
  return p;
}

TEST(ImportCourse, WatchTrackGetsSpeedAndCourseFromItsPositions) {
  Collect out;
  CourseFromPositions stage(out);
  // 1 Hz: 10 s east at 3 m/s, then north at 2 m/s; a 30 s pause in the log; then drifting at
  // 0.1 m/s; a point that states its own speed and course keeps them.
  double e = 0.0, n = 0.0, t = 0.0;
  for (int i = 0; i <= 10; ++i, t += 1.0, e += 3.0) stage.point(at(t, e, n));
  e -= 3.0;
  for (int i = 0; i < 10; ++i) {
    t += 0.0;
    n += 2.0;
    stage.point(at(t, e, n));
    t += 1.0;
  }
  t += 30.0;
  for (int i = 0; i < 5; ++i, t += 1.0, n += 0.1) stage.point(at(t, e, n));
  ImportPoint stated = at(t, e, n);
  stated.sog_m_s = 4.5;
  stated.cog_deg = 10.0;
  stage.point(stated);
  stage.finish();
  ASSERT_EQ(out.points.size(), 27u) << "every point passed on, the last one too";
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_NEAR(out.points[i].sog_m_s, 3.0, 1e-3) << i;
    EXPECT_NEAR(out.points[i].cog_deg, 90.0, 0.01) << i;
  }
  // The turn's point: the chord from east to north, speed ~ |(0,2) - (-3,0)| / 2 s.
  EXPECT_NEAR(out.points[10].cog_deg, std::atan2(3.0, 2.0) * 180.0 / M_PI, 0.05);
  for (std::size_t i = 11; i < 20; ++i) {
    EXPECT_NEAR(out.points[i].sog_m_s, 2.0, 1e-3) << i;
    EXPECT_NEAR(std::remainder(out.points[i].cog_deg, 360.0), 0.0, 0.01) << i;
  }
  // Across the 30 s pause nothing is bridged: each side has its own velocity.
  EXPECT_NEAR(out.points[20].sog_m_s, 2.0, 1e-3) << "the last before the pause, backwards";
  EXPECT_NEAR(out.points[21].sog_m_s, 0.1, 1e-3) << "the first after it, forwards";
  // Drifting: a speed, no course.
  EXPECT_NEAR(out.points[23].sog_m_s, 0.1, 1e-3);
  EXPECT_TRUE(std::isnan(out.points[23].cog_deg));
  EXPECT_DOUBLE_EQ(out.points[26].sog_m_s, 4.5);
  EXPECT_DOUBLE_EQ(out.points[26].cog_deg, 10.0);
}

TEST(ImportCourse, PointsWithoutPositionPassThroughAndEventsToo) {
  Collect out;
  CourseFromPositions stage(out);
  ImportPoint heel_only;
  heel_only.t_utc_ns = kT0;
  heel_only.heel_deg = 5.0;
  heel_only.pitch_deg = 1.0;
  stage.point(heel_only);
  stage.event({kT0, "race_start", ""});
  stage.device("watch");
  stage.point(at(1.0, 0.0, 0.0));
  stage.finish();
  stage.finish();  // twice is harmless
  ASSERT_EQ(out.points.size(), 2u);
  EXPECT_TRUE(std::isnan(out.points[0].sog_m_s));
  EXPECT_TRUE(std::isnan(out.points[1].sog_m_s)) << "one position alone has no velocity";
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.device_name, "watch");
}

}  // namespace
}  // namespace telltale::shore::import
