#include "telltale/fusion/complementary.hpp"

#include <cmath>

namespace telltale::fusion {

void tilt_from_accel(const Eigen::Vector3d& f, double& heel_rad, double& pitch_rad) {
  // At rest f = g (sin(pitch), cos(pitch) sin(heel), cos(pitch) cos(heel)).
  heel_rad = std::atan2(f.y(), f.z());
  pitch_rad = std::atan2(f.x(), std::hypot(f.y(), f.z()));
}

void ComplementaryFilter::update(const ImuSample& s) {
  if (!std::isfinite(s.t_s) || !s.gyro_body_rad_s.allFinite() || !s.acc_body_m_s2.allFinite()) {
    ++diag_.rejected_non_finite;
    return;
  }
  double heel_acc = 0.0;
  double pitch_acc = 0.0;
  tilt_from_accel(s.acc_body_m_s2, heel_acc, pitch_acc);
  if (!state_.initialised) {
    state_ = {heel_acc, pitch_acc, s.t_s, true};
    return;
  }
  const double dt = s.t_s - state_.last_t_s;
  if (!(dt > 0.0)) {
    ++diag_.rejected_time;
    return;
  }
  state_.last_t_s = s.t_s;
  // ZYX Euler kinematics: body rates -> roll and pitch rates.
  const double p = s.gyro_body_rad_s.x();
  const double q = s.gyro_body_rad_s.y();
  const double r = s.gyro_body_rad_s.z();
  // SPEC section 1 defines pitch as bow-up positive. In FLU a positive rotation about +y (port)
  // puts the bow down, so pitch = -theta of the standard ZYX sequence R = Rz(psi) Ry(theta)
  // Rx(phi), while heel = phi. The standard Euler-rate relations then read:
  //   dphi/dt   = p + (q sin(phi) + r cos(phi)) tan(theta)
  //   dtheta/dt = q cos(phi) - r sin(phi)
  const double sr = std::sin(state_.heel_rad);
  const double cr = std::cos(state_.heel_rad);
  const double tan_theta = -std::tan(state_.pitch_rad);
  const double heel_rate = p + (q * sr + r * cr) * tan_theta;
  const double pitch_rate = -(q * cr - r * sr);
  const double k = dt / (params_.tau_s + dt);
  const double heel_pred = state_.heel_rad + heel_rate * dt;
  const double pitch_pred = state_.pitch_rad + pitch_rate * dt;
  state_.heel_rad = heel_pred + k * std::remainder(heel_acc - heel_pred, 2.0 * M_PI);
  state_.pitch_rad = pitch_pred + k * (pitch_acc - pitch_pred);
}

}  // namespace telltale::fusion
