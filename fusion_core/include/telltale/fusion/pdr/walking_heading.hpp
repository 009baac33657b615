#pragma once
/// \file
/// PDR stage: the walking heading. Owns the heading of the walking frame (HeadingFilter: gyro +
/// magnetometer, seed 004) and the correction of the phone's yaw from the walking direction
/// (WalkingDirection, our addition), because both turn the same heading and both must start
/// again when the pose's walking frame changes. Angles: heading clockwise from north, rad.
///
/// Memory: fixed-size Eigen types, no heap.

#include <cmath>

#include "telltale/fusion/angles.hpp"
#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

/// The walking frame's forward (its x axis made horizontal) and left, for an up direction in
/// that frame; false when x is within ~17 deg of vertical (no forward direction).
[[nodiscard]] inline bool horizontal_axes(const Eigen::Vector3d& up, Eigen::Vector3d& fwd,
                                          Eigen::Vector3d& left) {
  fwd = Eigen::Vector3d::UnitX() - up.x() * up;
  if (!(fwd.norm() > 0.3)) return false;
  fwd.normalize();
  left = up.cross(fwd);
  return true;
}

/// Heading of the walking frame's x axis from gyro + magnetometer (seed 004, Fig. 2): a two-state
/// Kalman filter [heading, heading-rate bias]; prediction with the gyro rate about the tracked
/// up direction, update with the tilt-compensated magnetic heading. The up direction is tracked
/// by integrating the gyro and pulling toward the accelerometer (`up_tau_s`), with the
/// centripetal acceleration of turns and a swinging hand's lever-arm acceleration taken out of
/// the accelerometer first. Magnetic north (no declination).
struct HeadingFilterParams {
  double gyro_noise_rad_s = 0.02;  ///< heading-rate noise density, rad/s/sqrt(Hz)
  double bias_walk_rad_s2 = 2e-4;  ///< bias random walk, rad/s^2/sqrt(Hz)
  double mag_noise_deg = 6.0;      ///< magnetic heading noise per sample, deg
  double gate_deg = 40.0;          ///< larger innovations are rejected...
  double reset_after_s = 3.0;      ///< ...unless they persist this long (then reset)
  double up_tau_s = 1.5;           ///< time constant of the pull toward the accelerometer
  /// Lever arm: a phone that swings about a point (the shoulder, the hip) reads that point's
  /// tangential and centripetal acceleration, w' x p + w x (w x p), with p the phone's position
  /// from the point, fixed in the phone. p is fitted by weighted least squares (forgetting
  /// `lever_arm_tau_s`, prior 0 +- `lever_arm_prior_m`, residual noise `lever_arm_noise_m_s2`
  /// per sqrt(Hz)) from the rotation about the horizontal axes only, and taken out of the
  /// accelerometer before the up direction is pulled toward it.
  bool lever_arm = true;
  double lever_arm_tau_s = 10.0;
  double lever_arm_prior_m = 0.5;
  double lever_arm_noise_m_s2 = 3.0;
};
class HeadingFilter {
 public:
  using Params = HeadingFilterParams;
  struct State {
    double heading_rad = 0.0;
    double bias_rad_s = 0.0;
    Eigen::Matrix2d p = Eigen::Matrix2d::Identity();
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< up, walking frame
    double last_t_s = 0.0;
    double rejected_since_s = -1.0;
    bool initialised = false;
  };
  struct Diagnostics {
    unsigned rejected_non_finite = 0;
    unsigned rejected_mag = 0;  ///< magnetometer updates refused by the gate
    unsigned resets = 0;
  };
  explicit HeadingFilter(Params params = {}) : params_(params) {}
  /// Feeds a sample already rotated into the walking frame; mag may be NaN (prediction only).
  void update(double t_s, const Eigen::Vector3d& gyro_rad_s, const Eigen::Vector3d& acc_m_s2,
              const Eigen::Vector3d& mag_uT);
  /// Forgets the heading (next magnetic reading initialises it); keeps the up direction.
  void reset_heading() { state_.initialised = false; }
  /// Walking speed along the frame's x axis, m/s: its centripetal acceleration in turns is taken
  /// out of the accelerometer before the up direction is pulled toward it.
  void set_speed(double v_m_s) { speed_m_s_ = v_m_s; }
  /// The walking frame changed by `r` (v_new = r v_old): re-expresses the up direction and
  /// forgets the heading.
  void change_frame(const Eigen::Matrix3d& r) {
    state_.up = r * state_.up;
    last_acc_ = r * last_acc_;
    last_gyro_ = r * last_gyro_;
    before_gyro_ = r * before_gyro_;
    lever_info_.setZero();  // the phone sits another way in the hand: a new lever arm
    lever_sum_.setZero();
    lever_m_.setZero();
    state_.initialised = false;
  }
  [[nodiscard]] double heading_rad() const { return state_.heading_rad; }
  [[nodiscard]] bool initialised() const { return state_.initialised; }
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  /// Tilt-compensated heading of the x axis from a magnetometer reading and the up direction
  /// (same frame); NaN when x is near vertical or the field is degenerate.
  [[nodiscard]] static double magnetic_heading_rad(const Eigen::Vector3d& mag,
                                                   const Eigen::Vector3d& up);
  /// The same for any unit axis of that frame (its horizontal projection's heading).
  [[nodiscard]] static double magnetic_heading_rad(const Eigen::Vector3d& mag,
                                                   const Eigen::Vector3d& up,
                                                   const Eigen::Vector3d& axis);

