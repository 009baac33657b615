#pragma once
/// \file
/// The one IMU sample type every filter in fusion_core consumes.
/// Frames and signs: body frame FLU (x bow, y port, z up), see idl/README.md.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace telltale::fusion {

/// One inertial sample in the body frame (FLU).
struct ImuSample {
  double t_s = 0.0;                                       ///< sample time, seconds (any epoch)
  Eigen::Vector3d gyro_body_rad_s = Eigen::Vector3d::Zero();  ///< body rate, rad/s, right-hand
  Eigen::Vector3d acc_body_m_s2 = Eigen::Vector3d::Zero();    ///< specific force, m/s^2 (+g up at rest)
};

/// The body's rotation over one sample interval from the rates at both ends (trapezoidal rate,
/// exact rotation): q such that v_reference = q v_body_after for a vector expressed in the body
/// frame before (attitude_after = attitude_before * q). A world-fixed vector's coordinates turn
/// by q^-1. Identity for a negligible turn.
[[nodiscard]] inline Eigen::Quaterniond interval_rotation(const Eigen::Vector3d& rate_before,
                                                          const Eigen::Vector3d& rate_after,
                                                          double dt_s) {
  const Eigen::Vector3d theta = 0.5 * (rate_before + rate_after) * dt_s;
  const double angle = theta.norm();
  if (!(angle > 1e-12)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle));
}

}  // namespace telltale::fusion
