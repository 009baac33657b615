#pragma once
/// \file
/// Telltale's production heel/pitch filter: the default of `fusion_cli attitude` and of the boat
/// node. It keeps the paper's idea (trust the accelerometer only while the motion is inertial) and
/// adds what is needed to hold +-1 deg on a boat:
///   - full 3-D kinematics: the gyro is integrated as a quaternion (no per-axis Euler integration),
///     each sample as the mean rate over the interval that ends at it (decimation filter);
///   - the accelerometer is rotated into a quasi-inertial frame (the gyro-integrated frame I) and
///     low-passed THERE (two first-order stages, tau_acc_s each): in an earth-fixed frame the
///     mean of any bounded motion's acceleration is dv/T -> 0, so waves, a pendulum's swing, a
///     turntable's centripetal acceleration (a vector that rotates with the yaw) average out while
///     gravity stays put (the idea of Laidig & Seel's VQF, 2023);
///   - a non-inertial test that sees horizontal accelerations (|a_I - lowpass(a_I)|, not |a| ~ g),
///     with a peak hold: while it is high the accelerometer's correction is scaled down
///     (weight -> w_min) and the gyro carries the attitude;
///   - a turn test (centripetal acceleration across the heading, toward the turn): during a tack
///     the low-pass is not fed either, so the tack's acceleration is not remembered as a tilt;
///   - gyro bias estimated online: fast at rest (rest detection), slowly in motion from the
///     corrections the accelerometer has to make;
///   - non-uniform time steps, dropped samples (gaps up to max_gap_s are integrated, longer gaps
///     only counted and the quality lowered), saturated gyro/accelerometer samples, NaN/Inf.
///
/// Call order: update() once per sample, time strictly increasing; read output() afterwards.
/// Cannot observe: the gyro bias about the vertical (heading drift; irrelevant to heel/pitch),
/// an accelerometer offset (it becomes a tilt error of offset/g rad), a linear acceleration that
/// is sustained in one earth direction for longer than ~tau_acc_s while looking inertial.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {

/// Settings of TelltaleAttitudeFilter.
struct TelltaleAttitudeParams {
  double g_m_s2 = kStandardGravity_m_s2;
  /// Time constant of each of the two low-pass stages on the accelerometer in the inertial frame.
  double tau_acc_s = 3.5;
  /// Same, while the sensor is at rest (nothing to reject; converge fast).
  double tau_acc_rest_s = 0.2;
  /// Non-inertial test: |a_I - lowpass| (m/s^2) below low -> weight 1, above high -> w_min.
  double nonin_low_m_s2 = 0.4;
  double nonin_high_m_s2 = 2.0;
  double nonin_lp_tau_s = 1.0;   ///< the test compares a_I with its low-pass of this time constant
  double nonin_release_s = 1.0;  ///< decay time of the peak hold of the non-inertial measure
  /// Turn test: a vehicle turning while it moves accelerates toward the inside of the turn.
  /// Measure = low-pass(lateral horizontal acceleration * clamp(yaw rate / turn_rate_rad_s, +-1)),
  /// with a peak hold; between turn_low and turn_high the low-pass input and the weight fade
  /// to lp_turn_min and w_min.
  double turn_rate_rad_s = 0.1;
  double turn_tau_s = 0.5;
  double turn_release_s = 2.0;
  double turn_low_m_s2 = 0.4;
  double turn_high_m_s2 = 1.5;
  double lp_turn_min = 0.1;
  double w_min = 0.05;  ///< floor of the accelerometer weight (keeps long-run correction)
  /// Rest detection (gyro bias learning): deviations below these for rest_min_s.
  double rest_gyro_rad_s = 0.035;  ///< 2 deg/s
  double rest_acc_m_s2 = 0.4;
  double rest_min_s = 1.0;
  double rest_bias_match_rad_s = 0.0026;  ///< 0.15 deg/s: rest = the gyro reads the known bias
  double rest_bias_tau_s = 5.0;  ///< bias refinement at rest after the first (which sets it)
  double rest_lp_tau_s = 0.5;    ///< low-pass of gyro/acc for the rest test and the bias
  /// Bias learning in motion: time constant of the integral of the accelerometer corrections.
  double bias_motion_tau_s = 60.0;
  double max_bias_rad_s = 0.35;  ///< |bias| clamp (20 deg/s, twice the L3G4200D zero-rate spread)
  double gyro_range_rad_s = 250.0 * M_PI / 180.0;       ///< full scale (L3G4200D default 250 dps)
  double acc_range_m_s2 = 2.0 * kStandardGravity_m_s2;  ///< full scale (LSM303DLH default 2 g)
  double saturation_fraction = 0.98;                    ///< |reading| >= this * range -> saturated
  double max_gap_s = 1.0;                               ///< longer gaps are not integrated
};