 private:
  Params params_;
  State state_;
  Diagnostics diag_;
  bool up_init_ = false;
  double speed_m_s_ = 0.0;
  /// Pulls the up direction toward the previous sample's accelerometer reading (its angular
  /// acceleration needs the rates on both sides of it: `gyro` is the current one).
  void pull_up(double dt, const Eigen::Vector3d& gyro, bool gyro_ok, double t_s);

  Eigen::Vector3d last_gyro_ = Eigen::Vector3d::Zero();  ///< for the trapezoidal rate
  bool last_gyro_ok_ = false;
  Eigen::Vector3d last_acc_ = Eigen::Vector3d::Zero();     ///< the sample the pull is for
  Eigen::Vector3d before_gyro_ = Eigen::Vector3d::Zero();  ///< the rate a sample before that
  bool before_gyro_ok_ = false;
  double before_t_s_ = 0.0;
  Eigen::Matrix3d lever_info_ = Eigen::Matrix3d::Zero();  ///< sum of A^T A dt, forgetting
  Eigen::Vector3d lever_sum_ = Eigen::Vector3d::Zero();   ///< sum of A^T r dt, forgetting
  Eigen::Vector3d lever_m_ = Eigen::Vector3d::Zero();
  double lever_solved_t_s_ = -1e9;
};

// ---------------------------------------------------------------------------------------------
struct WalkingDirectionParams {
  bool correct = true;  ///< correct the phone's yaw from the acceleration pattern
  int steps = 4;        ///< straight steps in a pose before the correction applies
  /// How far a phone is yawed in a hand or pocket, rms (a few degrees). The estimate is shrunk
  /// toward 0 by prior^2 / (prior^2 + s^2), s its standard error from the scatter of the steps'
  /// own angles, so a noisy estimate (a pocket, a swinging arm) corrects little and a clean one
  /// (hand-held, at the ear) almost in full. Only steps walked straight (this and the neighbouring
  /// step within straight_deg of each other) feed it: in a corner the centripetal acceleration
  /// starts and stops within a step and correlates with the vertical's derivative (end-of-pose
  /// error, seeds 100-139: hand-held 1.13 -> 0.47 deg rms, phone call 0.73 -> 0.14).
  double prior_deg = 2.0;
  /// Straight: a step within this of the one before (and, for a pose switch's stand-in heading,
  /// 3 steps within this of their mean).
  double straight_deg = 10.0;
  /// In arm swing the walking direction comes from the step's principal rotation axis, when its
  /// sum of squared rates is this many times the next axis's (a swing, not a turn or a fumble).
  double swing_axis_ratio = 4.0;
};

/// How far the phone is yawed from the walking direction, in the pose's walking frame, learnt
/// over the pose's straight steps. The trunk brakes after heel strike and speeds up before the
/// next one, so the forward acceleration is in quadrature with the vertical one, correlated with
/// its time derivative; sideways sway is at half the step frequency and a tilt error leaks the
/// vertical in phase, both uncorrelated with it. The angle of that correlation in the horizontal
/// plane is the yaw (2 deg rms per pose in the simulator, and what a hand really does). In arm
/// swing the pattern is the arm's: the swing's rotation axis gives the direction instead.
class WalkingDirection {
 public:
  using Params = WalkingDirectionParams;
  explicit WalkingDirection(Params params) : params_(params) {}
  /// One sample (walking frame, gyro bias removed; `up` the heading filter's).
  void add(double t_s, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyro,
           const Eigen::Vector3d& up, bool arm_swing);
  /// A sample that does not feed the estimate (no gyro, a switch, correction off).
  void skip() { have_av_ = false; }
  /// At a step laid with `heading_rad` (uncorrected): books the step that ended, returns the
  /// yaw correction to subtract from the heading (0 until enough straight steps).
  double at_step(double heading_rad, bool arm_swing, const Eigen::Vector3d& up);
  /// The walking frame changed (a new pose): the yaw is unknown again.
  void reset();

 private:
  /// Arm swing: the step's walking direction from its principal rotation axis (step_fwd_/left_).
  void swing_axis_direction(const Eigen::Vector3d& up);
  Params params_;
  // Correlation of the horizontal acceleration with d(vertical)/dt in the pose's walking frame:
  // the sums of straight steps, of the step in progress, and of the last step (kept until the
  // next one shows whether it was straight).
  double yaw_fwd_ = 0.0, yaw_left_ = 0.0;
  /// Arm swing: sum of w w^T (walking frame) over the step in progress.
  Eigen::Matrix3d step_swing_ = Eigen::Matrix3d::Zero();
  double step_fwd_ = 0.0, step_left_ = 0.0, last_fwd_ = 0.0, last_left_ = 0.0;
  double last_raw_heading_rad_ = 0.0;
  bool have_last_raw_ = false, last_straight_ = false;
  // Per straight step: sum and sum of squares of its own yaw angle, and how many.
  double step_yaw_sum_ = 0.0, step_yaw_sq_ = 0.0;
  int straight_steps_ = 0;
  double last_av_ = 0.0, last_av_t_ = 0.0;  ///< the previous sample's vertical acceleration
  bool have_av_ = false;
};

}  // namespace telltale::fusion
