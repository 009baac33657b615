// ForwardAxisYaw (forward_axis_yaw.hpp): the turn of a body-fixed axis about the vertical, on
// orientations given exactly as ZYX angles (yaw psi, pitch theta, roll phi): the body's x axis
// points at azimuth psi whatever the pitch and roll, so psi is the truth for forward = x. The
// gyro is the exact rotation between consecutive orientations over the interval, the vertical
// the exact one.
#include "telltale/fusion/forward_axis_yaw.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

namespace {

using telltale::fusion::ForwardAxisYaw;

struct Angles {
  double psi, theta, phi;
};

Eigen::Quaterniond body_to_level(const Angles& a) {
  return Eigen::AngleAxisd(a.psi, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(a.theta, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(a.phi, Eigen::Vector3d::UnitX());
}

struct Turns {
  double forward_rad = 0.0;  ///< ForwardAxisYaw's, summed
  double rate_up_rad = 0.0;  ///< the rate about the vertical, integrated
  double truth_rad = 0.0;    ///< psi's change
};

/// Runs `angles` (a function of time) at rate_hz for duration_s through a ForwardAxisYaw of the
/// given axis.
Turns run(const std::function<Angles(double)>& angles, const Eigen::Vector3d& forward,
          double rate_hz, double duration_s) {
  ForwardAxisYaw yaw(forward);
  const double dt = 1.0 / rate_hz;
  Eigen::Quaterniond q_prev = body_to_level(angles(0.0));
  yaw.update(Eigen::Vector3d::Zero(), 0.0, q_prev.conjugate() * Eigen::Vector3d::UnitZ());
  Turns out;
  const int n = static_cast<int>(std::lround(duration_s * rate_hz));
  for (int i = 1; i <= n; ++i) {
    const Eigen::Quaterniond q = body_to_level(angles(i * dt));
    const Eigen::AngleAxisd step(q_prev.conjugate() * q);  // body frame, over dt
    const Eigen::Vector3d rate = step.axis() * step.angle() / dt;
    const Eigen::Vector3d up = q.conjugate() * Eigen::Vector3d::UnitZ();
    out.forward_rad += yaw.update(rate, dt, up);
    out.rate_up_rad += rate.dot(up) * dt;
    q_prev = q;
  }
  out.truth_rad = angles(n * dt).psi - angles(0.0).psi;
  return out;
}

}  // namespace

// A hand whose pitch and roll swing a quarter period apart (6 deg each, twice a second, the
// phone pitched 30 deg) while the phone keeps pointing the same way: every swing is a loop in
// (roll, pitch), and the rate about the vertical gathers its area (psi' = omega . up +
// phi' sin(theta)): 120 loops turn it by ~3 rad. The axis does not turn.
// Seen failing with update() returning the rate about the vertical: 3.30 rad.
TEST(ForwardAxisYaw, AHandsLoopsDoNotTurnTheAxis) {
  const double a = 0.1;
  const double w = 2.0 * M_PI * 2.0;
  const auto coning = [&](double t) {
    return Angles{0.3, 0.5 + a * std::sin(w * t), a * std::cos(w * t)};
  };
  const Turns t = run(coning, Eigen::Vector3d::UnitX(), 100.0, 60.0);
  EXPECT_NEAR(t.truth_rad, 0.0, 1e-12);
  EXPECT_GT(std::abs(t.rate_up_rad), 2.0);  // the effect is there to be missed
  EXPECT_NEAR(t.forward_rad, 0.0, 1e-3);
}

// A steady turn of a tilted body (28.6 deg/s, pitch 23 deg, roll -17 deg): both the axis and the
// rate about the vertical turn by psi, to rounding; at 25 Hz as at 200.
TEST(ForwardAxisYaw, ASteadyTiltedTurnIsTheTurn) {
  const auto turn = [](double t) { return Angles{0.5 * t, 0.4, -0.3}; };
  for (const double hz : {25.0, 200.0}) {
    const Turns t = run(turn, Eigen::Vector3d::UnitX(), hz, 10.0);
    EXPECT_NEAR(t.forward_rad, 5.0, 1e-9) << hz;
    EXPECT_NEAR(t.rate_up_rad, 5.0, 1e-9) << hz;
  }
}

// A walk's U-turn with the hand's loops on it (180 deg in 4 s, then 10 s straight; the phone's
// forward axis, kHandheldForward): the axis ends where it truly points, within 0.1 deg; the
// integrated rate 20 deg off (seen failing so, with update() returning it).
TEST(ForwardAxisYaw, AUTurnWithTheHandsLoopsEndsWherePsiDoes) {
  const double a = 0.08;
  const double w = 2.0 * M_PI * 1.8;
  const auto walk = [&](double t) {
    const double psi =
        t < 4.0 ? M_PI * (t / 4.0 - std::sin(2.0 * M_PI * t / 4.0) / (2.0 * M_PI)) : M_PI;
    return Angles{psi, 0.6 + a * std::sin(w * t), a * std::cos(w * t)};
  };
  const Turns t = run(walk, Eigen::Vector3d(0.0, 1.0, -1.0).normalized(), 50.0, 14.0);
  // The truth for this axis: its azimuth at the end less at the start (not psi: it is not x).
  const auto azimuth = [](const Angles& g) {
    const Eigen::Vector3d f = body_to_level(g) * Eigen::Vector3d(0.0, 1.0, -1.0).normalized();
    return std::atan2(f.y(), f.x());
  };
  const double truth = std::remainder(azimuth(walk(14.0)) - azimuth(walk(0.0)), 2.0 * M_PI);
  EXPECT_NEAR(std::remainder(t.forward_rad - truth, 2.0 * M_PI), 0.0, 0.1 * M_PI / 180.0);
  EXPECT_GT(std::abs(std::remainder(t.rate_up_rad - truth, 2.0 * M_PI)), 10.0 * M_PI / 180.0);
}

// An axis within 30 deg of the vertical has no direction to follow: the turn is the rate about
// the vertical (forward = z on a body turning level at 1 rad/s with a slight wobble).
TEST(ForwardAxisYaw, AnAxisNearTheVerticalFollowsTheRateAboutIt) {
  const auto turn = [](double t) { return Angles{t, 0.05 * std::sin(3.0 * t), 0.0}; };
  const Turns t = run(turn, Eigen::Vector3d::UnitZ(), 100.0, 3.0);
  EXPECT_DOUBLE_EQ(t.forward_rad, t.rate_up_rad);
  EXPECT_NEAR(t.forward_rad, 3.0, 0.01);
}

// After restart() (a gap) the first update reports nothing and levels; the turn goes on from there.
TEST(ForwardAxisYaw, RestartReportsNoTurnAcrossTheGap) {
  ForwardAxisYaw yaw(Eigen::Vector3d::UnitX());
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  EXPECT_EQ(yaw.update(Eigen::Vector3d::Zero(), 0.0, up), 0.0);
  EXPECT_NEAR(yaw.update(Eigen::Vector3d(0.0, 0.0, 1.0), 0.1, up), 0.1, 1e-9);
  yaw.restart();
  EXPECT_EQ(yaw.update(Eigen::Vector3d(0.0, 0.0, 5.0), 2.0, up), 0.0);
  EXPECT_NEAR(yaw.update(Eigen::Vector3d(0.0, 0.0, -1.0), 0.1, up), -0.1, 1e-9);
}
