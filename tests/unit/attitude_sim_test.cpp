// Invariants of the attitude simulator: kinematics, the sensor model, the scenarios.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "telltale/fusion/attitude.hpp"
#include "telltale/fusion/sim/scenario.hpp"

namespace telltale::fusion::sim {
namespace {

constexpr double kG = telltale::fusion::kStandardGravity_m_s2;
constexpr double kDeg = M_PI / 180.0;

ScenarioOptions ideal() {
  ScenarioOptions o;
  o.errors = ImuErrorParams::ideal();
  return o;
}

/// A test trajectory with closed-form position, so the simulator's lever-arm acceleration can be
/// checked against finite differences of the sensor's position.
class Wobble final : public SmoothTrajectory {
 public:
  [[nodiscard]] Eigen::Quaterniond attitude(double t) const override {
    return attitude_from_euler(0.4 * std::sin(1.3 * t), 0.2 * std::cos(0.9 * t),
                               0.8 * t + 0.3 * std::sin(2.1 * t));
  }
  [[nodiscard]] Eigen::Vector3d position(double t) const {
    return {2.0 * t + 0.3 * std::sin(1.7 * t), 0.5 * std::cos(1.1 * t), 0.2 * std::sin(2.3 * t)};
  }
  [[nodiscard]] Eigen::Vector3d velocity_world(double t) const override {
    return {2.0 + 0.51 * std::cos(1.7 * t), -0.55 * std::sin(1.1 * t), 0.46 * std::cos(2.3 * t)};
  }
};

// Given a body moving and rotating smoothly with a sensor 1.5 m off its origin, the simulator's
// specific force equals R^T (d2/dt2 (p + R r) + g e_z) by central differences of the position.
TEST(Motion, LeverArmAccelerationMatchesFiniteDifferences) {
  Wobble traj;
  const Eigen::Vector3d r(1.5, -0.2, 0.3);
  for (double t : {0.3, 1.7, 4.2}) {
    const RigidMotion m = traj.motion(t);
    const double h = 1e-3;
    const auto sensor = [&](double s) {
      return Eigen::Vector3d(traj.position(s) + traj.attitude(s) * r);
    };
    const Eigen::Vector3d acc = (sensor(t + h) - 2.0 * sensor(t) + sensor(t - h)) / (h * h);
    const Eigen::Vector3d expected = m.att.conjugate() * (acc + Eigen::Vector3d(0.0, 0.0, kG));
    EXPECT_LT((specific_force_body(m, r, kG) - expected).norm(), 1e-4) << "t=" << t;
  }
}

// The body rate integrated over a step reproduces the attitude increment.
TEST(Motion, BodyRateIsTheDerivativeOfTheAttitude) {
  Wobble traj;
  const double t = 2.0;
  const double h = 1e-4;
  const Eigen::AngleAxisd inc(traj.attitude(t - h).conjugate() * traj.attitude(t + h));
  EXPECT_LT((inc.angle() * inc.axis() / (2 * h) - traj.motion(t).omega_body_rad_s).norm(), 1e-6);
}

// Given the turntable still (first 5 s) with ideal sensors, the accelerometer reads
// g (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)) with heel -17.5, pitch 7.5.
TEST(Scenario, StaticPoseReadsGravity) {
  auto sc = make_scenario("turntable", 3, 25.0, 4.0, ideal());
  ImuSample s;
  AttitudeTruth t;
  int n = 0;
  while (sc->next(s, t)) {
    const double h = -17.5 * kDeg;
    const double p = 7.5 * kDeg;
    const Eigen::Vector3d g(kG * std::sin(p), kG * std::cos(p) * std::sin(h),
                            kG * std::cos(p) * std::cos(h));
    EXPECT_LT((s.acc_body_m_s2 - g).norm(), 1e-9);
    EXPECT_LT(s.gyro_body_rad_s.norm(), 1e-12);
    EXPECT_NEAR(t.heel_rad / kDeg, -17.5, 1e-12);
    ++n;
  }
  EXPECT_EQ(n, 101);
}

// Given the paper's pendulum released from 30 deg with the instrument at the bob, when it swings,
// then the accelerometer reads almost no tilt in the swing plane (the bob is in free fall along
// the swing, only damping and the few cm of offset show), while the truth swings +-30 deg.
TEST(Scenario, PendulumBobReadsNoSwingPlaneTilt) {
  for (const char* name : {"pendulum-heel-30", "pendulum-pitch-30"}) {
    auto sc = make_scenario(name, 2, 100.0, 25.0, ideal());
    ImuSample s;
    AttitudeTruth t;
    double max_truth = 0.0;
    double max_acc_tilt = 0.0;
    const bool heel = std::string(name).find("heel") != std::string::npos;
    while (sc->next(s, t)) {
      if (t.t_s < 5.5) continue;
      double h = 0.0;
      double p = 0.0;
      tilt_from_accel(s.acc_body_m_s2, h, p);
      max_truth = std::max(max_truth, std::abs(heel ? t.heel_rad : t.pitch_rad));
      max_acc_tilt = std::max(max_acc_tilt, std::abs(heel ? h : p));
    }
    EXPECT_GT(max_truth / kDeg, 25.0) << name;
    EXPECT_LT(max_acc_tilt / kDeg, 2.5) << name;
  }
}

// The pendulum's period is that of a 0.95 m pendulum (2 pi sqrt(L/g) ~ 1.955 s, +1.7 % at 30 deg).
TEST(Scenario, PendulumSwingsWithItsPhysicalPeriod) {
  auto sc = make_scenario("pendulum-heel-5", 2, 100.0, 25.0, ideal());
  ImuSample s;
  AttitudeTruth t;
  double prev = 0.0;
  std::vector<double> crossings;
  while (sc->next(s, t)) {
    if (t.t_s > 5.0 && prev < 0.0 && t.heel_rad >= 0.0) crossings.push_back(t.t_s);
    prev = t.heel_rad;
  }
  ASSERT_GE(crossings.size(), 5u);
  const double period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(period, 2.0 * M_PI * std::sqrt(0.95 / kG), 0.01);
}

// With ideal sensors the gyro is the mean rate over each interval: integrating it reproduces the
// true attitude of the dinghy through waves and tacks.
TEST(Scenario, IdealGyroIntegratesToTheTruth) {
  auto sc = make_scenario("dinghy", 4, 25.0, 120.0, ideal());
  ImuSample s;
  AttitudeTruth t;
  sc->next(s, t);
  Eigen::Quaterniond q = attitude_from_euler(t.heel_rad, t.pitch_rad, t.yaw_rad);
  double max_err = 0.0;
  double last = t.t_s;
  while (sc->next(s, t)) {
    const Eigen::Vector3d v = s.gyro_body_rad_s * (s.t_s - last);
    last = s.t_s;
    if (v.norm() > 0) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(v.norm(), v.normalized()));
    double h = 0.0;
    double p = 0.0;
    heel_pitch_of(q, h, p);
    max_err = std::max({max_err, std::abs(h - t.heel_rad), std::abs(p - t.pitch_rad)});
  }
  EXPECT_LT(max_err / kDeg, 1e-6);
}

// The error model: white noise with the datasheet density, one LSB steps, clipping at full scale.
TEST(ImuErrorModel, NoiseQuantisationAndSaturation) {
  ImuErrorParams p;
  p.gyro_bias_max_rad_s = p.gyro_bias_walk_rad_s_sqrt_s = p.gyro_scale_max =
      p.gyro_misalign_max_rad = 0;
  p.gyro_lsb_rad_s = 0;
  ImuErrorModel m(p, 7);
  const double rate = 100.0;
  double sum2 = 0.0;
  const int n = 20000;
  Eigen::Vector3d g;
  Eigen::Vector3d a;
  for (int k = 0; k < n; ++k) {
    m.apply(0.01, rate, Eigen::Vector3d::Zero(), {0.0, 0.0, kG}, g, a);
    sum2 += g.x() * g.x();
    const double steps = a.z() / p.acc_lsb_m_s2;
    ASSERT_NEAR(steps, std::round(steps), 1e-6);
  }
  const double expected = p.gyro_noise_density_rad_s_sqrt_hz * std::sqrt(rate / 2.0);
  EXPECT_NEAR(std::sqrt(sum2 / n), expected, 0.03 * expected);
  m.apply(0.01, rate, {100.0, 0.0, 0.0}, {100.0, 0.0, kG}, g, a);
  EXPECT_NEAR(g.x(), p.gyro_full_scale_rad_s, 1e-12);
  EXPECT_NEAR(a.x(), p.acc_full_scale_m_s2, 1e-12);
}

TEST(Scenario, EveryNameBuildsIsDeterministicAndDinghyStreamsEndlessly) {
  for (const auto& name : scenario_names()) {
    auto a = make_scenario(name, 9, 25.0, 2.0);
    auto b = make_scenario(name, 9, 25.0, 2.0);
    ASSERT_NE(a, nullptr) << name;
    ImuSample sa;
    ImuSample sb;
    AttitudeTruth ta;
    AttitudeTruth tb;
    while (a->next(sa, ta)) {
      ASSERT_TRUE(b->next(sb, tb));
      ASSERT_EQ(sa.acc_body_m_s2, sb.acc_body_m_s2) << name;
      ASSERT_EQ(sa.gyro_body_rad_s, sb.gyro_body_rad_s) << name;
    }
  }
  EXPECT_EQ(make_scenario("no-such-scenario", 1, 25.0, 1.0), nullptr);
  auto endless = make_scenario("dinghy", 1, 25.0, 0.0);
  ImuSample s;
  AttitudeTruth t;
  for (int k = 0; k < 25 * 400; ++k) ASSERT_TRUE(endless->next(s, t));
  EXPECT_NEAR(t.t_s, 399.96, 1e-9);
  EXPECT_TRUE(s.acc_body_m_s2.allFinite() && s.gyro_body_rad_s.allFinite());
}

// Non-uniform sampling: jittered and dropped samples keep time strictly increasing.
TEST(Scenario, JitterAndDropsKeepTimeIncreasing) {
  ScenarioOptions o;
  o.jitter_s = 0.003;
  o.drop_probability = 0.2;
  auto sc = make_scenario("desk", 1, 100.0, 20.0, o);
  ImuSample s;
  AttitudeTruth t;
  double last = -1.0;
  int n = 0;
  while (sc->next(s, t)) {
    ASSERT_GT(s.t_s, last);
    last = s.t_s;
    ++n;
  }
  EXPECT_NEAR(n, 1600, 80);
}

}  // namespace
}  // namespace telltale::fusion::sim
