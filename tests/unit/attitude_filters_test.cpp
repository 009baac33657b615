// Shared helpers, the registry, and the contract every attitude filter keeps (NaN, time).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "telltale/fusion/attitude.hpp"
#include "telltale/fusion/attitude_baselines.hpp"

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

// The fast atan2 of the production filter agrees with the C library's everywhere to 1e-9 rad.
TEST(FastAtan2, MatchesTheLibraryOnEveryOctant) {
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double a = -M_PI + 2.0 * M_PI * (i + 0.5) / 20000.0;
    for (double r : {1e-6, 0.3, 1.0, 9.81, 1e5}) {
      const double y = r * std::sin(a);
      const double x = r * std::cos(a);
      worst = std::max(worst, std::abs(fast_atan2(y, x) - std::atan2(y, x)));
    }
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_DOUBLE_EQ(fast_atan2(0.0, 1.0), 0.0);
  EXPECT_NEAR(fast_atan2(1.0, 0.0), M_PI / 2, 1e-15);
  EXPECT_NEAR(fast_atan2(-1.0, -1.0), -3.0 * M_PI / 4, 1e-9);
}

// The pair folds the octant steps into one sign flip and one offset: every octant, both lanes.
TEST(FastAtan2, PairMatchesTheLibraryOnEveryOctantInBothLanes) {
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double a = -M_PI + 2.0 * M_PI * (i + 0.5) / 20000.0;
    const double b = 1.0 - a;  // the other lane in another octant
    for (double r : {1e-6, 0.3, 1.0, 9.81, 1e5}) {
      double r0 = 0.0;
      double r1 = 0.0;
      fast_atan2_pair(r * std::sin(a), r * std::cos(a), std::sin(b), std::cos(b), r0, r1);
      worst = std::max(worst, std::abs(r0 - std::atan2(r * std::sin(a), r * std::cos(a))));
      worst = std::max(worst, std::abs(r1 - std::atan2(std::sin(b), std::cos(b))));
    }
  }
  EXPECT_LT(worst, 1e-9);
  double r0 = 1.0;
  double r1 = 1.0;
  fast_atan2_pair(0.0, 1.0, 1.0, 0.0, r0, r1);
  EXPECT_DOUBLE_EQ(r0, 0.0);
  EXPECT_NEAR(r1, M_PI / 2, 1e-15);
}

// A positive roll rate heels to starboard; a positive rate about +y (port) puts the bow down.
TEST(EulerRates, SignsOfSpecSection1) {
  double hr = 0.0;
  double pr = 0.0;
  euler_rates_from_body({0.1, 0.0, 0.0}, 0.0, 0.0, hr, pr);
  EXPECT_DOUBLE_EQ(hr, 0.1);
  EXPECT_DOUBLE_EQ(pr, 0.0);
  euler_rates_from_body({0.0, 0.1, 0.0}, 0.0, 0.0, hr, pr);
  EXPECT_DOUBLE_EQ(pr, -0.1);
  // Yawing about body z while heeled moves pitch (the coupling the per-axis paper leaves open).
  euler_rates_from_body({0.0, 0.0, 0.1}, 30.0 * kDeg, 0.0, hr, pr);
  EXPECT_NEAR(pr, 0.1 * std::sin(30.0 * kDeg), 1e-15);
}

TEST(Registry, EveryNameBuildsAndTheDefaultComesFirst) {
  const auto& names = attitude_filter_names();
  ASSERT_GE(names.size(), 6u);
  EXPECT_EQ(names.front(), std::string(kDefaultAttitudeFilter));
  for (const auto& n : names) {
    EXPECT_NE(make_attitude_filter(n), nullptr) << n;
    EXPECT_FALSE(attitude_filter_description(n).empty()) << n;
  }
  EXPECT_EQ(make_attitude_filter("complementary-typo"), nullptr);
}

class EveryFilter : public ::testing::TestWithParam<std::string> {};

// Given a filter settled on a static tilt, when samples with NaN/Inf or a repeated time arrive,
// then they change nothing and the output stays finite.
TEST_P(EveryFilter, IgnoresNonFiniteAndNonIncreasingTime) {
  auto f = make_attitude_filter(GetParam());
  const Eigen::Vector3d g = gravity_in_body(-17.5 * kDeg, 7.5 * kDeg);
  for (int k = 0; k < 500; ++k) f->update({0.04 * k, Eigen::Vector3d::Zero(), g});
  const AttitudeOutput before = f->output();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  f->update({20.0, {nan, 0.0, 0.0}, g});
  f->update({20.04, Eigen::Vector3d::Zero(), {0.0, inf, 9.8}});
  f->update({nan, Eigen::Vector3d::Zero(), g});
  f->update({0.04 * 499, {1.0, 1.0, 1.0}, g});  // time did not advance
  const AttitudeOutput after = f->output();
  EXPECT_EQ(after.heel_rad, before.heel_rad);
  EXPECT_EQ(after.pitch_rad, before.pitch_rad);
  EXPECT_TRUE(std::isfinite(after.heel_rad) && std::isfinite(after.pitch_rad));
  EXPECT_GE(after.acc_weight, 0.0);
  EXPECT_LE(after.acc_weight, 1.0);
  EXPECT_GE(after.quality, 0.0);
  EXPECT_LE(after.quality, 1.0);
}

// Given a static tilt, every filter but gyro-only (which never looks again) ends on it.
TEST_P(EveryFilter, SettlesOnAStaticTilt) {
  auto f = make_attitude_filter(GetParam());
  const Eigen::Vector3d g = gravity_in_body(-17.5 * kDeg, 7.5 * kDeg);
  for (int k = 0; k < 1500; ++k) f->update({0.04 * k, Eigen::Vector3d::Zero(), g});
  EXPECT_NEAR(f->output().heel_rad / kDeg, -17.5, 0.01) << GetParam();
  EXPECT_NEAR(f->output().pitch_rad / kDeg, 7.5, 0.01) << GetParam();
  EXPECT_TRUE(f->output().valid);
}

INSTANTIATE_TEST_SUITE_P(Attitude, EveryFilter, ::testing::ValuesIn(attitude_filter_names()),
                         [](const auto& param_info) {
                           std::string n = param_info.param;
                           for (auto& ch : n) ch = (ch == '-') ? '_' : ch;
                           return n;
                         });

TEST(GyroAttitudeFilter, IntegratesARollRateAndCountsRejections) {
  GyroAttitudeFilter f;
  const double rate = 10.0 * kDeg;
  for (int k = 0; k <= 100; ++k) f.update({k * 0.01, {rate, 0.0, 0.0}, {0.0, 0.0, kG}});
  EXPECT_NEAR(f.output().heel_rad / kDeg, 10.0, 1e-9);
  f.update({0.5, {rate, 0.0, 0.0}, {0.0, 0.0, kG}});
  EXPECT_EQ(f.diagnostics().rejected_time, 1u);
}

TEST(AverageAttitudeFilter, WeightIsFixedForUniformSampling) {
  AverageAttitudeFilter f({.tau_s = 0.96});
  for (int k = 0; k < 10; ++k) f.update({0.04 * k, Eigen::Vector3d::Zero(), {0.0, 0.0, kG}});
  EXPECT_NEAR(f.output().acc_weight, 0.04, 1e-12);  // dt / (tau + dt)
}

}  // namespace
}  // namespace telltale::fusion
