#include "telltale/fusion/pdr/foot_ins.hpp"

#include <cmath>

namespace telltale::fusion {

bool FootIns::update(const ImuSample& s, double dt_s) {
  const Eigen::Vector3d& f = s.acc_body_m_s2;
  const Eigen::Vector3d& w = s.gyro_body_rad_s;
  if (!started_) {
    // The first attitude from gravity: the smallest rotation taking the measured up to the
    // vertical (a foot about to walk stands still). Nothing to go on in free fall.
    if (!(f.norm() > 0.5 * kStandardGravity_m_s2)) return false;
    q_ = Eigen::Quaterniond::FromTwoVectors(f, Eigen::Vector3d::UnitZ());
    started_ = true;
    return false;
  }
  if (!(dt_s > 0.0)) return false;
  if (dt_s > params_.max_gap_s) {
    // Samples lost: the rotation over the gap is unknown. A swing in progress is not measured;
    // the next one is, from the next stance.
    if (!stance_ && !waiting_) ++dropped_;
    waiting_ = true;
    still_s_ = 0.0;
    dtheta_prev_rad_.setZero();
    return false;
  }
  // The sample's rate over the interval that ends at it (a MEMS gyro's sample is close to the
  // mean rate over it) with the coning term, as a rotation of exact angle.
  const Eigen::Vector3d dtheta = w * dt_s;
  q_ = (q_ * rotation_of(coned_rotation_vector(dtheta_prev_rad_, dtheta))).normalized();
  dtheta_prev_rad_ = dtheta;

  const bool still = w.norm() < params_.stance_gyro_rad_s &&
                     std::abs(f.norm() - g_.g_m_s2) < params_.stance_acc_m_s2;
  still_s_ = still ? still_s_ + dt_s : 0.0;
  if (waiting_) {
    if (still_s_ < params_.stance_min_s) return false;
    waiting_ = false;  // a stance again: level from here and measure the next swing
    stance_ = true;
  }
  if (stance_) {
    if (still) {
      // Foot flat: up is what the accelerometer says. Level to it (the smallest rotation, about
      // a horizontal axis: the yaw stays), and learn the accelerometer's g.
      q_ = Eigen::Quaterniond::FromTwoVectors(q_ * f, Eigen::Vector3d::UnitZ()) * q_;
      q_.normalize();
      g_.still(f.norm(), dt_s, params_.g_tau_s);
      return false;
    }
    stance_ = false;  // the swing begins at this sample
    v_.setZero();
    p_.setZero();
    swing_s_ = 0.0;
  }
  // Swing: navigate. The specific force in the world less gravity is the acceleration.
  const Eigen::Vector3d a =
      q_ * force_at_its_instant(f, dtheta) - Eigen::Vector3d(0.0, 0.0, g_.g_m_s2);
  v_ += a * dt_s;
  p_ += v_ * dt_s;
  swing_s_ += dt_s;
  if (swing_s_ > params_.max_swing_s) {
    // No stance for this long: not a walking stride. Start over at the next stance.
    ++dropped_;
    waiting_ = true;
    return false;
  }
  if (still_s_ < params_.stance_min_s) return false;
  // A stance: the velocity left is all error, taken as grown evenly since the swing began; its
  // integral comes off the displacement.
  p_ -= 0.5 * swing_s_ * v_;
  stride_m_ = p_.head<2>();
  stance_ = true;
  v_.setZero();
  return true;
}

double FootIns::sensor_yaw_rad() const {
  const Eigen::Vector3d x = q_ * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

}  // namespace telltale::fusion
