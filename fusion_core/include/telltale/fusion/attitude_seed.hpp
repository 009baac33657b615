#pragma once
/// \file
/// The paper's filter exactly as published (seed 000/001, SPEC section 2, eqs 1-5, table 1):
/// per axis (heel, pitch) a 3-state Kalman filter X = [phi_g, phi_a, dphi_g] whose observation
/// weights the gyro angle by 1-c and the accelerometer angle by c, with c chosen by the
/// non-inertial operator da = | |a| - g_c | / g_c (eq 2) and r_k growing by dr while c = 0 (eq 4).
///
/// Units: the paper's Q, R and P0 are numbers without units; they only make sense for angles in
/// degrees (r_a = 0.005 deg^2 ~ the LSM303DLH tilt noise), so the Kalman algebra runs in degrees.
/// Inputs and outputs are SI (rad, rad/s) like every filter.
///
/// Points the paper leaves open and how they are resolved (see attitude_seed.cpp for the why):
///  1. The gyro increment enters as the state dphi_g: before each prediction dphi_g(k-1|k-1) is
///     replaced by the measured increment (heel or pitch rate) * dt, so eq 1's prediction adds it
///     to phi_g. The gyro's measured angle in Y(k) is phi_o(k-1) + rate*dt: the last optimal
///     estimate is the gyro's prior (the paper: "the optimal estimate serves as the gyro's prior
///     angle, correcting its drift in real time").
///  2. Body rates -> heel/pitch rates: full ZYX Euler kinematics (euler_rates_from_body) at the
///     last optimal heel and pitch, so the two per-axis filters are coupled only through it.
///  3. dr (eq 4) is a parameter; default 0.005 deg^2 per sample (see SeedAttitudeParams::dr).
///  4. dt: the actual time step of each sample (the paper samples at a fixed 40 ms).
///  5. X0 = 0 and P0 = I as in table 1: the output starts at 0 and converges to the tilt.

#include <Eigen/Core>

#include "telltale/fusion/attitude.hpp"

namespace telltale::fusion {

/// Settings of SeedAttitudeFilter: table 1 of the paper, angles in degrees.
struct SeedAttitudeParams {
  double q_a_deg2 = 0.02;   ///< process noise of phi_a (table 1)
  double q_g_deg2 = 0.02;   ///< process noise of dphi_g (table 1)
  double r_a_deg2 = 0.005;  ///< measurement noise while c != 0 (table 1, R)
  /// Growth of r_k per sample while c = 0 (eq 4), "found by experiment" in the paper. Default:
  /// r_a per sample, i.e. each gyro-only step is assumed to add as much variance as one
  /// accelerometer reading. Only the covariance depends on it: while c = 0 the innovation is zero.
  double dr_deg2 = 0.005;
  double g_c_m_s2 = kStandardGravity_m_s2;  ///< g_c of the operator da
  double c_max = 0.7;                       ///< eq 2, da < 0.005
  double da_low = 0.005;                    ///< eq 2 thresholds
  double da_high = 0.03;
  double c_slope = 240.0;  ///< eq 2: c = 1 / (slope * da)^2
};

class SeedAttitudeFilter final : public AttitudeFilter {
 public:
  using Params = SeedAttitudeParams;
  struct Axis {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();      ///< [phi_g, phi_a, dphi_g], deg (X0 = 0)
    Eigen::Matrix3d p = Eigen::Matrix3d::Identity();  ///< P0 = I
    double r_deg2 = 0.005;                            ///< r_k (eq 4)
    double out_deg = 0.0;                             ///< phi_o, the published angle
  };
  struct State {
    Axis heel;
    Axis pitch;
    double last_t_s = 0.0;
    double c = 0.0;  ///< weight of the accelerometer in the last update (eq 2)
    double heel_rate_rad_s = 0.0;
    double pitch_rate_rad_s = 0.0;
    bool started = false;
  };
  struct Diagnostics : ImuGateCounts {};

  explicit SeedAttitudeFilter(Params params = {});
  void update(const ImuSample& sample) override;
  [[nodiscard]] AttitudeOutput output() const override;
  [[nodiscard]] const State& state() const { return state_; }
  void set_state(const State& s) { state_ = s; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }

  /// Eq 2: accelerometer weight c from da.
  [[nodiscard]] static double weight_from_da(double da, const Params& p);

 private:
  void step_axis(Axis& a, double increment_deg, double acc_deg) const;
  Params params_;
  State state_;
  Diagnostics diag_;
};

}  // namespace telltale::fusion
