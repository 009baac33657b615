#include "telltale/fusion/pdr/walking_heading.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

/// [v]x: the matrix of the cross product v x.
Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

// --- heading ----------------------------------------------------------------------------------
double HeadingFilter::magnetic_heading_rad(const Eigen::Vector3d& mag, const Eigen::Vector3d& up) {
  return magnetic_heading_rad(mag, up, Eigen::Vector3d::UnitX());
}

double HeadingFilter::magnetic_heading_rad(const Eigen::Vector3d& mag, const Eigen::Vector3d& up,
                                           const Eigen::Vector3d& axis) {
  const Eigen::Vector3d north = mag - mag.dot(up) * up;
  const double nn = north.norm();
  if (!(nn > 1e-6)) return std::nan("");
  const Eigen::Vector3d n = north / nn;
  const Eigen::Vector3d e = n.cross(up);
  const Eigen::Vector3d x = axis - axis.dot(up) * up;
  if (x.norm() < 0.3) return std::nan("");  // x within ~17 deg of vertical: no heading
  return wrap_2pi(std::atan2(x.dot(e), x.dot(n)));
}

void HeadingFilter::pull_up(double dt, const Eigen::Vector3d& gyro, bool gyro_ok, double t_s) {
  Eigen::Vector3d f = last_acc_;
  Eigen::Vector3d& up = state_.up;
  // Walking round a corner (0.6 m radius at 1.4 m/s: 3 m/s^2, 17 deg of tilt) the
  // accelerometer also reads the centripetal acceleration v w (toward the centre, left for a
  // left turn); left in, it tilts the up direction, and the magnetic heading by about
  // tan(dip) times as much, for seconds after every corner.
  const double w_up = last_gyro_ok_ ? last_gyro_.dot(up) : 0.0;
  Eigen::Vector3d fwd, left;
  if (speed_m_s_ > 0.0 && horizontal_axes(up, fwd, left)) f -= speed_m_s_ * w_up * left;
  // A swinging arm: the hand's pendulum acceleration (+-10 m/s^2 along the walking direction)
  // swung the up direction +-8 deg round the vertical every stride, and the magnetic heading
  // turned that into a bias of 2-3 deg that depends on the heading. Rotation about the
  // horizontal axes only: turning the body is the corner's business (above).
  const double span = t_s - before_t_s_;
  if (params_.lever_arm && gyro_ok && last_gyro_ok_ && before_gyro_ok_ && span > 0.0) {
    const auto horizontal = [&up](const Eigen::Vector3d& v) { return v - v.dot(up) * up; };
    const Eigen::Vector3d w = horizontal(last_gyro_);
    const Eigen::Vector3d w_dot = horizontal((gyro - before_gyro_) / span);
    const Eigen::Matrix3d a = cross_matrix(w_dot) + cross_matrix(w) * cross_matrix(w);
    const double keep = std::exp(-dt / params_.lever_arm_tau_s);
    lever_info_ = keep * lever_info_ + a.transpose() * a * dt;
    lever_sum_ = keep * lever_sum_ + a.transpose() * (f - kStandardGravity_m_s2 * up) * dt;
    // p changes over the forgetting time (10 s): solved again every 0.1 s, not every sample.
    if (t_s - lever_solved_t_s_ >= 0.1 || t_s < lever_solved_t_s_) {
      const double prior = std::pow(params_.lever_arm_noise_m_s2 / params_.lever_arm_prior_m, 2);
      lever_m_ = (lever_info_ + prior * Eigen::Matrix3d::Identity()).ldlt().solve(lever_sum_);
      lever_solved_t_s_ = t_s;
    }
    f -= a * lever_m_;
  }
  if (!(f.norm() > 1e-3)) return;
  up += dt / (params_.up_tau_s + dt) * (f.normalized() - up);
  up.normalize();
}

