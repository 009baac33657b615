// PDR (seed 003): pose rotations, magnetic heading geometry, the heading filter against analytic
// motion, BP training determinism and the shipped model on held-out people, step-length
// calibration, and closed-loop walks on the simulator.
#include "telltale/fusion/pdr.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "telltale/fusion/sim/pose_dataset.hpp"

namespace telltale::fusion {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;
constexpr double kDeg = M_PI / 180.0;

TEST(PoseRotation, PaperMatricesAreProperRotations) {
  for (int p = 0; p < kPoseCount; ++p) {
    const Eigen::Matrix3d m = pose_rotation(static_cast<PhonePose>(p));
    EXPECT_TRUE((m * m.transpose()).isIdentity(1e-15));
    EXPECT_NEAR(m.determinant(), 1.0, 1e-15);
  }
  // Eqs. (14)-(15) as printed: call [[0,0,-1],[0,-1,0],[-1,0,0]], pocket
  // [[0,0,-1],[0,1,0],[1,0,0]].
  EXPECT_EQ(pose_rotation(PhonePose::kCall) * Eigen::Vector3d(1, 2, 3),
            Eigen::Vector3d(-3, -2, -1));
  EXPECT_EQ(pose_rotation(PhonePose::kPocket) * Eigen::Vector3d(1, 2, 3),
            Eigen::Vector3d(-3, 2, 1));
}

// Walking frame x forward, y left, z up; earth field ENU (0, 20, -44) uT. For a heading psi the
// field in the walking frame is (20 cos psi, 20 sin psi, -44) — the tilt-compensated heading must
// return psi whatever the tilt.
TEST(HeadingFilter, MagneticHeadingInvertsTheFieldGeometryUnderTilt) {
  for (double psi : {0.0, 37.0, 90.0, 181.0, 300.0}) {
    const Eigen::Vector3d m_level(20 * std::cos(psi * kDeg), 20 * std::sin(psi * kDeg), -44);
    for (double roll : {-30.0, 0.0, 20.0})
      for (double pitch : {-25.0, 0.0, 40.0}) {
        // Tilt the sensor: vectors in the tilted frame are R^T v.
        const Eigen::Matrix3d r = (Eigen::AngleAxisd(pitch * kDeg, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(roll * kDeg, Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
        const double h = HeadingFilter::magnetic_heading_rad(
            r.transpose() * m_level, r.transpose() * Eigen::Vector3d::UnitZ());
        EXPECT_NEAR(std::remainder(h / kDeg - psi, 360.0), 0.0, 1e-9) << psi << roll << pitch;
      }
  }
}

// Given a level sensor turning right at 20 deg/s with a consistent magnetometer, when filtered,
// then the heading follows the turn (clockwise heading increases) within a degree.
TEST(HeadingFilter, FollowsAConstantRightTurn) {
  HeadingFilter f;
  const double rate = 20.0 * kDeg;
  for (int k = 0; k <= 500; ++k) {
    const double t = k * 0.02;
    const double psi = 10.0 * kDeg + rate * t;
    const Eigen::Vector3d mag(20 * std::cos(psi), 20 * std::sin(psi), -44);
    f.update(t, {0, 0, -rate}, {0, 0, kG}, mag);  // right turn = negative yaw rate about up
  }
  EXPECT_NEAR(std::remainder(f.heading_rad() / kDeg - (10.0 + 200.0), 360.0), 0.0, 1.0);
  EXPECT_EQ(f.diagnostics().rejected_mag, 0u);
}

// A corner at walking speed (0.6 m radius, 1.4 m/s: 3.3 m/s^2 toward the centre) read by a
// level sensor with a perfect magnetometer: the largest heading error in the 3 s after the corner,
// with and without the walking speed known (the centripetal part taken out of the up direction).
double worst_error_after_corner_deg(bool speed_known) {
  HeadingFilter f;
  if (speed_known) f.set_speed(1.4);
  const double v = 1.4, radius = 0.6, w = v / radius, turn_s = 0.5 * M_PI / w;
  double psi = 100.0 * kDeg, worst = 0.0;
  for (int k = 0; k <= 400; ++k) {
    const double t = k * 0.02;
    const bool turning = t >= 2.0 && t < 2.0 + turn_s;  // a left turn: the heading falls
    if (turning) psi -= w * 0.02;
    const Eigen::Vector3d mag(20 * std::cos(psi), 20 * std::sin(psi), -44);
    f.update(t, {0, 0, turning ? w : 0.0}, {0, turning ? v * w : 0.0, kG}, mag);
    if (t > 2.0 + turn_s)
      worst = std::max(worst, std::abs(std::remainder(f.heading_rad() - psi, 2 * M_PI)) / kDeg);
  }
  return worst;
}

TEST(HeadingFilter, CornerAtWalkingSpeedDoesNotTiltTheHeading) {
  const double with = worst_error_after_corner_deg(true);
  const double without = worst_error_after_corner_deg(false);
  RecordProperty("worst_after_corner_deg", std::to_string(with));
  RecordProperty("without_speed_deg", std::to_string(without));
  EXPECT_LT(with, 1.0);
  EXPECT_GT(without, 3.0 * with);  // what the correction is for
}

TEST(HeadingFilter, GyroOnlyWithoutMagnetometerAndRejectsNaN) {
  HeadingFilter f;
  const Eigen::Vector3d no_mag = Eigen::Vector3d::Constant(std::nan(""));
  for (int k = 0; k <= 100; ++k) f.update(k * 0.01, {0, 0, 0.5}, {0, 0, kG}, no_mag);
  // Left turn at 0.5 rad/s for 1 s from heading 0: heading 360 - 28.6 deg.
  EXPECT_NEAR(std::remainder(f.heading_rad() / kDeg + 0.5 / kDeg, 360.0), 0.0, 1e-6);
  f.update(1.5, {std::nan(""), 0, 0}, {0, 0, std::nan("")}, no_mag);
  EXPECT_EQ(f.diagnostics().rejected_non_finite, 1u);
}

TEST(PoseNetwork, TrainingIsDeterministicAndTheModelFileRoundTrips) {
  const auto set = sim::simulate_pose_windows(1, 3, 6);
  PoseTrainingParams p;
  p.epochs = 30;
  const PoseNetwork a = train_pose_network(set.features, set.labels, p);
  const PoseNetwork b = train_pose_network(set.features, set.labels, p);
  EXPECT_EQ(a.w_ih, b.w_ih);
  EXPECT_EQ(a.w_ho, b.w_ho);
  StepLengthModel len;
  len.abc[2] = {0.5, 0.3, -0.4};
  PoseNetwork c;
  StepLengthModel len2;
  ASSERT_TRUE(parse_pdr_model(format_pdr_model(a, len), c, len2));
  EXPECT_TRUE(c.w_ih.isApprox(a.w_ih, 1e-15));
  EXPECT_TRUE(c.b_o.isApprox(a.b_o, 1e-15));
  EXPECT_EQ(len2.abc[2], len.abc[2]);
  EXPECT_FALSE(parse_pdr_model("w_ih 2 2 1 2 3 4\n", c, len2));
  EXPECT_FALSE(parse_pdr_model("in_mean 3 1 1 nan 2\n", c, len2));
}

// The shipped network (trained by tools/train_pose on people 1..23) on 10 people it never saw:
// seed 003 reports > 90 % (decision tree) and > 94 % (SVM) for related work; we require 95 %.
TEST(PoseNetwork, ShippedModelClassifiesHeldOutPeopleAtLeast95Percent) {
  const PoseNetwork& net = builtin_pose_network();
  ASSERT_TRUE(net.trained) << "fusion_core/data/pose_bp.txt missing or malformed";
  const auto set = sim::simulate_pose_windows(1001, 10, 20);
  std::size_t ok = 0;
  for (std::size_t i = 0; i < set.features.size(); ++i)
    ok += net.classify(set.features[i]) == set.labels[i] ? 1u : 0u;
  const double acc = static_cast<double>(ok) / static_cast<double>(set.features.size());
  RecordProperty("held_out_accuracy_percent", std::to_string(100.0 * acc));
  EXPECT_GE(acc, 0.95);
}

// Walks generated from known coefficients are fitted back exactly (the model is linear).
TEST(StepLengthCalibration, RecoversKnownCoefficientsAndStaysNearThePriorWithOneWalk) {
  const Eigen::Vector3d truth(0.45, 0.25, -0.35);
  std::vector<CalibrationWalk> walks;
  for (double h : {1.58, 1.72, 1.90})
    for (double f : {1.5, 1.9, 2.2}) {
      CalibrationWalk w;
      w.height_m = h;
      w.step_hz.assign(40, f);
      w.distance_m = 40 * (truth[0] * h + truth[1] * f + truth[2]);
      walks.push_back(w);
    }
  const Eigen::Vector3d fit = calibrate_step_length(walks, Eigen::Vector3d::Zero(), 1e-9);
  EXPECT_TRUE(fit.isApprox(truth, 1e-6)) << fit.transpose();
  // One walk of known length: the fitted model reproduces that walk's length.
  const Eigen::Vector3d prior(0.3, 0.4, -0.51);
  const Eigen::Vector3d one = calibrate_step_length({walks[4]}, prior, 1e-3);
  const double per_step = one[0] * walks[4].height_m + one[1] * 1.9 + one[2];
  EXPECT_NEAR(40 * per_step, walks[4].distance_m, 0.01 * walks[4].distance_m);
}

// Given a walker with a phone held in hand on a straight line with ideal sensors, when the PDR
// runs, then the step count and the straight-line distance are right within 5 % and the track
// points the right way.
TEST(Pdr, StraightWalkHandHeld) {
  auto sc = *sim::make_gait_scenario("phone-hand-held-walk", 11);
  sc.path = {{500.0, 0.0}};
  sc.start_heading_deg = 60.0;
  sc.errors.acc_bias_m_s2 = sc.errors.gyro_bias_rad_s = sc.errors.mag_bias_uT = 0.0;
  auto person = sim::random_person(11);
  for (int i = 0; i < kPoseCount; ++i) person.mount_yaw_deg[i] = person.mount_tilt_deg[i] = 0.0;
  const auto run = sim::simulate_gait(sc, person, 11);
  PdrParams p;
  p.step_length.height_m = person.height_m;
  Pdr pdr(p);
  for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
  const auto& out = pdr.output();
  EXPECT_NEAR(static_cast<double>(out.steps), static_cast<double>(run.step_times_s.size()), 1.0);
  EXPECT_NEAR(out.distance_m, run.distance_m, 0.05 * run.distance_m);
  EXPECT_NEAR(std::atan2(out.x_m, out.y_m) / kDeg, 60.0, 1.5);
  EXPECT_EQ(out.pose, PhonePose::kHandHeld);
  EXPECT_GT(out.cadence_spm, 80.0);
}

// Given a phone without gyroscope (accelerometer + magnetometer), when walking straight, then
// the PDR still counts, keeps the hand-held frame and lays the track along the magnetic heading.
TEST(Pdr, AccelerometerAndMagnetometerOnly) {
  auto sc = *sim::make_gait_scenario("phone-hand-held-walk", 12);
  sc.path = {{500.0, 0.0}};
  sc.start_heading_deg = 200.0;
  const auto person = sim::random_person(12);
  const auto run = sim::simulate_gait(sc, person, 12);
  PdrParams p;
  p.step_length.height_m = person.height_m;
  Pdr pdr(p);
  for (auto s : run.samples) {
    s.imu.gyro_body_rad_s.setConstant(std::nan(""));
    (void)pdr.update(s.imu, s.mag_uT);
  }
  EXPECT_NEAR(static_cast<double>(pdr.output().steps), static_cast<double>(run.step_times_s.size()),
              1.0);
  EXPECT_GT(std::hypot(pdr.output().x_m, pdr.output().y_m), 0.9 * run.distance_m);
  EXPECT_NEAR(std::remainder(std::atan2(pdr.output().x_m, pdr.output().y_m) / kDeg - 200.0, 360.0),
              0.0, 8.0);
}

// Given the four poses in turn on a straight walk, then the switches are detected by
// cross-correlation and the final pose is the true one.
TEST(Pdr, DetectsPoseSwitchesAndEndsInTheTruePose) {
  auto sc = *sim::make_gait_scenario("phone-switch", 5);
  sc.path = {{2000.0, 0.0}};
  const auto person = sim::random_person(5);
  const auto run = sim::simulate_gait(sc, person, 5);
  PdrParams p;
  p.step_length.height_m = person.height_m;
  Pdr pdr(p);
  for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
  EXPECT_GE(pdr.diagnostics().switches, 3u);
  EXPECT_EQ(pdr.output().pose, run.samples.back().pose);
  EXPECT_NEAR(std::atan2(pdr.output().x_m, pdr.output().y_m) / kDeg, 0.0, 5.0);
}

// Given a phone still in a pocket with a gyro bias, then the PDR learns the bias from the still
// windows; when the walk starts, the windows stop (|f| and the rate vary) and the bias is kept.
// (A hand-held phone's tremor, 0.11 rad/s in the simulator, is too much motion to learn from.)
TEST(Pdr, LearnsTheGyroBiasWhileStillAndKeepsItWalking) {
  auto sc = *sim::make_gait_scenario("phone-pocket-walk", 21);
  sc.standing_s = 6.0;
  sc.errors.gyro_bias_rad_s = 0.02;  // per axis, 1.1 deg/s
  const auto person = sim::random_person(21);
  const auto run = sim::simulate_gait(sc, person, 21);
  // The bias the simulator drew: the mean rate while standing (the hand's tremor averages out).
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : run.samples)
    if (s.imu.t_s < 5.5) {
      truth += s.imu.gyro_body_rad_s;
      ++n;
    }
  truth /= n;
  PdrParams p;
  p.step_length.height_m = person.height_m;
  Pdr pdr(p);
  unsigned windows_before_walk = 0, windows_at_walk_end = 0;
  const double walk_end_s = run.step_times_s.back();
  Eigen::Vector3d bias_before_walk = Eigen::Vector3d::Zero();
  for (const auto& s : run.samples) {
    (void)pdr.update(s.imu, s.mag_uT);
    if (s.imu.t_s < 6.0) {
      windows_before_walk = pdr.diagnostics().still_windows;
      bias_before_walk = pdr.gyro_bias_rad_s();
    }
    if (s.imu.t_s < walk_end_s) windows_at_walk_end = pdr.diagnostics().still_windows;
  }
  EXPECT_GE(windows_before_walk, 4u);
  EXPECT_LT((bias_before_walk - truth).norm(), 0.003);
  EXPECT_GT(truth.norm(), 0.01);
  // Walking adds no window (one may close in the first step), and the bias stays learnt.
  EXPECT_LE(windows_at_walk_end, windows_before_walk + 1u);
  EXPECT_LT((pdr.gyro_bias_rad_s() - truth).norm(), 0.003);
}

// An accelerometer bias tilts the up direction by its part across gravity over g, and the
// magnetic heading by tan(dip) times that; the vertical field then seems to change with the
// heading. Hand-held loops with a 0.1 m/s^2 (per axis) bias: the part of the learnt bias across
// gravity (the part that tilts) against the truth, which the simulator's runs with and without
// the bias give exactly. Measured over these 6 walks: 0.47 of the tilting bias is left (the
// prior and one loop's four corners), 1.0 without learning.
TEST(Pdr, LearnsTheAccelerometerBiasFromTheVerticalField) {
  double left = 0.0, total = 0.0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    auto sc = *sim::make_gait_scenario("loop", seed);
    for (auto& seg : sc.segments) seg.pose = PhonePose::kHandHeld;
    sc.errors.acc_bias_m_s2 = 0.1;
    const auto person = sim::random_person(seed);
    const auto run = sim::simulate_gait(sc, person, seed);
    auto unbiased = sc;
    unbiased.errors.acc_bias_m_s2 = 0.0;
    const auto clean = sim::simulate_gait(unbiased, person, seed);  // same noise, no bias
    const Eigen::Vector3d truth =
        run.samples[10].imu.acc_body_m_s2 - clean.samples[10].imu.acc_body_m_s2;
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const auto& s : clean.samples) g += s.imu.acc_body_m_s2;
    const Eigen::Vector3d up = g.normalized();
    auto across = [&up](const Eigen::Vector3d& v) { return (v - v.dot(up) * up).norm(); };
    PdrParams p;
    p.step_length.height_m = person.height_m;
    Pdr pdr(p);
    for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
    EXPECT_TRUE(pdr.acc_bias_m_s2().allFinite());
    left += across(pdr.acc_bias_m_s2() - truth);
    total += across(truth);
  }
  RecordProperty("tilting_bias_left", std::to_string(left / total));
  EXPECT_GT(total, 0.3);
  EXPECT_LT(left / total, 0.6);
}

// Hostile samples on a walk with switches: NaN gyro or magnetometer every 7th sample, a 200 uT
// magnetic disturbance (a car) for 3 s, a gyro spike. The learnt biases stay finite and bounded
// (the vertical-field estimator gates the disturbance), and the track stays finite.
TEST(Pdr, LearntBiasesSurviveNaNAndAMagneticDisturbance) {
  auto sc = *sim::make_gait_scenario("loop", 7);
  const auto person = sim::random_person(7);
  auto run = sim::simulate_gait(sc, person, 7);
  const double nan = std::nan("");
  for (std::size_t i = 0; i < run.samples.size(); ++i) {
    auto& s = run.samples[i];
    if (i % 7 == 3) s.imu.gyro_body_rad_s.setConstant(nan);
    if (i % 7 == 5) s.mag_uT.setConstant(nan);
    if (s.imu.t_s > 30.0 && s.imu.t_s < 33.0) s.mag_uT += Eigen::Vector3d(120.0, -80.0, 150.0);
    if (i == 2000) s.imu.gyro_body_rad_s = Eigen::Vector3d(40.0, -40.0, 40.0);
  }
  PdrParams p;
  p.step_length.height_m = person.height_m;
  Pdr pdr(p);
  for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
  EXPECT_TRUE(pdr.acc_bias_m_s2().allFinite());
  EXPECT_LT(pdr.acc_bias_m_s2().norm(), 5.0 * p.acc_bias.prior_m_s2);
  EXPECT_TRUE(std::isfinite(pdr.output().x_m) && std::isfinite(pdr.output().y_m));
  EXPECT_GT(pdr.output().steps, run.step_times_s.size() * 9 / 10);
}

// In arm swing the walking direction comes from the arm's swing axis, not from the phone's yaw
// in the hand: a phone held 6 deg off to either side walks the right way within 1.5 deg once the
// pose is known (measured 0.5 and 1.2 deg; with the axis estimate off, -5.5 and +7.2 deg).
// Ideal sensors, so the yaw is the only error.
TEST(Pdr, ArmSwingWalkingDirectionFromTheSwingAxis) {
  for (const double yaw_deg : {6.0, -6.0}) {
    for (const bool axis : {true, false}) {
      auto sc = *sim::make_gait_scenario("phone-arm-swing-walk", 1);
      sc.errors.acc_bias_m_s2 = sc.errors.gyro_bias_rad_s = sc.errors.mag_bias_uT = 0.0;
      auto person = sim::random_person(1);
      for (int k = 0; k < kPoseCount; ++k) person.mount_yaw_deg[k] = person.mount_tilt_deg[k] = 0;
      person.mount_yaw_deg[static_cast<int>(PhonePose::kArmSwing)] = yaw_deg;
      const auto run = sim::simulate_gait(sc, person, 1);
      PdrParams p;
      p.step_length.height_m = person.height_m;
      if (!axis) p.walking_direction.swing_axis_ratio = std::numeric_limits<double>::infinity();
      Pdr pdr(p);
      const double last_s = run.samples.back().imu.t_s - 25.0;
      double sn = 0.0, cs = 0.0;
      for (const auto& s : run.samples) {
        const auto& o = pdr.update(s.imu, s.mag_uT);
        if (!o.step || s.imu.t_s < last_s) continue;
        const double e = (o.heading_deg - s.heading_deg) * kDeg;
        sn += std::sin(e);
        cs += std::cos(e);
      }
      EXPECT_EQ(pdr.output().pose, PhonePose::kArmSwing);
      const double err_deg = std::atan2(sn, cs) / kDeg;
      if (axis)
        EXPECT_LT(std::abs(err_deg), 1.5) << "yaw " << yaw_deg;
      else
        EXPECT_GT(std::abs(err_deg), 4.0) << "yaw " << yaw_deg;
    }
  }
}

// A swinging hand reads its pendulum's acceleration (+-10 m/s^2 along the walk): pulled toward
// the accelerometer, the up direction swung with the arm and the magnetic heading turned that
// into a bias that depends on the heading. Straight arm-swing walks with ideal sensors at 12
// headings, 3 people: the worst mean heading error over a walk, with the lever arm fitted and
// taken out of the accelerometer and without (measured: 0.38 / 1.77 / 2.64 deg with, 0.94 /
// 2.74 / 3.05 without; what is left is the trunk's own motion, rectified).
double worst_arm_swing_heading_deg(std::uint64_t seed, bool lever_arm) {
  double worst = 0.0;
  for (int h = 0; h < 360; h += 30) {
    auto sc = *sim::make_gait_scenario("phone-arm-swing-walk", seed);
    sc.start_heading_deg = h;
    sc.path = {{200.0, 0.0}};
    sc.errors.acc_bias_m_s2 = sc.errors.gyro_bias_rad_s = sc.errors.mag_bias_uT = 0.0;
    auto person = sim::random_person(seed);
    for (int k = 0; k < kPoseCount; ++k) person.mount_yaw_deg[k] = person.mount_tilt_deg[k] = 0;
    const auto run = sim::simulate_gait(sc, person, seed);
    PdrParams p;
    p.step_length.height_m = person.height_m;
    p.heading.lever_arm = lever_arm;
    Pdr pdr(p);
    double sn = 0.0, cs = 0.0;
    for (const auto& s : run.samples) {
      const auto& o = pdr.update(s.imu, s.mag_uT);
      if (!o.step || s.imu.t_s < 20.0) continue;
      const double e = (o.heading_deg - s.heading_deg) * kDeg;
      sn += std::sin(e);
      cs += std::cos(e);
    }
    worst = std::max(worst, std::abs(std::atan2(sn, cs) / kDeg));
  }
  return worst;
}

TEST(Pdr, ArmSwingLeverArmKeepsTheHeadingLevel) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const double with = worst_arm_swing_heading_deg(seed, true);
    const double without = worst_arm_swing_heading_deg(seed, false);
    RecordProperty("worst_deg_person_" + std::to_string(seed),
                   std::to_string(with) + " / " + std::to_string(without));
    EXPECT_LT(with, without - 0.3) << "person " << seed;
    EXPECT_LT(with, 3.0) << "person " << seed;
  }
}

