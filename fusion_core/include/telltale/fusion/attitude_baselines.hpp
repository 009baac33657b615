#pragma once
/// \file
/// The yardsticks the paper compares with (SPEC section 2): gyro-only integration,
/// accelerometer-only tilt, a fixed-weight average of the two, and a constant-parameter Kalman
/// filter. Same contract as every AttitudeFilter: SI units, strictly increasing time, NaN/Inf and
/// non-increasing time rejected and counted, no heap in update.

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {

/// Counters shared by the baselines.
struct BaselineDiagnostics : ImuGateCounts {};

/// Heel/pitch state shared by the integrating baselines.
struct EulerTiltState {
  double heel_rad = 0.0;
  double pitch_rad = 0.0;
  double heel_rate_rad_s = 0.0;
  double pitch_rate_rad_s = 0.0;
  double last_t_s = 0.0;
  bool initialised = false;
};

/// What the Euler-angle baselines share: their state, counters and accessors.
class EulerBaseline : public AttitudeFilter {
 public:
  using State = EulerTiltState;
  using Diagnostics = BaselineDiagnostics;
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }

 protected:
  State state_;
  Diagnostics diag_;
};

/// `gyro`: Euler-rate integration of the gyro from the first sample's accelerometer tilt.
/// Never corrected afterwards: it shows the drift every fusion must remove.
class GyroAttitudeFilter final : public EulerBaseline {
 public:
  void update(const ImuSample& sample) override;
  [[nodiscard]] AttitudeOutput output() const override;
};

/// `accel`: tilt of the measured specific force, every sample on its own (tilt_from_accel).
class AccelAttitudeFilter final : public EulerBaseline {
 public:
  void update(const ImuSample& sample) override;
  [[nodiscard]] AttitudeOutput output() const override;
};

/// Settings of AverageAttitudeFilter.
struct AverageAttitudeParams {
  /// Time constant of the pull toward the accelerometer tilt, s. The per-sample weight of the
  /// accelerometer is w = dt / (tau_s + dt): fixed for uniform sampling (0.038 at 25 Hz).
  double tau_s = 1.0;
};

/// `average`: the fixed-weight average of gyro and accelerometer angles the paper cites ([5]),
/// angle = (1 - w) (angle + rate dt) + w tilt_acc. This is the walking skeleton's
/// complementary filter; it has no defence against non-inertial motion.
class AverageAttitudeFilter final : public EulerBaseline {
 public:
  using Params = AverageAttitudeParams;
  explicit AverageAttitudeFilter(Params params = {}) : params_(params) {}
  void update(const ImuSample& sample) override;
  [[nodiscard]] AttitudeOutput output() const override;

 private:
  Params params_;
  double weight_ = 0.0;
};

/// Settings of ConstKalmanAttitudeFilter (the widespread angle + gyro-bias Kalman filter per axis,
/// cf. the paper's reference [6]; values in degrees and seconds, constant).
struct ConstKalmanAttitudeParams {
  double q_angle_deg2_s = 0.001;  ///< angle process noise per second
  double q_bias_deg2_s = 0.003;   ///< bias random walk per second ((deg/s)^2 / s)
  double r_deg2 = 0.03;           ///< accelerometer tilt noise
};

/// `kalman-const`: per axis, state [angle, gyro bias], prediction by the Euler rate, update by the
/// accelerometer tilt with constant Q and R (no non-inertial test).
class ConstKalmanAttitudeFilter final : public AttitudeFilter {
 public:
  using Params = ConstKalmanAttitudeParams;
  struct Axis {
    double angle_deg = 0.0;
    double bias_deg_s = 0.0;
    double p00 = 0.0, p01 = 0.0, p10 = 0.0, p11 = 0.0;
  };
  struct State {
    Axis heel;
    Axis pitch;
    double heel_rate_rad_s = 0.0;
    double pitch_rate_rad_s = 0.0;
    double last_t_s = 0.0;
    bool initialised = false;
  };
  using Diagnostics = BaselineDiagnostics;
  explicit ConstKalmanAttitudeFilter(Params params = {}) : params_(params) {}
  void update(const ImuSample& sample) override;
  [[nodiscard]] AttitudeOutput output() const override;
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }

 private:
  void step_axis(Axis& a, double rate_deg_s, double acc_deg, double dt) const;
  Params params_;
  State state_;
  Diagnostics diag_;
};

}  // namespace telltale::fusion