void HeadingFilter::update(double t_s, const Eigen::Vector3d& gyro, const Eigen::Vector3d& acc,
                           const Eigen::Vector3d& mag) {
  if (!std::isfinite(t_s) || !acc.allFinite() || !(acc.norm() > 1e-3)) {
    ++diag_.rejected_non_finite;
    return;
  }
  const bool gyro_ok = gyro.allFinite();
  const double dt = up_init_ ? t_s - state_.last_t_s : 0.0;
  if (up_init_ && !(dt > 0.0)) {
    ++diag_.rejected_non_finite;
    return;
  }
  const double t_prev = state_.last_t_s;
  state_.last_t_s = t_s;
  // Up direction in the walking frame: gyro-propagated (du/dt = u x w for a world-fixed vector),
  // pulled toward the accelerometer's direction with time constant up_tau_s.
  if (!up_init_) {
    state_.up = acc.normalized();
    up_init_ = true;
  } else {
    pull_up(dt, gyro, gyro_ok, t_s);
    if (gyro_ok) {
      // A world-fixed vector turns back by the body's rotation: trapezoidal rate, exact
      // rotation. A swinging arm turns the phone +-30 deg and back every stride, and the
      // first-order step (u += u x w dt with the end-of-interval rate) drifted the up direction
      // steadily, held only by the accelerometer's pull.
      state_.up =
          interval_rotation(last_gyro_ok_ ? last_gyro_ : gyro, gyro, dt).conjugate() * state_.up;
    }
  }
  before_gyro_ = last_gyro_;
  before_gyro_ok_ = last_gyro_ok_;
  before_t_s_ = t_prev;
  last_gyro_ = gyro;
  last_gyro_ok_ = gyro_ok;
  last_acc_ = acc;
  // Prediction: heading rate = -(yaw rate about up) (heading is clockwise).
  if (state_.initialised) {
    const double rate = gyro_ok ? -gyro.dot(state_.up) : 0.0;
    state_.heading_rad = wrap_2pi(state_.heading_rad + (rate - state_.bias_rad_s) * dt);
    Eigen::Matrix2d f;
    f << 1.0, -dt, 0.0, 1.0;
    const double q_h = gyro_ok ? params_.gyro_noise_rad_s * params_.gyro_noise_rad_s : 1.0;
    Eigen::Matrix2d q = Eigen::Matrix2d::Zero();
    q(0, 0) = q_h * dt;
    q(1, 1) = params_.bias_walk_rad_s2 * params_.bias_walk_rad_s2 * dt;
    state_.p = f * state_.p * f.transpose() + q;
  }
  if (!mag.allFinite()) {
    if (!state_.initialised) {  // no magnetometer: gyro heading relative to the start
      state_.heading_rad = 0.0;
      state_.p = Eigen::Matrix2d::Identity() * 1e-4;
      state_.initialised = true;
    }
    return;
  }
  const double z = magnetic_heading_rad(mag, state_.up);
  if (!std::isfinite(z)) return;
  const double r = std::pow(params_.mag_noise_deg * M_PI / 180.0, 2);
  if (!state_.initialised) {
    state_.heading_rad = z;
    state_.p << r, 0.0, 0.0, 1e-4;
    state_.initialised = true;
    state_.rejected_since_s = -1.0;
    return;
  }
  const double y = std::remainder(z - state_.heading_rad, kTwoPi);
  if (std::abs(y) > params_.gate_deg * M_PI / 180.0) {
    ++diag_.rejected_mag;
    if (state_.rejected_since_s < 0.0) state_.rejected_since_s = t_s;
    if (t_s - state_.rejected_since_s > params_.reset_after_s) {
      state_.heading_rad = z;
      state_.p << r, 0.0, 0.0, 1e-4;
      state_.rejected_since_s = -1.0;
      ++diag_.resets;
    }
    return;
  }
  state_.rejected_since_s = -1.0;
  const double s = state_.p(0, 0) + r;
  const Eigen::Vector2d k = state_.p.col(0) / s;
  state_.heading_rad = wrap_2pi(state_.heading_rad + k[0] * y);
  state_.bias_rad_s += k[1] * y;
  const Eigen::Matrix2d ikh = Eigen::Matrix2d::Identity() - k * Eigen::RowVector2d(1.0, 0.0);
  state_.p = ikh * state_.p;
}

