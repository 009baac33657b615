// The paper's filter (seed 000/001) against golden values computed here, independently, from
// equations 1-5 and table 1 with plain arrays.
#include "telltale/fusion/attitude_seed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace telltale::fusion {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;
constexpr double kRad = M_PI / 180.0;

/// One axis of the paper's filter, written from the equations with scalars (degrees).
struct RefAxis {
  double x[3] = {0.0, 0.0, 0.0};                                         // X0 = 0 (table 1)
  double p[3][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};  // P0 = I
  double r = 0.005;
  double out = 0.0;

  void step(double c, double inc, double acc, double dr) {
    x[2] = inc;                                      // measured increment
    const double xp[3] = {x[0] + x[2], x[1], x[2]};  // eq 1, A X
    double ap[3][3];                                 // A P
    for (int j = 0; j < 3; ++j) {
      ap[0][j] = p[0][j] + p[2][j];
      ap[1][j] = p[1][j];
      ap[2][j] = p[2][j];
    }
    double pp[3][3];  // (A P) A^T + Q, eq 3
    for (int i = 0; i < 3; ++i) {
      pp[i][0] = ap[i][0] + ap[i][2];
      pp[i][1] = ap[i][1];
      pp[i][2] = ap[i][2];
    }
    pp[1][1] += 0.02;
    pp[2][2] += 0.02;
    r = (c != 0.0) ? 0.005 : r + dr;  // eq 4
    const double h[3] = {1.0 - c, c, 0.0};
    const double y = (1.0 - c) * (out + inc) + c * acc;  // Y(k)
    double pht[3];
    for (int i = 0; i < 3; ++i) pht[i] = pp[i][0] * h[0] + pp[i][1] * h[1] + pp[i][2] * h[2];
    const double s = h[0] * pht[0] + h[1] * pht[1] + h[2] * pht[2] + r;
    const double innov = y - (h[0] * xp[0] + h[1] * xp[1] + h[2] * xp[2]);
    for (int i = 0; i < 3; ++i) x[i] = xp[i] + pht[i] / s * innov;  // eq 5
    double hp[3];
    for (int j = 0; j < 3; ++j) hp[j] = h[0] * pp[0][j] + h[1] * pp[1][j] + h[2] * pp[2][j];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) p[i][j] = pp[i][j] - pht[i] / s * hp[j];
    }
    out = (1.0 - c) * x[0] + c * x[1];
  }
};

double ref_weight(double da) {  // eq 2
  if (da < 0.005) return 0.7;
  if (da <= 0.03) return 1.0 / ((240.0 * da) * (240.0 * da));
  return 0.0;
}

TEST(SeedWeight, FollowsEquation2) {
  const SeedAttitudeParams p;
  EXPECT_DOUBLE_EQ(SeedAttitudeFilter::weight_from_da(0.0, p), 0.7);
  EXPECT_DOUBLE_EQ(SeedAttitudeFilter::weight_from_da(0.0049, p), 0.7);
  EXPECT_NEAR(SeedAttitudeFilter::weight_from_da(0.005, p), 1.0 / 1.44, 1e-15);
  EXPECT_NEAR(SeedAttitudeFilter::weight_from_da(0.01, p), 1.0 / 5.76, 1e-15);
  EXPECT_NEAR(SeedAttitudeFilter::weight_from_da(0.03, p), 1.0 / 51.84, 1e-15);
  EXPECT_DOUBLE_EQ(SeedAttitudeFilter::weight_from_da(0.0301, p), 0.0);
}

// Given a sequence that visits every branch of eq 2 (|a| scaled by 1.002 .. 1.05) while the
// instrument rolls and pitches, when the seed filter and the scalar reference run it, then every
// published angle agrees to 1e-9 deg.
TEST(SeedAttitudeFilter, ReproducesGoldenValuesFromTheEquations) {
  SeedAttitudeFilter filter;
  RefAxis heel;
  RefAxis pitch;
  const double scales[] = {1.002, 1.01, 1.02, 1.05, 1.0, 0.96};
  double last_t = 0.0;
  for (int k = 0; k < 300; ++k) {
    const double t = 0.04 * k;
    const double h_true = 12.0 * kRad * std::sin(0.7 * t);
    const double p_true = -6.0 * kRad * std::cos(0.4 * t);
    const double s = scales[(k / 7) % 6];
    const Eigen::Vector3d f = s * kG *
                              Eigen::Vector3d(std::sin(p_true), std::cos(p_true) * std::sin(h_true),
                                              std::cos(p_true) * std::cos(h_true));
    const Eigen::Vector3d w(0.15 * std::cos(0.7 * t), -0.05 * std::sin(0.4 * t), 0.3);
    filter.update({t, w, f});
    // Reference: eq 2 on |a|, tilt from the SPEC accelerometer model, Euler rates at phi_o.
    const double c = ref_weight(std::abs(f.norm() - kG) / kG);
    const double h_acc = std::atan2(f.y(), f.z()) / kRad;
    const double p_acc = std::atan2(f.x(), std::sqrt(f.y() * f.y() + f.z() * f.z())) / kRad;
    const double ho = heel.out * kRad;
    const double po = pitch.out * kRad;
    const double heel_rate = w.x() + (w.y() * std::sin(ho) + w.z() * std::cos(ho)) * std::tan(-po);
    const double pitch_rate = -(w.y() * std::cos(ho) - w.z() * std::sin(ho));
    const double dt = k == 0 ? 0.0 : t - last_t;
    last_t = t;
    heel.step(c, heel_rate * dt / kRad, h_acc, 0.005);
    pitch.step(c, pitch_rate * dt / kRad, p_acc, 0.005);
    const AttitudeOutput o = filter.output();
    ASSERT_NEAR(o.heel_rad / kRad, heel.out, 1e-9) << "k=" << k;
    ASSERT_NEAR(o.pitch_rad / kRad, pitch.out, 1e-9) << "k=" << k;
    ASSERT_NEAR(o.acc_weight, c, 1e-15);
  }
  // The sequence must really have visited the three branches of eq 2.
  EXPECT_GT(std::abs(heel.out), 1.0);
}

// Given the instrument static at heel -17.5, pitch 7.5 (the paper's turntable pose), then the
// seed converges from X0 = 0 to the tilt: the accelerometer dominates while motion is inertial.
TEST(SeedAttitudeFilter, ConvergesToAStaticTiltFromZero) {
  SeedAttitudeFilter filter;
  const double h = -17.5 * kRad;
  const double p = 7.5 * kRad;
  const Eigen::Vector3d f =
      kG * Eigen::Vector3d(std::sin(p), std::cos(p) * std::sin(h), std::cos(p) * std::cos(h));
  for (int k = 0; k < 250; ++k) filter.update({0.04 * k, Eigen::Vector3d::Zero(), f});
  EXPECT_NEAR(filter.output().heel_rad / kRad, -17.5, 1e-3);
  EXPECT_NEAR(filter.output().pitch_rad / kRad, 7.5, 1e-3);
}

}  // namespace
}  // namespace telltale::fusion