// Arm swing at every pace for 10 people: every step counted (the arm's turns; the first steps,
// before the swing is recognised, from the turns since the walk began; the last at rest), and
// no cadence learnt from two detections of one step (that once counted 113 steps for 58).
TEST(Pdr, CountsEveryStepOfAnArmSwingWalk) {
  for (int i = 1; i <= 10; ++i) {
    const auto seed = static_cast<std::uint64_t>(i);
    const sim::Person person = sim::random_person(seed);
    for (sim::Gait g : {sim::Gait::kSlowWalk, sim::Gait::kWalk, sim::Gait::kFastWalk}) {
      const auto run = sim::simulate_gait(sim::straight_phone_walk(g, PhonePose::kArmSwing, 40.0),
                                          person, seed * 32 + static_cast<std::uint64_t>(g));
      PdrParams p;
      p.step_length.height_m = person.height_m;
      Pdr pdr(p);
      for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
      EXPECT_EQ(pdr.output().steps, run.step_times_s.size())
          << "person " << i << " " << sim::gait_name(g);
      EXPECT_EQ(pdr.output().pose, PhonePose::kArmSwing);
    }
  }
}

// A walker who stops, stands one to three seconds and then puts the phone away (from the hand
// into the trouser pocket) makes step events with the hand's movement. After a stand (the phone
// still since the last step) a gap holds no missed steps, and a walk's first event counts only
// if a second follows within two step intervals. Measured on these 8 people and 3 pauses: every
// count exact; without the stand (stand_still_s = 0) 55 steps too many in all, up to 7 in one.
TEST(Pdr, AStopThenThePhonePutAwayCountsNoSteps) {
  long extra_without = 0, worst_without = 0;
  for (int i = 1; i <= 8; ++i) {
    const auto seed = static_cast<std::uint64_t>(i);
    const sim::Person person = sim::random_person(seed);
    for (const double pause_s : {1.0, 2.0, 3.0}) {
      sim::GaitScenario sc = sim::straight_phone_walk(sim::Gait::kWalk, PhonePose::kHandHeld, 60.0);
      sc.path = {{14.0, 0.0}};
      sc.closed = true;
      sc.standing_s = 4.0;
      sc.segments.push_back({sim::Gait::kWalk, PhonePose::kPocket, 60.0});
      // The walk's end for this person, then the switch after the pause.
      const double walk_end_s = sim::simulate_gait(sc, person, seed).step_times_s.back();
      sc.segments.front().duration_s = walk_end_s + pause_s - sc.standing_s;
      const auto run = sim::simulate_gait(sc, person, seed);
      const auto first_switching = std::find_if(run.samples.begin(), run.samples.end(),
                                                [](const auto& s) { return s.switching; });
      ASSERT_NE(first_switching, run.samples.end()) << "person " << i;
      ASSERT_GT(first_switching->imu.t_s, run.step_times_s.back() + 0.5 * pause_s)
          << "person " << i;
      const auto extra = [&run, &person](double stand_s) {
        PdrParams p;
        p.step_length.height_m = person.height_m;
        p.stand_still_s = stand_s;
        Pdr pdr(p);
        for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
        return static_cast<long>(pdr.output().steps) - static_cast<long>(run.step_times_s.size());
      };
      EXPECT_EQ(extra(PdrParams{}.stand_still_s), 0) << "person " << i << " pause " << pause_s;
      const long without = extra(0.0);
      extra_without += without;
      worst_without = std::max(worst_without, without);
    }
  }
  RecordProperty("extra_steps_without", std::to_string(extra_without));
  EXPECT_GE(extra_without, 40);  // the case is real and the test sees it
  EXPECT_GE(worst_without, 3);
}