// --- walking direction ------------------------------------------------------------------------
void WalkingDirection::add(double t_s, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyro,
                           const Eigen::Vector3d& up, bool arm_swing) {
  if (arm_swing) {
    // A swinging arm turns the phone about the shoulder's axis, across the walking direction
    // whatever the phone's yaw in the hand: its rotations are summed for the step's principal
    // axis (swing_axis_direction), in place of the acceleration pattern (the arm's, not the
    // trunk's).
    step_swing_.noalias() += gyro * gyro.transpose();
    have_av_ = false;
    return;
  }
  const double av = acc.dot(up);
  Eigen::Vector3d fwd, left;
  if (have_av_ && horizontal_axes(up, fwd, left)) {
    const double dav = (av - last_av_) / (t_s - last_av_t_);
    step_fwd_ += acc.dot(fwd) * dav;
    step_left_ += acc.dot(left) * dav;
  }
  last_av_ = av;
  last_av_t_ = t_s;
  have_av_ = true;
}

double WalkingDirection::at_step(double heading_rad, bool arm_swing, const Eigen::Vector3d& up) {
  // The sums of the last step count once this step shows that both were straight (a corner's
  // centripetal acceleration would bias them).
  const bool straight =
      have_last_raw_ && std::abs(std::remainder(heading_rad - last_raw_heading_rad_, kTwoPi)) <
                            params_.straight_deg * M_PI / 180.0;
  if (straight && last_straight_ && last_fwd_ > 0.0) {
    yaw_fwd_ += last_fwd_;
    yaw_left_ += last_left_;
    const double a = std::atan2(last_left_, last_fwd_);
    step_yaw_sum_ += a;
    step_yaw_sq_ += a * a;
    ++straight_steps_;
  }
  if (arm_swing) swing_axis_direction(up);
  last_fwd_ = step_fwd_;
  last_left_ = step_left_;
  step_fwd_ = step_left_ = 0.0;
  last_straight_ = straight;
  last_raw_heading_rad_ = heading_rad;
  have_last_raw_ = true;
  if (!params_.correct || straight_steps_ < std::max(2, params_.steps) || !(yaw_fwd_ > 0.0))
    return 0.0;
  const double n = straight_steps_, mean = step_yaw_sum_ / n;
  const double se2 = std::max(0.0, step_yaw_sq_ / n - mean * mean) / (n - 1.0);
  const double prior2 = std::pow(params_.prior_deg * M_PI / 180.0, 2);
  return prior2 / (prior2 + se2) * std::atan2(yaw_left_, yaw_fwd_);
}

void WalkingDirection::swing_axis_direction(const Eigen::Vector3d& up) {
  // Arm swing: the acceleration pattern is the arm's, not the trunk's, and says little about the
  // walking direction (2.8 deg rms per pose in the simulator). The arm swings in the walking
  // direction's vertical plane, so the step's principal rotation axis, made horizontal, is the
  // walking frame's left; forward = left x up. The pattern's step sums are replaced by that unit
  // direction (the arm's swing rate is ~1 rad/s, its gyro noise and bias ~0.01 rad/s).
  const Eigen::Matrix3d sw = step_swing_;
  step_swing_.setZero();
  step_fwd_ = step_left_ = 0.0;
  if (!(sw.trace() > 0.0)) return;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(sw);
  Eigen::Vector3d axis = eig.eigenvectors().col(2);
  // The swing must dominate: a stronger second axis (no swing, a turn, a hand moving about)
  // leaves the step without an estimate.
  if (!(eig.eigenvalues()[2] > params_.swing_axis_ratio * eig.eigenvalues()[1])) return;
  axis -= axis.dot(up) * up;
  Eigen::Vector3d fwd, left;
  if (axis.norm() < 0.5 || !horizontal_axes(up, fwd, left)) return;
  if (axis.dot(left) < 0.0) axis = -axis;
  const Eigen::Vector3d walk = axis.normalized().cross(up);
  step_fwd_ = walk.dot(fwd);
  step_left_ = walk.dot(left);
}

void WalkingDirection::reset() {
  step_swing_.setZero();
  yaw_fwd_ = yaw_left_ = 0.0;
  step_fwd_ = step_left_ = last_fwd_ = last_left_ = 0.0;
  have_last_raw_ = last_straight_ = false;
  step_yaw_sum_ = step_yaw_sq_ = 0.0;
  straight_steps_ = 0;
  have_av_ = false;
}

}  // namespace telltale::fusion
