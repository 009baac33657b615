#pragma once
/// \file
/// PDR stage: the sensor biases learnt while walking and standing (our additions). Each learner
/// owns its sums and its estimate, which the PDR removes from the samples before the heading
/// filter: the gyro bias from still windows, the accelerometer bias from the constancy of the
/// field's vertical component. The magnetometer's hard-iron offset is the third learner
/// (HardIronCalibrator, hard_iron.hpp), used as it is.
///
/// Memory: fixed-size Eigen types, no heap.

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

/// Gyro bias from standing still: a window of window_s in which the rate and |f| vary less than
/// the limits below gives the bias as its mean rate (the average of the last 10 such windows is
/// subtracted from every sample). A mean rate above max_bias_rad_s is a slow steady turn (a
/// vehicle), not a bias.
struct GyroBiasParams {
  double window_s = 1.0;
  double gyro_std_rad_s = 0.03;
  double acc_std_m_s2 = 0.15;
  double max_bias_rad_s = 0.1;
};

class GyroBiasLearner {
 public:
  using Params = GyroBiasParams;
  explicit GyroBiasLearner(Params params) : params_(params) {}
  /// Adds a sample that has a gyro (raw, sensor frame); a still window it closes sets the bias.
  void add(const ImuSample& s);
  /// Sensor frame, rad/s.
  [[nodiscard]] const Eigen::Vector3d& bias_rad_s() const { return bias_; }
  /// Still windows that set the bias so far (Pdr::Diagnostics::still_windows).
  [[nodiscard]] unsigned windows() const { return windows_; }

 private:
  Params params_;
  // The window in progress: its start, sums of the rate, |w|^2, |f| and |f|^2, and its size.
  double t0_ = 0.0, w2_ = 0.0, a_ = 0.0, a2_ = 0.0;
  Eigen::Vector3d w_ = Eigen::Vector3d::Zero(), bias_ = Eigen::Vector3d::Zero();
  int n_ = 0;
  unsigned windows_ = 0;  ///< still windows so far
};

/// Accelerometer bias from the field's vertical component: a bias b tilts the up direction by
/// its part across up over g, and the magnetic heading by tan(dip) times that (0.05 m/s^2:
/// 0.3 deg of tilt, 0.7 deg of heading at 65 deg dip), with a sign that turns with the heading,
/// so it does not cancel round a loop. Seen as a vertical field that changes with the heading
/// (AccBiasLearner::at_step); the estimate is removed from the accelerometer before the heading
/// filter.
struct AccBiasParams {
  bool learn = true;
  double prior_m_s2 = 0.1;         ///< prior std of each bias component
  double step_noise_uT = 0.5;      ///< noise of one step's mean vertical field
  double vertical_walk_uT = 0.05;  ///< drift of the vertical field, uT/sqrt(s)
  double max_turn_rad_s = 0.4;     ///< samples turning faster than this are left out
};

class AccBiasLearner {
 public:
  using Params = AccBiasParams;
  explicit AccBiasLearner(Params params) : params_(params) {}
  /// Adds one sample (sensor frame: gyro, tracked up, hard-iron-corrected field) to the step's
  /// vertical-field sums.
  void add(const Eigen::Vector3d& gyro, const Eigen::Vector3d& up, const Eigen::Vector3d& mag);
  /// At a step: one Kalman update from the step's sums (none: nothing), with the hard-iron
  /// offset in force.
  void at_step(double t_s, const Eigen::Vector3d& mag_offset_uT);
  /// The phone changed how it sits: the vertical field plus hard-iron residual is unknown
  /// again, and samples before `settled_t_s` (the up direction still moving) are left out.
  void forget(double settled_t_s);
  /// Whether samples at t_s may be added (the up direction has settled since forget).
  [[nodiscard]] bool settled(double t_s) const { return t_s > settled_t_s_; }
  /// Sensor frame, m/s^2.
  [[nodiscard]] const Eigen::Vector3d& bias_m_s2() const { return bias_; }

 private:
  [[nodiscard]] Eigen::Matrix4d initial_covariance() const {
    Eigen::Matrix4d p = Eigen::Matrix4d::Identity() * params_.prior_m_s2 * params_.prior_m_s2;
    p(0, 0) = 1e4;
    return p;
  }
  Params params_;
  // State [C (uT), b (m/s^2, sensor frame)], its covariance, the bias removed before the heading
  // filter, and the step's sums.
  Eigen::Vector4d x_ = Eigen::Vector4d::Zero();
  Eigen::Matrix4d p_ = initial_covariance();
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
  double z_sum_ = 0.0, t_s_ = -1.0, settled_t_s_ = 0.0;
  Eigen::Vector3d r_sum_ = Eigen::Vector3d::Zero(), up_sum_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset_uT_ = Eigen::Vector3d::Zero();  ///< hard-iron offset C is for
  int n_ = 0;
};

}  // namespace telltale::fusion