// A walk, a stand of six seconds, the same walk again (two runs back to back), in every pose
// and at three paces: the second walk's first step is held until the next confirms it, and
// counted then. Measured: every count exact (5 people x 3 paces x 4 poses) but one pair of
// walks (person 1, hand-held, slow), each one short: its closing heel strike, whose loading
// settles into standing with no valley after it for the acceleration's peak-valley to close
// (the simulated walk ends at a heel strike since the walk-start and closing-step physics went
// into the simulator). A lost first step of the second walk would be one short in most cases.
TEST(Pdr, AWalkResumedAfterAStandCountsEveryStep) {
  int short_cases = 0;
  for (int i = 1; i <= 5; ++i) {
    const auto seed = static_cast<std::uint64_t>(i);
    const sim::Person person = sim::random_person(seed);
    for (int k = 0; k < kPoseCount; ++k) {
      const auto pose = static_cast<PhonePose>(k);
      for (sim::Gait g : {sim::Gait::kSlowWalk, sim::Gait::kWalk, sim::Gait::kFastWalk}) {
        sim::GaitScenario sc = sim::straight_phone_walk(g, pose, 60.0);
        sc.path = {{20.0, 0.0}};
        sc.closed = true;
        sc.standing_s = 3.0;
        const auto g_seed = seed * 7 + static_cast<std::uint64_t>(g);
        const auto first = sim::simulate_gait(sc, person, g_seed);
        const auto second = sim::simulate_gait(sc, person, g_seed + 100);
        PdrParams p;
        p.step_length.height_m = person.height_m;
        Pdr pdr(p);
        for (const auto& s : first.samples) (void)pdr.update(s.imu, s.mag_uT);
        const double offset_s = first.samples.back().imu.t_s + 0.02;
        for (auto s : second.samples) {
          s.imu.t_s += offset_s;
          (void)pdr.update(s.imu, s.mag_uT);
        }
        const auto truth = first.step_times_s.size() + second.step_times_s.size();
        EXPECT_LE(pdr.output().steps, truth);
        EXPECT_GE(pdr.output().steps + 2, truth)
            << "person " << i << " pose " << k << " " << sim::gait_name(g);
        short_cases += pdr.output().steps < truth ? 1 : 0;
      }
    }
  }
  RecordProperty("short_cases", std::to_string(short_cases));
  EXPECT_LE(short_cases, 1);  // of 60
}