class TelltaleAttitudeFilter final : public AttitudeFilter {
 public:
  using Params = TelltaleAttitudeParams;
  struct State {
    Eigen::Quaterniond q_gyro = Eigen::Quaterniond::Identity();  ///< body -> inertial frame I
    Eigen::Vector3d up_i = Eigen::Vector3d::UnitZ();  ///< the earth's vertical in frame I (unit)
    Eigen::Vector3d bias_rad_s = Eigen::Vector3d::Zero();  ///< gyro bias, body
    Eigen::Vector3d acc_lp1_i = Eigen::Vector3d::Zero();   ///< first low-pass stage, frame I
    Eigen::Vector3d acc_lp2_i = Eigen::Vector3d::Zero();   ///< second stage, frame I
    Eigen::Vector3d acc_fast_i = Eigen::Vector3d::Zero();  ///< 1 s low-pass for the gate, frame I
    Eigen::Vector3d gyro_rest_lp_rad_s = Eigen::Vector3d::Zero();
    Eigen::Vector3d acc_rest_lp_m_s2 = Eigen::Vector3d::Zero();
    double rest_time_s = 0.0;
    bool bias_known = false;  ///< a rest has been seen
    double nonin_hold_m_s2 = 0.0;
    double turn_m_s2 = 0.0;
    double turn_hold_m_s2 = 0.0;
    double weight = 0.0;
    double tilt_var_rad2 = 0.0;  ///< rough tilt variance behind `quality`
    double last_t_s = 0.0;
    /// The output's inputs (output() is computed from them on demand): the corrected vertical
    /// seen in the body (unit) and the bias-corrected body rate of the last update.
    Eigen::Vector3d up_body = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d rate_rad_s = Eigen::Vector3d::Zero();
    bool initialised = false;
    bool updated = false;  ///< an update followed the first sample
  };
  struct Diagnostics {
    unsigned rejected_non_finite = 0;
    unsigned rejected_time = 0;
    unsigned gaps = 0;            ///< dt > max_gap_s (not integrated)
    unsigned gyro_saturated = 0;  ///< samples with a gyro axis at full scale
    unsigned acc_saturated = 0;   ///< samples with an accelerometer axis at full scale
    unsigned rest_samples = 0;    ///< samples spent learning the bias at rest
  };

  explicit TelltaleAttitudeFilter(Params params = {});
  void update(const ImuSample& sample) override;
  /// Computed on demand from the state (a read costs ~155 instructions; update() does not pay it).
  [[nodiscard]] AttitudeOutput output() const override;
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  [[nodiscard]] const Params& params() const { return params_; }

 private:
  void initialise(const ImuSample& s);
  /// 1 / time constant (and 1 / threshold span) of every Params entry used per sample, so the
  /// update multiplies instead of dividing; the saturation thresholds; 1 + low / span of the two
  /// weight ramps (w = one - measure / span); the Newton step 1 / |l| ~ newton_a - newton_b |l|^2
  /// from 1 / g.
  struct Rates {
    double rest_lp, rest_bias, nonin_lp, nonin_release, turn_lp, turn_release, acc, acc_rest,
        bias_motion, nonin_range, turn_range, turn_rate, gyro_sat_rad_s, acc_sat_m_s2, inv_g,
        inv_g2, nonin_one, turn_one, newton_a, newton_b;
  };
  Params params_;
  Rates rates_{};
  State state_;
  Diagnostics diag_;
};

}  // namespace telltale::fusion
