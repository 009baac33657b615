#pragma once
/// \file
/// MEMS error model of the paper's sensors: gyro L3G4200D (ST, DocID 17116), accelerometer
/// LSM303DLH (ST, DocID 16941). Every figure below is a datasheet figure unless marked.
///
/// measured = saturate(quantise(M (1 + S) true + bias + bias_walk + noise))
///   M: misalignment / cross-axis (small rotation-like matrix), S: scale factor error (diagonal),
///   bias: per run (drawn once), bias_walk: bias instability (random walk), noise: white,
///   standard deviation = noise density * sqrt(rate / 2) (bandwidth = Nyquist; the sensors' own
///   digital low-pass and group delay are not modelled), quantisation: one LSB, saturation: the
///   full scale of the register.

#include <Eigen/Core>
#include <cstdint>
#include <random>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion::sim {

struct ImuErrorParams {
  // L3G4200D at FS = 250 dps.
  double gyro_bias_max_rad_s =
      10.0 * M_PI / 180.0;  ///< zero-rate level +-10 dps (Table 4), uniform
  double gyro_bias_walk_rad_s_sqrt_s = 0.005 * M_PI / 180.0;  ///< assumed: 0.03 dps/degC drift
                                                              ///< (Table 4) over a few degC/hour
  double gyro_noise_density_rad_s_sqrt_hz = 0.03 * M_PI / 180.0;  ///< 0.03 dps/sqrt(Hz) (Table 4)
  /// Scale and cross-axis after the instrument's one-off rate-table calibration (assumed
  /// residual; the datasheet's +-2 % sensitivity change spans -40..85 degC, i.e. ~0.3 % over a
  /// +-15 degC season). uncalibrated() has the raw +-2 % and 1 % cross-axis (typical MEMS; the
  /// L3G4200D datasheet gives none).
  double gyro_scale_max = 0.003;
  double gyro_misalign_max_rad = 0.002;
  double gyro_lsb_rad_s = 8.75e-3 * M_PI / 180.0;                 ///< 8.75 mdps/digit (Table 4)
  double gyro_full_scale_rad_s = 32767 * 8.75e-3 * M_PI / 180.0;  ///< 16-bit register, 286.7 dps

  // LSM303DLH at FS = 2 g, after the one-off six-position calibration of the instrument
  // (datasheet: zero-g offset +-20 mg typ, sensitivity 1 mg/digit +-10 %): what remains is the
  // calibration residual below (assumed: 3 mg offset, 0.3 % scale, 0.1 deg cross-axis). With the
  // raw +-20 mg offset no filter can do better than atan(0.02) = 1.15 deg, see the closing note.
  double acc_bias_max_m_s2 = 0.003 * kStandardGravity_m_s2;
  double acc_bias_walk_m_s2_sqrt_s = 1e-5;  ///< 0.1 mg/degC (LA_TCOff) over a few degC/hour
  double acc_noise_density_m_s2_sqrt_hz =
      220e-6 * kStandardGravity_m_s2;  ///< 220 ug/sqrt(Hz) (assumed:
                                       ///< LSM303DLHC figure, DLH gives none)
  double acc_scale_max = 0.003;
  double acc_misalign_max_rad = 0.0017;
  double acc_lsb_m_s2 = 1e-3 * kStandardGravity_m_s2;          ///< 1 mg/digit (12 bit at 2 g)
  double acc_full_scale_m_s2 = 2.048 * kStandardGravity_m_s2;  ///< 2048 digits

  /// The same sensors without the accelerometer calibration (datasheet figures as they are).
  [[nodiscard]] static ImuErrorParams uncalibrated();
  /// No errors at all (for invariants).
  [[nodiscard]] static ImuErrorParams ideal();
};

/// One instance per simulated run: draws the per-run errors from the seed at construction.
class ImuErrorModel {
 public:
  ImuErrorModel(const ImuErrorParams& params, std::uint64_t seed);
  /// Applies the errors to the true rate and specific force of a sample taken dt_s after the last.
  void apply(double dt_s, double rate_hz, const Eigen::Vector3d& gyro_true_rad_s,
             const Eigen::Vector3d& acc_true_m_s2, Eigen::Vector3d& gyro_rad_s,
             Eigen::Vector3d& acc_m_s2);
  [[nodiscard]] const Eigen::Vector3d& gyro_bias_rad_s() const { return gyro_bias_; }

 private:
  ImuErrorParams p_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Matrix3d gyro_m_;
  Eigen::Matrix3d acc_m_;
  Eigen::Vector3d gyro_bias_;
  Eigen::Vector3d acc_bias_;
};

}  // namespace telltale::fusion::sim