// Given loops walked with the phone at the ear (a hard-iron offset the magnetometer calibration
// only learns at the first corner), then re-laying the steps already walked when the offset is
// known closes the loops far better: 20 walks, measured median 0.86 % with, 1.59 % without, and
// 18 within 2 % against 14.
TEST(Pdr, RevisingTheTrackWithTheLearntHardIronClosesLoops) {
  std::vector<double> with, without;
  for (int i = 0; i < 20; ++i) {
    const auto seed = static_cast<std::uint64_t>(2001 + i);
    auto sc = *sim::make_gait_scenario("loop", seed);
    for (auto& seg : sc.segments) seg.pose = PhonePose::kCall;
    const auto person = sim::random_person(seed);
    const auto run = sim::simulate_gait(sc, person, seed);
    for (const bool revise : {true, false}) {
      PdrParams p;
      p.step_length.height_m = person.height_m;
      p.step_length.scale.fill(sim::personal_step_scale(person, seed + 1000003));
      p.track.revise = revise;
      Pdr pdr(p);
      for (const auto& s : run.samples) (void)pdr.update(s.imu, s.mag_uT);
      const auto& last = run.samples.back();
      (revise ? with : without)
          .push_back(std::hypot(pdr.output().x_m - last.x_m, pdr.output().y_m - last.y_m) /
                     run.distance_m);
    }
  }
  std::sort(with.begin(), with.end());
  std::sort(without.begin(), without.end());
  const auto within = [](const std::vector<double>& v) {
    return std::count_if(v.begin(), v.end(), [](double e) { return e <= 0.02; });
  };
  RecordProperty("median_percent_revised", std::to_string(100 * with[10]));
  RecordProperty("median_percent_not_revised", std::to_string(100 * without[10]));
  RecordProperty("within_2_percent_revised", std::to_string(within(with)));
  RecordProperty("within_2_percent_not_revised", std::to_string(within(without)));
  EXPECT_LT(with[10], 0.75 * without[10]);
  EXPECT_GE(within(with), within(without) + 3);
}

