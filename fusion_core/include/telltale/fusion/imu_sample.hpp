#pragma once
/// \file
/// The one IMU sample type every filter in fusion_core consumes.
/// Frames and signs: body frame FLU (x bow, y port, z up), see idl/README.md.

#include <Eigen/Core>

namespace telltale::fusion {

/// One inertial sample in the body frame (FLU).
struct ImuSample {
  double t_s = 0.0;                                       ///< sample time, seconds (any epoch)
  Eigen::Vector3d gyro_body_rad_s = Eigen::Vector3d::Zero();  ///< body rate, rad/s, right-hand
  Eigen::Vector3d acc_body_m_s2 = Eigen::Vector3d::Zero();    ///< specific force, m/s^2 (+g up at rest)
};

}  // namespace telltale::fusion
