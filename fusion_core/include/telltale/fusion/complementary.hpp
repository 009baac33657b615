#pragma once
/// \file
/// A first-order complementary filter for heel and pitch: the walking skeleton's filter.
///
/// Gyro rates are mapped to Euler-angle rates (ZYX), integrated, and pulled toward the
/// accelerometer's tilt with time constant `tau_s`. It has no defence against non-inertial motion;
/// the production filters live beside it.

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

/// Settings of ComplementaryFilter (outside the class so it can be a default argument).
struct ComplementaryParams {
  double tau_s = 1.0;  ///< time constant of the pull toward the accelerometer tilt, s
};

class ComplementaryFilter {
 public:
  using Params = ComplementaryParams;
  struct State {
    double heel_rad = 0.0;   ///< roll of the ZYX sequence, + = starboard down
    double pitch_rad = 0.0;  ///< pitch of the ZYX sequence, + = bow up
    double last_t_s = 0.0;
    bool initialised = false;
  };
  struct Diagnostics {
    unsigned rejected_non_finite = 0;  ///< samples ignored for NaN/Inf
    unsigned rejected_time = 0;        ///< samples ignored because time did not advance
  };

  explicit ComplementaryFilter(Params params = {}) : params_(params) {}

  /// Feeds one sample. Samples with NaN/Inf or non-increasing time are ignored (counted).
  void update(const ImuSample& sample);

  [[nodiscard]] double heel_rad() const { return state_.heel_rad; }
  [[nodiscard]] double pitch_rad() const { return state_.pitch_rad; }
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }

 private:
  Params params_;
  State state_;
  Diagnostics diag_;
};

/// Heel and pitch (rad) of the gravity direction seen by an accelerometer at rest (SPEC section 1).
void tilt_from_accel(const Eigen::Vector3d& acc_body_m_s2, double& heel_rad, double& pitch_rad);

}  // namespace telltale::fusion
