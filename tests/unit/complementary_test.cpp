#include "telltale/fusion/complementary.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace telltale::fusion {
namespace {

constexpr double kG = 9.80665;
constexpr double kDeg = M_PI / 180.0;

Eigen::Vector3d gravity_in_body(double heel_rad, double pitch_rad) {
  return kG * Eigen::Vector3d(std::sin(pitch_rad), std::cos(pitch_rad) * std::sin(heel_rad),
                              std::cos(pitch_rad) * std::cos(heel_rad));
}

TEST(TiltFromAccel, InvertsTheSpecAccelerometerModel) {
  for (double heel : {-40.0, -17.5, 0.0, 12.0, 60.0}) {
    for (double pitch : {-30.0, 0.0, 7.5, 25.0}) {
      double h = 0.0;
      double p = 0.0;
      tilt_from_accel(gravity_in_body(heel * kDeg, pitch * kDeg), h, p);
      EXPECT_NEAR(h / kDeg, heel, 1e-9);
      EXPECT_NEAR(p / kDeg, pitch, 1e-9);
    }
  }
}

// Given a boat rolling to starboard at a constant body rate with pitch held at zero,
// when the filter integrates the gyro, then the heel follows the rate (sign of SPEC section 1).
TEST(ComplementaryFilter, PositiveRollRateIncreasesHeel) {
  ComplementaryFilter filter({.tau_s = 1e9});  // gyro only
  const double rate = 10.0 * kDeg;
  for (int k = 0; k <= 100; ++k) {
    const double t = k * 0.01;
    filter.update({t, {rate, 0.0, 0.0}, gravity_in_body(0.0, 0.0)});
  }
  EXPECT_NEAR(filter.heel_rad() / kDeg, 10.0, 1e-6);
  EXPECT_NEAR(filter.pitch_rad(), 0.0, 1e-9);
}

// A positive rate about +y (port) puts the bow down: pitch decreases.
TEST(ComplementaryFilter, PositivePitchAxisRateLowersBow) {
  ComplementaryFilter filter({.tau_s = 1e9});
  for (int k = 0; k <= 100; ++k) filter.update({k * 0.01, {0.0, 5.0 * kDeg, 0.0}, {0, 0, kG}});
  EXPECT_NEAR(filter.pitch_rad() / kDeg, -5.0, 1e-6);
}

TEST(ComplementaryFilter, ConvergesToStaticTiltAndRejectsNaN) {
  ComplementaryFilter filter;
  const Eigen::Vector3d f = gravity_in_body(-17.5 * kDeg, 7.5 * kDeg);
  for (int k = 0; k < 1000; ++k) filter.update({k * 0.04, Eigen::Vector3d::Zero(), f});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  filter.update({40.0, {nan, 0, 0}, f});
  EXPECT_EQ(filter.diagnostics().rejected_non_finite, 1u);
  EXPECT_NEAR(filter.heel_rad() / kDeg, -17.5, 1e-6);
  EXPECT_NEAR(filter.pitch_rad() / kDeg, 7.5, 1e-6);
}

}  // namespace
}  // namespace telltale::fusion
