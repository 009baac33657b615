// Online hard-iron calibration (hard_iron.hpp): a rotating sensor with a known offset, a steady
// one (nothing to learn), yaw-only rotation (the axis of rotation stays unobserved) and a
// magnetic disturbance (gated).
#include "telltale/fusion/hard_iron.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace telltale::fusion {
namespace {

const Eigen::Vector3d kEarth(0.0, 20.0, -44.0);  // ENU, uT

/// Feeds `seconds` at 50 Hz of a sensor whose attitude follows `rate(t)` (sensor frame, rad/s),
/// with hard iron `b` and white noise on the magnetometer.
template <class Rate>
HardIronCalibrator run(const Eigen::Vector3d& b, Rate rate, double seconds, double noise_uT,
                       unsigned seed, double disturb_from_s = -1.0) {
  HardIronCalibrator cal;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, noise_uT);
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // sensor -> world
  const double dt = 0.02;
  for (int k = 0; k * dt <= seconds; ++k) {
    const double t = k * dt;
    const Eigen::Vector3d w = rate(t);
    if (k > 0) {
      // Exact attitude for the sampled rate (trapezoid of the previous and this rate).
      const Eigen::Vector3d d = 0.5 * (w + rate(t - dt)) * dt;
      if (d.norm() > 0) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(d.norm(), d.normalized()));
    }
    Eigen::Vector3d m = q.conjugate() * kEarth + b + Eigen::Vector3d(n(rng), n(rng), n(rng));
    if (disturb_from_s >= 0.0 && t >= disturb_from_s && t < disturb_from_s + 1.0)
      m += Eigen::Vector3d(15.0, -10.0, 5.0);  // a steel door for one second
    cal.update(t, w, m);
  }
  return cal;
}

// Given a phone tumbling slowly about changing axes with a 3 uT-class offset, then the offset
// is recovered to 0.1 uT within a minute, whatever the field.
TEST(HardIron, RecoversTheOffsetOfATumblingSensor) {
  const Eigen::Vector3d b(2.5, -1.5, 1.0);
  const auto cal = run(
      b,
      [](double t) {
        return Eigen::Vector3d(0.6 * std::sin(0.7 * t), 0.5 * std::cos(0.3 * t), 0.4);
      },
      60.0, 0.4, 1);
  EXPECT_LT((cal.offset_uT() - b).norm(), 0.1) << cal.offset_uT().transpose();
  EXPECT_LT(cal.state().sigma_uT.maxCoeff(), 0.1);
}

// Given a steady sensor, then nothing is learned: the estimate stays at the prior's 0 and its
// uncertainty at the prior's.
TEST(HardIron, ASteadySensorLearnsNothing) {
  const auto cal = run(
      Eigen::Vector3d(2.0, 2.0, 2.0), [](double) { return Eigen::Vector3d::Zero(); }, 30.0, 0.4, 2);
  EXPECT_LT(cal.offset_uT().norm(), 1e-9);
  EXPECT_NEAR(cal.state().sigma_uT.minCoeff(), HardIronParams{}.prior_uT, 1e-9);
}

// Given turns about the sensor's z axis only (a level phone carried around corners), then the
// x and y components are learned and z stays unobserved (at its prior).
TEST(HardIron, YawOnlyCalibratesThePlanePerpendicularToTheTurns) {
  const Eigen::Vector3d b(1.5, -2.0, 2.5);
  const auto cal = run(
      b, [](double t) { return Eigen::Vector3d(0.0, 0.0, std::fmod(t, 10.0) < 2.0 ? 0.8 : 0.0); },
      60.0, 0.4, 3);
  EXPECT_NEAR(cal.offset_uT().x(), b.x(), 0.15);
  EXPECT_NEAR(cal.offset_uT().y(), b.y(), 0.15);
  EXPECT_NEAR(cal.offset_uT().z(), 0.0, 0.05);
  EXPECT_GT(cal.state().sigma_uT.z(), 2.5);
}

// Given a one-second magnetic disturbance in the middle of the tumbling walk, then its pairs
// are refused and the offset is still recovered.
TEST(HardIron, GatesAMagneticDisturbance) {
  const Eigen::Vector3d b(-1.0, 0.5, 2.0);
  const auto cal = run(
      b,
      [](double t) {
        return Eigen::Vector3d(0.6 * std::sin(0.7 * t), 0.5 * std::cos(0.3 * t), 0.4);
      },
      60.0, 0.4, 4, 30.0);
  EXPECT_GT(cal.diagnostics().rejected_gate, 40u);
  EXPECT_LT((cal.offset_uT() - b).norm(), 0.15) << cal.offset_uT().transpose();
  EXPECT_EQ(cal.diagnostics().rejected_non_finite, 0u);
}

}  // namespace
}  // namespace telltale::fusion
