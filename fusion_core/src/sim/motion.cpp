// Rigid-body kinematics of the simulators.
#include "telltale/fusion/sim/motion.hpp"

#include <cmath>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion::sim {

Eigen::Vector3d specific_force_body(const RigidMotion& m, const Eigen::Vector3d& r, double g) {
  const Eigen::Vector3d& w = m.omega_body_rad_s;
  const Eigen::Vector3d lever = m.alpha_body_rad_s2.cross(r) + w.cross(w.cross(r));
  return m.att.conjugate() * (m.acc_world_m_s2 + Eigen::Vector3d(0.0, 0.0, g)) + lever;
}

void heel_pitch_of(const Eigen::Quaterniond& att, double& heel_rad, double& pitch_rad) {
  tilt_from_accel(att.conjugate() * Eigen::Vector3d::UnitZ(), heel_rad, pitch_rad);
}

Eigen::Quaterniond attitude_from_euler(double heel_rad, double pitch_rad, double yaw_rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(-pitch_rad, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(heel_rad, Eigen::Vector3d::UnitX()));
}

namespace {
/// Rotation vector of a (near-identity) quaternion.
Eigen::Vector3d rotvec(const Eigen::Quaterniond& q) {
  const Eigen::AngleAxisd aa(q.w() < 0 ? Eigen::Quaterniond(-q.coeffs()) : q);
  return aa.angle() * aa.axis();
}
}  // namespace

Eigen::Vector3d SmoothTrajectory::body_rate(double t) const {
  // phi(d) = log(R(t)^T R(t + d)) is smooth in d with phi(0) = 0 and phi'(0) = omega_body.
  const Eigen::Quaterniond q0 = attitude(t).conjugate();
  const double h = h_s_;
  const Eigen::Vector3d p1 = rotvec(q0 * attitude(t + h));
  const Eigen::Vector3d m1 = rotvec(q0 * attitude(t - h));
  const Eigen::Vector3d p2 = rotvec(q0 * attitude(t + 2 * h));
  const Eigen::Vector3d m2 = rotvec(q0 * attitude(t - 2 * h));
  return (m2 - 8.0 * m1 + 8.0 * p1 - p2) / (12.0 * h);
}

RigidMotion SmoothTrajectory::motion(double t) {
  const double h = h_s_;
  RigidMotion m;
  m.att = attitude(t);
  m.omega_body_rad_s = body_rate(t);
  m.alpha_body_rad_s2 = (body_rate(t - 2 * h) - 8.0 * body_rate(t - h) + 8.0 * body_rate(t + h) -
                         body_rate(t + 2 * h)) /
                        (12.0 * h);
  m.acc_world_m_s2 = (velocity_world(t - 2 * h) - 8.0 * velocity_world(t - h) +
                      8.0 * velocity_world(t + h) - velocity_world(t + 2 * h)) /
                     (12.0 * h);
  m.vel_world_m_s = velocity_world(t);
  return m;
}

}  // namespace telltale::fusion::sim
