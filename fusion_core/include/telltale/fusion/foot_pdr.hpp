#pragma once
/// \file
/// Pedestrian dead reckoning with an IMU on the foot: `fusion_cli pdr --mount foot`,
/// `wearable_node --mount foot`.
///
/// Pipeline per sample (FootPdr::update): gyro bias learnt while standing and hard-iron offset
/// (SensorPrep) -> the foot's own inertial navigation, reset at every stance (FootIns): each
/// stride's displacement is measured, its length and its direction -> steps counted by the
/// gait-phase detector (two per stride of the instrumented foot) -> the track, each stride laid
/// as the INS measured it, turned once onto north by the magnetometer over the stance before
/// the first stride (no magnetometer: the sensor's x axis at the start is taken as north).
///
/// Why an INS and not a step model (seed 004's adaptive detector, a height-and-cadence line and
/// a gyro + magnetometer heading filter, until December 2026): on the IPOL foot recordings
/// (walk 10 m, turn, walk back; 44 files) that pipeline walked 24.4 m and ended 7.7 m (mean)
/// from its start; its heading, the gyro integrated about an up direction pulled toward the
/// accelerometer, drifted tens of degrees per leg, as a foot's swing accelerates at several g.
/// A foot's stance gives what no other mount has, zero velocity and a clean gravity every
/// second: the INS walked 20.67 m and ended 0.62 m (median) from its start (docs/pdr.md). The
/// step count is the gait-phase detector's, the real recordings' best (steps-eval).
///
/// What the phone's pipeline (Pdr, pdr.hpp) has and this one has not, and why: a foot sensor
/// is strapped on, so there is no pose to classify and no switch between poses; the stride is
/// measured, so no step-length model and no height.
/// Frames and units as Pdr: position x east, y north (m) from the start; heading clockwise from
/// north. The gyro is required (an accelerometer alone cannot navigate a foot): samples without
/// one move nothing and count nothing.
///
/// Memory: fixed-size members, no heap in update().

#include <cstddef>

#include "telltale/fusion/gait_phase_steps.hpp"
#include "telltale/fusion/hard_iron.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/bias_learners.hpp"
#include "telltale/fusion/pdr/cadence.hpp"
#include "telltale/fusion/pdr/foot_ins.hpp"
#include "telltale/fusion/pdr/sensor_prep.hpp"
#include "telltale/fusion/pdr_output.hpp"

namespace telltale::fusion {

struct FootPdrParams {
  GaitPhaseStepParams steps;  ///< the step counter (its defaults are the foot's)
  FootInsParams ins;          ///< the stride's navigation
  /// Shorter step intervals are no cadence (Cadence::kMinIntervalS).
  double min_step_interval_s = Cadence::kMinIntervalS;
  GyroBiasParams gyro_bias;
  bool calibrate_mag = true;  ///< online hard-iron calibration (hard_iron.hpp) before the heading
  HardIronParams hard_iron;
};

class FootPdr {
 public:
  using Params = FootPdrParams;
  /// The samples' counts (PrepCounts) and the strides.
  struct Diagnostics : PrepCounts {
    unsigned strides = 0;        ///< strides the INS laid
    unsigned dropped_swings = 0;  ///< swings not laid: longer than a stride's, or a gap in them
  };
  explicit FootPdr(Params params = {});
  /// Feeds one sample; `mag_uT` may be NaN. Returns the state after it (also `output()`); its
  /// `pose` and `switching` keep their defaults (a foot has no pose). `step`: steps were counted
  /// at this sample; the position moves at each stance (a stride laid).
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
  /// A stride measured by the INS: laid along its own direction.
  void lay_stride(const Eigen::Vector2d& d);

  Params params_;
  GaitPhaseStepDetector steps_;
  FootIns ins_;
  Cadence cadence_;  ///< the cadence only: the detector sees every stride, no gap is filled
  SensorPrep sensors_;
  Diagnostics diag_;
  PdrOutput out_;
  double last_t_s_ = 0.0;
  bool have_t_ = false;
  /// North: heading (clockwise from north) = orient_rad_ - (INS angle, counter-clockwise from
  /// its x). Circular sums over the stance before the first stride; fixed from then on.
  double orient_sin_ = 0.0, orient_cos_ = 0.0;
  double orient_rad_ = 0.0;
  bool oriented_ = false;
  double start_yaw_rad_ = 0.0;  ///< the INS's angle of the sensor's x axis at the start
  bool have_start_yaw_ = false;
};

}  // namespace telltale::fusion
