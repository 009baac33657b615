#pragma once
/// \file
/// Pedestrian dead reckoning with an IMU rigid to the trunk (a belt, the lower back):
/// `fusion_cli pdr --mount trunk`, `wearable_node --mount trunk`.
///
/// Pipeline per sample (TrunkPdr::update): gyro bias learnt while standing and hard-iron offset
/// (SensorPrep) -> the vertical from the production attitude filter (TelltaleAttitudeFilter: a
/// walk's accelerations average out in its frame I, the trunk's sway is a rotation the gyro
/// sees) -> the specific force along it and the yaw (the rate about it less the bias the stands
/// measured, integrated) kept for the last seconds (TrunkMotion) -> steps counted by the
/// gait-phase detector on the body (one per heel strike) -> each step measured from the trunk's
/// rise and fall over it, the inverted pendulum (trunk_motion.hpp), and laid along the trunk's
/// mean yaw over it.
///
/// Why not a step model: the height-and-cadence laws (the seed's line of `--mount body`, the
/// walk ratio of `--mount phone`) are a population's; on the IPOL lower-back walks of four
/// people they laid 26.6 and 22.0 m for walks the foot measures at 20.7 m, and no law of height
/// and cadence follows a walker whose steps are short for their cadence. A trunk sensor sees
/// its own step's height change; the pendulum turns it into the step (docs/pdr.md).
///
/// A walk's first step (after a pause of more than max_step_s) has no step before it to close:
/// it is counted at once and laid with the walk's second step, at that step's length and
/// direction. A step whose excursion is no pendulum's (a jump, the sensor handled) is laid at
/// the walk's last measured length (the walk ratio when there is none).
/// North: the magnetometer gives the sensor's x axis a heading over the samples before the
/// first step is laid; without one, or with x near vertical, the track's north is the direction of
/// the trunk's yaw at the start (the track is right up to one rotation). Frames and units as Pdr:
/// x east, y north (m) from the start; heading clockwise from north. The gyro is required.
///
/// Memory: fixed-size members, no heap in update().

#include <cstddef>

#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/gait_phase_steps.hpp"
#include "telltale/fusion/hard_iron.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/bias_learners.hpp"
#include "telltale/fusion/pdr/cadence.hpp"
#include "telltale/fusion/pdr/sensor_prep.hpp"
#include "telltale/fusion/pdr/trunk_motion.hpp"
#include "telltale/fusion/pdr_output.hpp"

namespace telltale::fusion {

struct TrunkPdrParams {
  double height_m = 1.75;  ///< the walker's: the pendulum's leg is a share of it
  GaitPhaseStepParams steps{.mount = StepMount::kBody};
  TrunkStepParams step;
  /// The production filter, its full scales not known (a belt sensor's are its maker's, the PDR
  /// is not told them; HandheldPdrParams::attitude says why): nothing is taken for clipped.
  TelltaleAttitudeParams attitude = without_ranges({});
  /// Heel strikes further apart than this close no step: the walk paused between them (a slow
  /// walk's step takes 0.7 s).
  double max_step_s = 1.2;
  double min_step_interval_s = Cadence::kMinIntervalS;  ///< shorter is no cadence
  GyroBiasParams gyro_bias;
  bool calibrate_mag = true;  ///< online hard-iron calibration (hard_iron.hpp) before the heading
  HardIronParams hard_iron;
};

class TrunkPdr {
 public:
  using Params = TrunkPdrParams;
  struct Diagnostics : PrepCounts {
    unsigned walks = 0;          ///< walks begun (a first step after a pause)
    unsigned unmeasured = 0;     ///< steps laid at another's length (no pendulum's excursion)
  };
  explicit TrunkPdr(Params params = {});
  /// Feeds one sample; `mag_uT` may be NaN. Returns the state after it (also `output()`); its
  /// `pose` and `switching` keep their defaults. `step`: a step was counted at this sample.
  const PdrOutput& update(const ImuSample& sample, const Eigen::Vector3d& mag_uT);
  [[nodiscard]] const PdrOutput& output() const { return out_; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  [[nodiscard]] const StepDiagnostics& step_diagnostics() const { return steps_.diagnostics(); }
  [[nodiscard]] const Eigen::Vector3d& gyro_bias_rad_s() const {
    return sensors_.gyro_bias_rad_s();
  }

 private:
  void on_step(double t_s);
  void lay(double length_m, double yaw_rad);

  Params params_;
  SensorPrep sensors_;
  TelltaleAttitudeFilter attitude_;
  GaitPhaseStepDetector steps_;
  TrunkMotion motion_;
  Cadence cadence_;
  Diagnostics diag_;
  PdrOutput out_;
  double last_t_s_ = 0.0;
  bool have_t_ = false;
  double yaw_rad_ = 0.0;         ///< the trunk's rotation about up since the start, ccw
  double last_step_t_s_ = -1.0;  ///< the last heel strike (local clock; < 0: none)
  bool first_pending_ = false;   ///< a walk's first step counted, not laid yet
  double last_length_m_ = 0.0;   ///< the walk's last measured step (0: none)
  double orient_sin_ = 0.0, orient_cos_ = 0.0;
  double orient_rad_ = 0.0;
  bool oriented_ = false;
};

}  // namespace telltale::fusion
