#pragma once
/// \file
/// PDR stage: the samples a PDR works on, for the phone's pipeline (Pdr), the foot's (FootPdr)
/// and the trunk's (TrunkPdr) alike. Each raw sample passes the IMU gate (gate_imu_sample; the gyro
/// may be missing), the gyro bias learnt while standing (GyroBiasLearner) is taken off the rate,
/// and the magnetometer's hard-iron offset (HardIronCalibrator), learnt from the bias-corrected
/// rate, off the field. The offset rotates with the sensor, so its heading error changes with the
/// walking direction and does not cancel around a loop: it goes before any heading.
///
/// Memory: fixed-size members, no heap.

#include <Eigen/Core>

#include "telltale/fusion/hard_iron.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/bias_learners.hpp"
#include "telltale/fusion/pdr_output.hpp"

namespace telltale::fusion {

/// What every PDR counts of its samples: the IMU gate's counts (the gyro may be missing) and the
/// stands that set the gyro bias. Each PDR's Diagnostics extends it.
struct PrepCounts : ImuGateCounts {
  unsigned still_windows = 0;  ///< still windows that set the gyro bias
};

class SensorPrep {
 public:
  SensorPrep(const GyroBiasParams& gyro_bias, bool calibrate_mag, const HardIronParams& hard_iron)
      : gyro_bias_(gyro_bias), mag_cal_(hard_iron), calibrate_mag_(calibrate_mag) {}
  /// One raw sample and its field (NaN: none). false: the gate rejected it (counted in
  /// `counts`), `s` and `mag` untouched. true: `s` on the stages' LocalClock (the same steps
  /// whatever the time origin) with the bias off its rate (when it has one), `mag` with the
  /// offset off (when it is finite and calibration is on).
  bool prepare(const ImuSample& raw, const Eigen::Vector3d& mag_uT, ImuGateCounts& counts,
               ImuSample& s, Eigen::Vector3d& mag);
  /// A sample's arrival at a PDR, the same for all three (Pdr, FootPdr, TrunkPdr): `out.step`
  /// cleared, then prepare(); if it passed, the stands counted into `counts` and `out.t_s` set to
  /// the caller's clock (the stages run on `s.t_s`, the local one).
  bool arrive(const ImuSample& raw, const Eigen::Vector3d& mag_uT, PrepCounts& counts,
              PdrOutput& out, ImuSample& s, Eigen::Vector3d& mag);
  /// Gyro bias learnt while still (sensor frame, rad/s).
  [[nodiscard]] const Eigen::Vector3d& gyro_bias_rad_s() const { return gyro_bias_.bias_rad_s(); }
  /// Still windows that set the gyro bias so far.
  [[nodiscard]] unsigned still_windows() const { return gyro_bias_.windows(); }
  [[nodiscard]] const HardIronCalibrator& mag_calibration() const { return mag_cal_; }
  /// The last accepted sample's time, local (0 before the first).
  [[nodiscard]] double last_t_s() const { return last_t_s_; }

 private:
  GyroBiasLearner gyro_bias_;
  HardIronCalibrator mag_cal_;
  bool calibrate_mag_;
  LocalClock clock_;
  bool have_t_ = false;
  double last_t_s_ = 0.0;
};

}  // namespace telltale::fusion
