// The paper's time-varying weighted Kalman filter (seed 000/001), as published.
#include "telltale/fusion/attitude_seed.hpp"

#include <cmath>

namespace telltale::fusion {
namespace {
constexpr double kRadToDeg = 180.0 / M_PI;
}

SeedAttitudeFilter::SeedAttitudeFilter(Params params) : params_(params) {
  state_.heel.r_deg2 = params_.r_a_deg2;
  state_.pitch.r_deg2 = params_.r_a_deg2;
}

double SeedAttitudeFilter::weight_from_da(double da, const Params& p) {
  // Eq 2. At da = 0.005 the curve gives 1/1.44 = 0.69, so it joins c_max = 0.7 almost smoothly.
  if (da < p.da_low) return p.c_max;
  if (da <= p.da_high) {
    const double s = p.c_slope * da;
    return 1.0 / (s * s);
  }
  return 0.0;
}

void SeedAttitudeFilter::step_axis(Axis& a, double increment_deg, double acc_deg) const {
  const double c = state_.c;
  // Open point 1: the increment state is the measured one; the filter keeps its own phi_g (the
  // prior of the optimal estimate enters through Y below). Overwriting phi_g(k-1|k-1) with phi_o
  // too was tried: the state then no longer matches P and the filter diverges at 100 Hz.
  a.x(2) = increment_deg;
  // Eq 1, prediction with A = [[1,0,1],[0,1,0],[0,0,1]].
  Eigen::Matrix3d A;
  A << 1, 0, 1, 0, 1, 0, 0, 0, 1;
  const Eigen::Vector3d x_pred = A * a.x;
  // Eq 3 with Q = diag(0, q_a, q_g) (table 1).
  Eigen::Matrix3d p_pred = A * a.p * A.transpose();
  p_pred(1, 1) += params_.q_a_deg2;
  p_pred(2, 2) += params_.q_g_deg2;
  // Eq 4: r_k.
  a.r_deg2 = (c != 0.0) ? params_.r_a_deg2 : a.r_deg2 + params_.dr_deg2;
  // Eq 1 observation: Y = (1-c) phi_g,meas + c phi_a,meas, H = (1-c, c, 0), where the gyro's
  // measured angle uses the last optimal estimate as its prior ("the optimal estimate serves as
  // the gyro's prior angle, correcting its drift in real time"): phi_g,meas = phi_o(k-1) + dphi.
  const Eigen::RowVector3d H(1.0 - c, c, 0.0);
  const double y = (1.0 - c) * (a.out_deg + increment_deg) + c * acc_deg;
  // Eq 3 gain, eq 5 update.
  const double s = H * p_pred * H.transpose() + a.r_deg2;
  const Eigen::Vector3d K = p_pred * H.transpose() / s;
  a.x = x_pred + K * (y - H * x_pred);
  a.p = (Eigen::Matrix3d::Identity() - K * H) * p_pred;
  // The published angle: phi_o = (1-c) phi_g(k|k) + c phi_a(k|k).
  a.out_deg = (1.0 - c) * a.x(0) + c * a.x(1);
}

void SeedAttitudeFilter::update(const ImuSample& s) {
  // The first sample has no increment (X0 = 0 stands for "no history"): dt = 0.
  const ImuGateResult g =
      gate_imu_sample(s, ImuGateParams{}, state_.started, state_.last_t_s, diag_);
  if (g.verdict == ImuVerdict::kReject) return;
  const double dt = g.dt_s;
  // Eq 2: da = | |a| - g_c | / g_c from the measured specific force.
  const double da = std::abs(s.acc_body_m_s2.norm() - params_.g_c_m_s2) / params_.g_c_m_s2;
  state_.c = weight_from_da(da, params_);
  double heel_acc = 0.0;
  double pitch_acc = 0.0;
  tilt_from_accel(s.acc_body_m_s2, heel_acc, pitch_acc);
  // Open point 2: body rates -> Euler rates at the last optimal angles.
  euler_rates_from_body(s.gyro_body_rad_s, state_.heel.out_deg / kRadToDeg,
                        state_.pitch.out_deg / kRadToDeg, state_.heel_rate_rad_s,
                        state_.pitch_rate_rad_s);
  step_axis(state_.heel, state_.heel_rate_rad_s * dt * kRadToDeg, heel_acc * kRadToDeg);
  step_axis(state_.pitch, state_.pitch_rate_rad_s * dt * kRadToDeg, pitch_acc * kRadToDeg);
}

AttitudeOutput SeedAttitudeFilter::output() const {
  AttitudeOutput o;
  o.heel_rad = state_.heel.out_deg / kRadToDeg;
  o.pitch_rad = state_.pitch.out_deg / kRadToDeg;
  o.heel_rate_rad_s = state_.heel_rate_rad_s;
  o.pitch_rate_rad_s = state_.pitch_rate_rad_s;
  o.acc_weight = state_.c;
  o.quality = state_.c / params_.c_max;
  o.valid = state_.started;
  return o;
}

}  // namespace telltale::fusion
