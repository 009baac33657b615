// The paper's yardsticks: gyro-only, accelerometer-only, fixed-weight average, constant Kalman.
#include "telltale/fusion/attitude_baselines.hpp"

#include <cmath>

namespace telltale::fusion {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

/// Shared gate of the integrating baselines; on the first sample initialises heel/pitch from the
/// accelerometer (dt = 0).
bool accept(const ImuSample& s, EulerTiltState& st, BaselineDiagnostics& d, double& dt) {
  // The yardsticks are the paper's: they integrate over gaps and saturation as it did (the gate
  // only counts them).
  const ImuGateResult g = gate_imu_sample(s, ImuGateParams{}, st.initialised, st.last_t_s, d);
  dt = g.dt_s;
  if (g.verdict == ImuVerdict::kFirst) tilt_from_accel(s.acc_body_m_s2, st.heel_rad, st.pitch_rad);
  return g.verdict != ImuVerdict::kReject;
}

AttitudeOutput euler_output(const EulerTiltState& st, double acc_weight) {
  AttitudeOutput o;
  o.heel_rad = st.heel_rad;
  o.pitch_rad = st.pitch_rad;
  o.heel_rate_rad_s = st.heel_rate_rad_s;
  o.pitch_rate_rad_s = st.pitch_rate_rad_s;
  o.acc_weight = acc_weight;
  o.quality = acc_weight;
  o.valid = st.initialised;
  return o;
}

}  // namespace

void GyroAttitudeFilter::update(const ImuSample& s) {
  double dt = 0.0;
  if (!accept(s, state_, diag_, dt)) return;
  euler_rates_from_body(s.gyro_body_rad_s, state_.heel_rad, state_.pitch_rad,
                        state_.heel_rate_rad_s, state_.pitch_rate_rad_s);
  state_.heel_rad += state_.heel_rate_rad_s * dt;
  state_.pitch_rad += state_.pitch_rate_rad_s * dt;
}
AttitudeOutput GyroAttitudeFilter::output() const { return euler_output(state_, 0.0); }

void AccelAttitudeFilter::update(const ImuSample& s) {
  double dt = 0.0;
  if (!accept(s, state_, diag_, dt)) return;
  const double heel_prev = state_.heel_rad;
  const double pitch_prev = state_.pitch_rad;
  tilt_from_accel(s.acc_body_m_s2, state_.heel_rad, state_.pitch_rad);
  if (dt > 0.0) {
    state_.heel_rate_rad_s = (state_.heel_rad - heel_prev) / dt;
    state_.pitch_rate_rad_s = (state_.pitch_rad - pitch_prev) / dt;
  }
}
AttitudeOutput AccelAttitudeFilter::output() const { return euler_output(state_, 1.0); }

void AverageAttitudeFilter::update(const ImuSample& s) {
  double dt = 0.0;
  if (!accept(s, state_, diag_, dt)) return;
  double heel_acc = 0.0;
  double pitch_acc = 0.0;
  tilt_from_accel(s.acc_body_m_s2, heel_acc, pitch_acc);
  euler_rates_from_body(s.gyro_body_rad_s, state_.heel_rad, state_.pitch_rad,
                        state_.heel_rate_rad_s, state_.pitch_rate_rad_s);
  weight_ = dt / (params_.tau_s + dt);
  const double heel_pred = state_.heel_rad + state_.heel_rate_rad_s * dt;
  const double pitch_pred = state_.pitch_rad + state_.pitch_rate_rad_s * dt;
  state_.heel_rad = heel_pred + weight_ * std::remainder(heel_acc - heel_pred, 2.0 * M_PI);
  state_.pitch_rad = pitch_pred + weight_ * (pitch_acc - pitch_pred);
}
AttitudeOutput AverageAttitudeFilter::output() const { return euler_output(state_, weight_); }

void ConstKalmanAttitudeFilter::step_axis(Axis& a, double rate_deg_s, double acc_deg,
                                          double dt) const {
  // Predict: angle += (rate - bias) dt; P = F P F^T + Q dt with F = [[1, -dt], [0, 1]].
  a.angle_deg += (rate_deg_s - a.bias_deg_s) * dt;
  a.p00 += dt * (dt * a.p11 - a.p01 - a.p10 + params_.q_angle_deg2_s);
  a.p01 -= dt * a.p11;
  a.p10 -= dt * a.p11;
  a.p11 += params_.q_bias_deg2_s * dt;
  // Update with the accelerometer tilt (H = [1, 0]).
  const double s = a.p00 + params_.r_deg2;
  const double k0 = a.p00 / s;
  const double k1 = a.p10 / s;
  const double innovation = acc_deg - a.angle_deg;
  a.angle_deg += k0 * innovation;
  a.bias_deg_s += k1 * innovation;
  const double p00 = a.p00;
  const double p01 = a.p01;
  a.p00 -= k0 * p00;
  a.p01 -= k0 * p01;
  a.p10 -= k1 * p00;
  a.p11 -= k1 * p01;
}

void ConstKalmanAttitudeFilter::update(const ImuSample& s) {
  const ImuGateResult g =
      gate_imu_sample(s, ImuGateParams{}, state_.initialised, state_.last_t_s, diag_);
  if (g.verdict == ImuVerdict::kReject) return;
  const double dt = g.dt_s;
  double heel_acc = 0.0;
  double pitch_acc = 0.0;
  tilt_from_accel(s.acc_body_m_s2, heel_acc, pitch_acc);
  if (g.verdict == ImuVerdict::kFirst) {
    state_.heel.angle_deg = heel_acc * kRadToDeg;
    state_.pitch.angle_deg = pitch_acc * kRadToDeg;
    return;
  }
  euler_rates_from_body(s.gyro_body_rad_s, state_.heel.angle_deg / kRadToDeg,
                        state_.pitch.angle_deg / kRadToDeg, state_.heel_rate_rad_s,
                        state_.pitch_rate_rad_s);
  step_axis(state_.heel, state_.heel_rate_rad_s * kRadToDeg, heel_acc * kRadToDeg, dt);
  step_axis(state_.pitch, state_.pitch_rate_rad_s * kRadToDeg, pitch_acc * kRadToDeg, dt);
}

AttitudeOutput ConstKalmanAttitudeFilter::output() const {
  const double k = state_.heel.p00 / (state_.heel.p00 + params_.r_deg2);
  AttitudeOutput o;
  o.heel_rad = state_.heel.angle_deg / kRadToDeg;
  o.pitch_rad = state_.pitch.angle_deg / kRadToDeg;
  o.heel_rate_rad_s = state_.heel_rate_rad_s - state_.heel.bias_deg_s / kRadToDeg;
  o.pitch_rate_rad_s = state_.pitch_rate_rad_s - state_.pitch.bias_deg_s / kRadToDeg;
  o.acc_weight = k;
  o.quality = k;
  o.valid = state_.initialised;
  return o;
}

}  // namespace telltale::fusion
