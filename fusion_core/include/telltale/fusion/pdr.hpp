#pragma once
/// \file
/// Pedestrian dead reckoning with a phone carried in four poses (seed 003, SPEC section 5). A
/// foot-mounted IMU has its own pipeline (FootPdr, foot_pdr.hpp, which says what it leaves out
/// and why); the two share the stages in pdr/ they both need.
///
/// Pipeline per sample (Pdr::update): step detection (peak-valley of seed 003) -> pose features
/// over a sliding window -> BP pose classifier (3 inputs, 4 outputs) at every step -> heading of
/// the walking direction from gyro + magnetometer (a two-state Kalman filter, seed 004 Fig. 2)
/// in the walking frame given by the pose rotation matrices of seed 003 (eqs. (14)-(15)) ->
/// pose-switch detection by cross-correlation of consecutive step waveforms, with the mean
/// heading of the 3 straight steps before the switch used during it -> step length
/// L = a h + b f + c per pose (eq. (13)) -> position (eq. (11)).
///
/// Our additions (each measured on closed loops, `fusion_cli steps-eval --tables pdr`): online
/// gyro-aided hard-iron calibration of the magnetometer (hard_iron.hpp); a switch's steps, and
/// the one or two before it was detected, re-laid with the heading each really had (at every
/// step while it lasts, with the pose the classifier sees, and once the new pose is confirmed);
/// steps the detector left in a gap of several intervals counted (the cadence the median of the
/// last measured intervals, the gap laid along the heading it had, a gap with a still phone a
/// stop); after a stand, a walk's first event held until a second confirms it; between poses
/// with one walking frame a faster pose change; the phone's yaw
/// from the walking direction removed using the step's acceleration pattern (shrunk toward 0
/// while the pose is young, from straight steps only); the centripetal acceleration of turns
/// taken out before the up direction follows the accelerometer; steps already walked re-laid when
/// the hard-iron offset or the pose's yaw estimate improves (TrackParams::revise); the gyro
/// bias learnt while standing still; in arm swing the walking direction from the arm's swing axis
/// (WalkingDirectionParams::swing_axis_ratio); the accelerometer bias learnt from the constancy of
/// the field's vertical component (AccBiasParams); while the phone swings, the steps counted from
/// its turns (SwingStepDetector, steps.hpp), whatever the pose; the swinging hand's pendulum
/// acceleration taken out before the up direction follows the accelerometer
/// (HeadingFilterParams::lever_arm); a personal step-length factor from one calibration walk of
/// known length (StepLengthParams::scale).
///
/// Frames: the phone's sensor axes are whatever the phone has; the walking frame is x forward, y
/// left, z up with `v_walking = M_pose v_sensor` (M = I for hand-held and arm swing). Position is
/// x east, y north (m) from the start; heading clockwise from north.
///
/// Structure: Pdr orders the work of a sample and of a step; each stage it calls owns its state
/// and its Params (a member of PdrParams), one file pair each in pdr/ (docs/pdr.md lists them):
/// sensor_prep (shared with FootPdr), phone_steps, step_clock, recent_samples, recent_headings,
/// pose_classifier, pose_switch, step_length, walking_heading, bias_learners, track.
///
/// Memory: fixed-size buffers and Eigen fixed-size types, no heap in update().

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "telltale/fusion/hard_iron.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr/bias_learners.hpp"
#include "telltale/fusion/pdr/phone_steps.hpp"
#include "telltale/fusion/pdr/pose_classifier.hpp"
#include "telltale/fusion/pdr/pose_switch.hpp"
#include "telltale/fusion/pdr/recent_headings.hpp"
#include "telltale/fusion/pdr/recent_samples.hpp"
#include "telltale/fusion/pdr/sensor_prep.hpp"
#include "telltale/fusion/pdr/step_clock.hpp"
#include "telltale/fusion/pdr/step_length.hpp"
#include "telltale/fusion/pdr/track.hpp"
#include "telltale/fusion/pdr/walking_heading.hpp"
#include "telltale/fusion/pdr_output.hpp"
#include "telltale/fusion/phone_pose.hpp"
#include "telltale/fusion/steps.hpp"

