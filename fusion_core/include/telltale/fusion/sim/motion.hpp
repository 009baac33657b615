#pragma once
/// \file
/// Rigid-body kinematics of the simulators. A trajectory gives the pose of a body (attitude and
/// the velocity of its origin, world frame ENU, z up) as smooth functions of time; its rates and
/// accelerations come from differentiating them (SmoothTrajectory) or from a dynamics model
/// (the pendulum). The sensor sits at a lever arm from the body origin.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace telltale::fusion::sim {

/// Pose and its derivatives at one instant.
struct RigidMotion {
  Eigen::Quaterniond att = Eigen::Quaterniond::Identity();      ///< body (FLU) -> world (ENU)
  Eigen::Vector3d omega_body_rad_s = Eigen::Vector3d::Zero();   ///< angular rate, body frame
  Eigen::Vector3d alpha_body_rad_s2 = Eigen::Vector3d::Zero();  ///< angular acceleration, body
  Eigen::Vector3d acc_world_m_s2 = Eigen::Vector3d::Zero();     ///< acceleration of the origin
  Eigen::Vector3d vel_world_m_s = Eigen::Vector3d::Zero();      ///< velocity of the origin
};

/// Specific force at the sensor (lever arm r, body frame): the acceleration of the sensor point
/// a_s = a_o + R (alpha x r + omega x (omega x r)), and f = R^T (a_s - g_vec) with
/// g_vec = (0, 0, -g): +g up at rest.
[[nodiscard]] Eigen::Vector3d specific_force_body(const RigidMotion& m,
                                                  const Eigen::Vector3d& lever_arm_body_m,
                                                  double g_m_s2);

/// Heel and pitch of an attitude (the ZYX roll and pitch of SPEC section 1): from the world's up
/// seen in the body, u = R^T e_z: heel = atan2(u_y, u_z), pitch = atan2(u_x, hypot(u_y, u_z)).
void heel_pitch_of(const Eigen::Quaterniond& att, double& heel_rad, double& pitch_rad);

/// Attitude from heel, pitch and yaw (rad): R = Rz(yaw) Ry(-pitch) Rx(heel).
[[nodiscard]] Eigen::Quaterniond attitude_from_euler(double heel_rad, double pitch_rad,
                                                     double yaw_rad);

/// A motion of a rigid body over time, queried at increasing times.
class Trajectory {
 public:
  virtual ~Trajectory() = default;
  [[nodiscard]] virtual RigidMotion motion(double t_s) = 0;
};

/// A trajectory given by smooth attitude(t) and velocity_world(t); rates and accelerations by
/// five-point central differences (step h_s; error O(h^4)).
class SmoothTrajectory : public Trajectory {
 public:
  [[nodiscard]] RigidMotion motion(double t_s) override;
  [[nodiscard]] virtual Eigen::Quaterniond attitude(double t_s) const = 0;
  [[nodiscard]] virtual Eigen::Vector3d velocity_world(double t_s) const = 0;
  /// Body rate at t by differentiating the attitude.
  [[nodiscard]] Eigen::Vector3d body_rate(double t_s) const;

 protected:
  double h_s_ = 1e-3;
};

}  // namespace telltale::fusion::sim