// Issue 5's closed-loop target: end-point error <= 2 % of the distance in >= 90 % of walks (seed
// 003: 85 %), with pose switches, each person first calibrated by a 100 m hand-held walk.
// Measured (fusion_cli steps-eval --tables pdr): these 40 walks (seeds 2001-2040) 37 within 2 %,
// median 0.97 %, 37th 1.98 %; 400 walks no change was tuned on (--first-seed 5001 --loops 400)
// 368, 92 %. The test asserts the target on these 40 walks and the median.
TEST(Pdr, ClosedLoopsWithPoseSwitchesReachTheTarget) {
  std::vector<double> err;
  for (int i = 0; i < 40; ++i)
    err.push_back(sim::simulate_pdr_loop(static_cast<std::uint64_t>(2001 + i)).error_fraction);
  std::sort(err.begin(), err.end());
  const auto within = std::count_if(err.begin(), err.end(), [](double e) { return e <= 0.02; });
  RecordProperty("within_2_percent", std::to_string(within));
  RecordProperty("median_percent", std::to_string(100 * err[20]));
  EXPECT_GE(within, 36);
  EXPECT_LE(err[20], 0.012);
}

// The same walks in one pose (the first of each schedule): measured 40 of 40 within 2 % on seeds
// 2001-2040 and 396 of 400 on seeds 5001-5400; in arm swing alone 385 of 400. These 20 walks:
// the test asserts >= 90 % within 2 % and the median.
TEST(Pdr, ClosedLoopsInOnePoseReachTheTarget) {
  std::vector<double> err;
  for (int i = 0; i < 20; ++i)
    err.push_back(
        sim::simulate_pdr_loop(static_cast<std::uint64_t>(2001 + i), sim::LoopVariant::kSinglePose)
            .error_fraction);
  std::sort(err.begin(), err.end());
  const auto within = std::count_if(err.begin(), err.end(), [](double e) { return e <= 0.02; });
  RecordProperty("within_2_percent", std::to_string(within));
  RecordProperty("median_percent", std::to_string(100 * err[10]));
  EXPECT_GE(within, 18);
  EXPECT_LE(err[10], 0.01);
}