namespace telltale::fusion {

/// The model file (fusion_core/data/pose_bp.txt): network + step-length coefficients, text.
[[nodiscard]] std::string format_pdr_model(const PoseNetwork& net, const StepLengthModel& len);
/// Parses it; false on malformed text (the outputs are then untouched).
[[nodiscard]] bool parse_pdr_model(std::string_view text, PoseNetwork& net, StepLengthModel& len);
/// The model shipped with the library (pose_bp.txt compiled in); untrained if it was missing.
[[nodiscard]] const PoseNetwork& builtin_pose_network();
[[nodiscard]] const StepLengthModel& builtin_step_length_model();

// ---------------------------------------------------------------------------------------------
struct PdrParams {
  /// A stand: the phone still (|f| within gyro_bias.acc_std_m_s2, rotating at less than
  /// stand_gyro_rad_s rms) for stand_still_s. A gap that held one has no missed steps
  /// and a walk after one must confirm its start (StepClock).
  /// A walker who stops and then moves the phone (puts it away, lifts it to the ear) makes
  /// events after a gap that held no steps (2-3 steps too many on 10 of 400 loops). 0: off.
  double stand_still_s = 0.6;
  /// A stand's rotation rate, rms: a still hand (0.05 rad/s), not a swinging arm (1-3 rad/s).
  double stand_gyro_rad_s = 0.2;
  StepClockParams step_clock;
  GyroBiasParams gyro_bias;
  AccBiasParams acc_bias;
  PoseClassifierParams pose;
  PoseSwitchParams pose_switch;
  StepLengthParams step_length;
  TrackParams track;
  HeadingFilterParams heading;
  WalkingDirectionParams walking_direction;
  bool calibrate_mag = true;  ///< online hard-iron calibration (hard_iron.hpp) before the heading
  HardIronParams hard_iron;
};

class Pdr {
 public:
  using Params = PdrParams;
  /// The samples' counts (PrepCounts) and the PDR's own.
  struct Diagnostics : PrepCounts {
    unsigned switches = 0;           ///< pose switches detected by cross-correlation
    unsigned pose_changes = 0;       ///< classified pose changes applied
    unsigned replaced_headings = 0;  ///< steps that used the pre-switch heading
    unsigned filled_steps = 0;       ///< steps added for gaps the detector left
  };
  /// `net` and `lengths` default to the built-in model; they are copied.
  explicit Pdr(Params params = {}, const PoseNetwork& net = builtin_pose_network(),
               const StepLengthModel& lengths = builtin_step_length_model());
  /// Feeds one sample; `mag_uT` may be NaN. Returns the state after it (also `output()`).
  const PdrOutput& update(const ImuSample& sample, const Eigen::Vector3d& mag_uT);
  [[nodiscard]] const PdrOutput& output() const { return out_; }
  [[nodiscard]] const Diagnostics& diagnostics() const { return diag_; }
  [[nodiscard]] const StepDiagnostics& step_diagnostics() const;
  [[nodiscard]] const HardIronCalibrator& mag_calibration() const {
    return sensors_.mag_calibration();
  }
  /// Gyro bias learnt while still (sensor frame, rad/s; subtracted from every sample).
  [[nodiscard]] const Eigen::Vector3d& gyro_bias_rad_s() const {
    return sensors_.gyro_bias_rad_s();
  }
  /// Accelerometer bias learnt from the vertical field (sensor frame, m/s^2; removed from the
  /// accelerometer before the heading filter).
  [[nodiscard]] const Eigen::Vector3d& acc_bias_m_s2() const { return acc_bias_.bias_m_s2(); }
  /// Step frequencies seen at each step so far are not stored (no heap); for calibration, collect
  /// `output().step_hz` at every step in the caller.

 private:
  void on_step(const ClockStep& step);
  /// Counts the step and the ones the clock counted with it; the cadence it learnt.
  void count_steps(const ClockStep& step);
  /// Compares the step [t_prev, t_s]'s waveform with the same foot's last: a pose switch
  /// begins (its steps gathered; `ups_before` each foot's up before this step) or settles.
  void detect_switch(double t_prev, double t_s, const std::array<Eigen::Vector3d, 2>& ups_before);
  /// The pose classifier's vote at this step, and a new walking frame if it confirms one.
  void classify_pose(double t_s);
  /// The step's walking direction (rad): the heading over the step, yaw-corrected.
  double walked_heading();
  /// Lays the step (`missed` more with it) walked along `walked_rad`: its length, the heading a
  /// switch or a gap gives it, the track, and what a later re-laying needs.
  void lay_step(double t_s, double t_prev, int missed, double walked_rad,
                const std::array<Eigen::Vector3d, 2>& ups_before);
  /// Re-lays the switch's steps for the phone now in `pose`; `heading_after` is the heading of
  /// the step after them (none: the switch goes on).
  void relay_switch_steps(std::optional<double> heading_after, PhonePose pose);
  /// Keeps a laid step for a switch's re-laying (in the switch, or among the last steps before
  /// one) and re-lays the switch's steps when it ends or the classifier sees a pose.
  void book_laid_step(const SwitchStep& laid, double heading,
                      const std::array<Eigen::Vector3d, 2>& ups_before);
  /// A new pose or a switch: the walking direction and the pose's track revision start again.
  void reset_walking_direction();
  /// The phone changed how it sits: the accelerometer bias's vertical field is unknown again.
  void forget_vertical_field();
  /// Turns the steps laid in this pose so far with a new yaw correction `corr` (rad).
  void revise_pose_yaw(double corr);

  Params params_;
  StepLength step_length_;
  PhoneSteps phone_steps_;
  StepClock clock_;
  PoseClassifier pose_;
  RecentSamples recent_;
  RecentHeadings headings_;  ///< the heading a gap's steps are laid along
  HeadingFilter heading_;
  WalkingDirection walking_;
  SensorPrep sensors_;
  AccBiasLearner acc_bias_;
  Track track_;
  Diagnostics diag_;
  PdrOutput out_;
  PoseSwitch switch_;
  SwitchRelay relay_;  ///< the steps of a pose switch, and the last ones before one
  /// Over the current step, sums of unit (east, north) vectors of the horizontal sensor x and
  /// -z axes: the walking direction if the pose's forward axis is that one.
  std::array<Eigen::Vector2d, 2> axis_sum_{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  double sum_sin_ = 0.0, sum_cos_ = 0.0;  ///< heading over the current step (circular mean)
};

}  // namespace telltale::fusion
