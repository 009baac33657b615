#pragma once
/// \file
/// Pedestrian dead reckoning with an IMU on the foot (seed 004): `fusion_cli pdr --mount foot`,
/// `wearable_node --mount foot`.
///
/// Pipeline per sample (FootPdr::update): gyro bias learnt while standing and hard-iron offset
/// (SensorPrep) -> heading of the sensor's x axis from gyro + magnetometer (the two-state Kalman
/// filter of seed 004, Fig. 2) -> strides of the adaptive detector (seed 004) -> at each stride:
/// the cadence, the heading's circular mean over the stride, two steps of the step-length model
/// laid along it -> position.
///
/// What the phone's pipeline (Pdr, pdr.hpp) has and this one has not, and why: a foot sensor
/// is strapped on, so there is no pose to classify and no switch between poses, and its frame
/// is the walking frame (no rotation into one); the detector sees each stride, so no step is
/// left in a gap; the phone's corrections of the walking direction and of the accelerometer
/// bias read a trunk's or a hand's motion, which a foot does not make.
///
/// Structure: FootPdr orders the work of a sample and of a stride; the stages it calls are the
/// phone's (pdr/: cadence, step_length, walking_heading's HeadingFilter,
/// sensor_prep, track), each with its Params a member of FootPdrParams.
/// Frames and units as Pdr: position x east, y north (m) from the start; heading clockwise from
/// north.
///
/// Memory: fixed-size buffers and Eigen fixed-size types, no heap in update().

#include <cstddef>

#include "telltale/fusion/hard_iron.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/bias_learners.hpp"
#include "telltale/fusion/pdr/cadence.hpp"
#include "telltale/fusion/pdr/sensor_prep.hpp"
#include "telltale/fusion/pdr/step_length.hpp"
#include "telltale/fusion/pdr/track.hpp"
#include "telltale/fusion/pdr/walking_heading.hpp"
#include "telltale/fusion/pdr_output.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::fusion {

struct FootPdrParams {
  AdaptiveStepParams steps;  ///< the stride detector (its defaults are the foot's)
  /// Shorter step intervals are no cadence (Cadence::kMinIntervalS).
  double min_step_interval_s = Cadence::kMinIntervalS;
  GyroBiasParams gyro_bias;
  /// Height and personal factor; the model's hand-held row and its `scale` are the foot's (it
  /// has no pose): the seed's line, fitted to our gait simulator.
  StepLengthParams step_length;
  TrackParams track;
  HeadingFilterParams heading;
  bool calibrate_mag = true;  ///< online hard-iron calibration (hard_iron.hpp) before the heading
  HardIronParams hard_iron;
};

class FootPdr {
 public:
  using Params = FootPdrParams;
  /// The IMU gate's counts (gate_imu_sample; the gyro may be missing) and the stands.
  struct Diagnostics : ImuGateCounts {
    unsigned still_windows = 0;  ///< still windows that set the gyro bias
  };
  explicit FootPdr(Params params = {});
  FootPdr(Params params, const StepLengthModel& lengths);
  /// Feeds one sample; `mag_uT` may be NaN. Returns the state after it (also `output()`); its
  /// `pose` and `switching` keep their defaults (a foot has no pose).
  const PdrOutput& update(const ImuSample& sample, const Eigen::Vector3d& mag_uT);
  [[nodiscard]] const PdrOutput& output() const { return out_; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  [[nodiscard]] const StepDiagnostics& step_diagnostics() const { return steps_.diagnostics(); }
  [[nodiscard]] const HardIronCalibrator& mag_calibration() const {
    return sensors_.mag_calibration();
  }
  /// Gyro bias learnt while still (sensor frame, rad/s; subtracted from every sample).
  [[nodiscard]] const Eigen::Vector3d& gyro_bias_rad_s() const {
    return sensors_.gyro_bias_rad_s();
  }

 private:
  /// A stride ended at t_s: counts its two steps and lays them.
  void on_stride(double t_s);

  Params params_;
  StepLength step_length_;
  AdaptiveStepDetector steps_;
  Cadence cadence_;  ///< the cadence only: the detector sees every stride, no gap is filled
  HeadingFilter heading_;
  SensorPrep sensors_;
  Track track_;
  Diagnostics diag_;
  PdrOutput out_;
  double sum_sin_ = 0.0, sum_cos_ = 0.0;  ///< heading over the current stride (circular mean)
};

}  // namespace telltale::fusion