// One 100 m hand-held walk of known length per person fixes the distance for every pose: the
// population model is 4 % off in the median (people differ by +-8 % in step length at the same
// height and cadence), the calibrated one about 0.5 %.
TEST(Pdr, PersonalCalibrationWalkFixesTheDistance) {
  std::vector<double> with, without;
  for (int i = 0; i < 10; ++i) {
    const auto seed = static_cast<std::uint64_t>(2001 + i);
    const auto cal = sim::simulate_pdr_loop(seed, sim::LoopVariant::kAsSimulated, true);
    const auto pop = sim::simulate_pdr_loop(seed, sim::LoopVariant::kAsSimulated, false);
    EXPECT_NE(cal.step_scale, 1.0);
    EXPECT_EQ(pop.step_scale, 1.0);
    with.push_back(std::fabs(cal.distance_error_fraction));
    without.push_back(std::fabs(pop.distance_error_fraction));
  }
  std::sort(with.begin(), with.end());
  std::sort(without.begin(), without.end());
  RecordProperty("median_abs_distance_error_percent", std::to_string(100 * with[5]));
  RecordProperty("uncalibrated_percent", std::to_string(100 * without[5]));
  EXPECT_LE(with[5], 0.01);
  EXPECT_LE(with[9], 0.025);
  EXPECT_GT(without[5], 2 * with[5]);
}

TEST(Pdr, ClosedLoopsWithIdealSensorsInOnePose) {
  std::vector<double> err;
  for (int i = 0; i < 10; ++i)
    err.push_back(sim::simulate_pdr_loop(static_cast<std::uint64_t>(2001 + i),
                                         sim::LoopVariant::kIdealSensors)
                      .error_fraction);
  std::sort(err.begin(), err.end());
  EXPECT_LE(err[5], 0.03);
}

}  // namespace
}  // namespace telltale::fusion
