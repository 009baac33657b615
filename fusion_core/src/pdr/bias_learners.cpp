#include "telltale/fusion/pdr/bias_learners.hpp"

#include <algorithm>
#include <cmath>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {

void GyroBiasLearner::add(const ImuSample& s) {
  if (n_ == 0) t0_ = s.t_s;
  ++n_;
  w_ += s.gyro_body_rad_s;
  w2_ += s.gyro_body_rad_s.squaredNorm();
  const double a = s.acc_body_m_s2.norm();
  a_ += a;
  a2_ += a * a;
  if (s.t_s - t0_ < params_.window_s) return;
  const double n = n_;
  const Eigen::Vector3d mean_w = w_ / n;
  const double var_w = w2_ / n - mean_w.squaredNorm();
  const double mean_a = a_ / n, var_a = a2_ / n - mean_a * mean_a;
  const bool still = n_ >= 10 && var_w < params_.gyro_std_rad_s * params_.gyro_std_rad_s &&
                     var_a < params_.acc_std_m_s2 * params_.acc_std_m_s2 &&
                     mean_w.norm() < params_.max_bias_rad_s;
  if (still) {
    ++windows_;
    bias_ += (mean_w - bias_) / std::min(windows_, 10u);
  }
  n_ = 0;
  w_.setZero();
  w2_ = a_ = a2_ = 0.0;
}

void AccBiasLearner::add(const Eigen::Vector3d& gyro, const Eigen::Vector3d& up,
                         const Eigen::Vector3d& mag) {
  // One sample of what the field's vertical component says about the up direction (sensor
  // frame; at_step). The caller leaves out arm swing (the pendulum's acceleration tilts
  // up in step with the swing, which also turns the horizontal field in the phone) and the few
  // up time constants after the phone moved. Turns are left out here: what is left of the
  // centripetal acceleration tilts up with the turn, in step with the change of heading the
  // estimate feeds on.
  if (!(std::abs(gyro.dot(up)) < params_.max_turn_rad_s)) return;
  const double vertical = mag.dot(up);
  const Eigen::Vector3d r = (mag - vertical * up) / kStandardGravity_m_s2;
  z_sum_ += vertical + r.dot(bias_);
  r_sum_ += r;
  up_sum_ += up;
  ++n_;
}

void AccBiasLearner::at_step(double t_s, const Eigen::Vector3d& mag_offset_uT) {
  // The earth field's vertical component is the same wherever the walker faces. Up tilted by
  // an angle d (a vector across up, rad) reads m.up + m_h.d, where m_h is the horizontal field
  // in the sensor frame, which turns round as the walker turns: a tilt fixed in the phone shows
  // as a vertical field that changes with the heading. An accelerometer bias b tilts up by
  // b_h / g (its part across up), so, with the bias already removed (bias_) and C the
  // vertical field plus the hard-iron residual along up (constant while the phone sits the same
  // way, free after a pose change):
  //   m.up + m_h.bias_ / g = C + m_h.b / g.
  // One measurement per step (the step's means), a Kalman filter for [C, b].
  if (n_ == 0) return;
  const double n = n_;
  const double z = z_sum_ / n;
  const Eigen::Vector3d r = r_sum_ / n;
  // A better hard-iron offset moves the corrected field, and C with it, by the change along up.
  const Eigen::Vector3d& offset = mag_offset_uT;
  x_[0] -= (offset - offset_uT_).dot(up_sum_ / n);
  offset_uT_ = offset;
  z_sum_ = 0.0;
  r_sum_.setZero();
  up_sum_.setZero();
  n_ = 0;
  if (t_s_ >= 0.0)
    p_(0, 0) += params_.vertical_walk_uT * params_.vertical_walk_uT * std::max(0.0, t_s - t_s_);
  t_s_ = t_s;
  Eigen::Vector4d h;
  h << 1.0, r;
  const double var = params_.step_noise_uT * params_.step_noise_uT;
  const double innovation = z - h.dot(x_);
  const double s = h.dot(p_ * h) + var;
  if (!std::isfinite(innovation) || !(s > 0.0)) return;
  // A magnetic disturbance (steel, a car) moves the vertical field by far more than a bias can.
  if (innovation * innovation > 25.0 * s) return;
  const Eigen::Vector4d k = p_ * h / s;
  x_ += k * innovation;
  p_ -= k * h.transpose() * p_;
  p_ = 0.5 * (p_ + p_.transpose()).eval();  // symmetric over hours of steps
  // Past a few times the prior the estimate is no bias (a field that is not the earth's):
  // the last plausible one stays.
  if (x_.tail<3>().norm() < 5.0 * params_.prior_m_s2) bias_ = x_.tail<3>();
}

void AccBiasLearner::forget(double settled_t_s) {
  // The phone now sits another way: the hard-iron residual along up, hence C, is new.
  p_.row(0).setZero();
  p_.col(0).setZero();
  p_(0, 0) = 1e4;
  settled_t_s_ = settled_t_s;
  z_sum_ = 0.0;
  r_sum_.setZero();
  up_sum_.setZero();
  n_ = 0;
}

}  // namespace telltale::fusion
