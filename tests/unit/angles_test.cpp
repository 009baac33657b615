// The one definition of angle wrapping (telltale/fusion/angles.hpp), at the edges where the
// copies it replaced differed.
#include "telltale/fusion/angles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {
using telltale::fusion::diff_180_deg;
using telltale::fusion::wrap_180_deg;
using telltale::fusion::wrap_2pi;
using telltale::fusion::wrap_360_deg;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A tiny negative angle plus 360 rounds to 360: the manoeuvre detector's and the race
// simulator's copies returned 360 there, outside [0, 360).
TEST(Angles, WrapStaysInsideItsRangeForATinyNegativeAngle) {
  EXPECT_EQ(wrap_360_deg(-1e-15), 0.0);
  EXPECT_EQ(wrap_2pi(-1e-17), 0.0);
  EXPECT_EQ(wrap_360_deg(-90.0), 270.0);
  EXPECT_EQ(wrap_360_deg(720.5), 0.5);
  EXPECT_EQ(wrap_180_deg(180.0), -180.0);
  EXPECT_EQ(wrap_180_deg(-190.0), 170.0);
  EXPECT_NEAR(wrap_2pi(-M_PI / 2.0), 1.5 * M_PI, 1e-15);
}

// An unwrapped course a day of 720s away: the race simulator's copy, fmod(a - b + 540) - 180,
// went negative past -540 and was off by 360.
TEST(Angles, DifferenceIsRightForAnyTwoAnglesAndTiesAt180) {
  EXPECT_EQ(diff_180_deg(10.0, 3600.0 + 20.0), -10.0);
  EXPECT_EQ(diff_180_deg(3600.0 + 20.0, 10.0), 10.0);
  EXPECT_EQ(diff_180_deg(-700.0, 0.0), 20.0);
  EXPECT_EQ(diff_180_deg(0.0, 180.0), 180.0);
  EXPECT_EQ(diff_180_deg(180.0, 0.0), 180.0);
  EXPECT_EQ(diff_180_deg(350.0, 10.0), -20.0);
  // remainder is exact: no rounding from adding 540 first.
  EXPECT_EQ(diff_180_deg(0.1, 0.0), 0.1);
}

TEST(Angles, NotFiniteComesBackNaN) {
  for (double a : {kNaN, kInf, -kInf}) {
    EXPECT_TRUE(std::isnan(wrap_360_deg(a)));
    EXPECT_TRUE(std::isnan(wrap_180_deg(a)));
    EXPECT_TRUE(std::isnan(wrap_2pi(a)));
    EXPECT_TRUE(std::isnan(diff_180_deg(a, 0.0)));
  }
}

}  // namespace
