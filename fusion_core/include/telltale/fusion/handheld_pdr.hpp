#pragma once
/// \file
/// Pedestrian dead reckoning for a phone held in front of the walker (the reading / texting pose
/// of real phone walks), in stages, one per file (handheld/), each with its Params and State:
///
///   1. tilt: the up direction in the phone's frame from TelltaleAttitudeFilter
///      (attitude_telltale.hpp);
///   2. StandBiasLearner (handheld/stand_bias.hpp): the gyro bias from the walker standing still
///      (a hand, not a table);
///   3. WalkStepDetector (handheld/walk_steps.hpp): steps from the vertical specific force,
///      counted only once the motion is a walk (a regular cadence with the phone's tilt steady),
///      so handling the phone, standing and pausing make no steps and no distance;
///   4. step length from height and cadence by the walk ratio (walk_ratio_step_length_m,
///      handheld/walk_ratio.hpp);
///   5. WalkingHeading (handheld/walking_yaw.hpp): the direction of the phone's forward axis
///      about the vertical, carried by the bias-corrected gyro and held level by the up
///      direction (ForwardAxisYaw, forward_axis_yaw.hpp). A phone held in front keeps a
///      fixed yaw to the walking direction, so turns of the phone are turns of the walk; the
///      magnetometer (unreliable indoors) only orients the track once, at the start, and never
///      steers it;
///   6. the track (TrackRelay, handheld/track_relay.hpp): each step laid at the heading the
///      phone had at that step, with the best gyro bias known then, the steps before it laid
///      again with it (relay_track: the whole walk with its last, once it is over).
///
/// Steps are reported with the time of the step itself (they are confirmed up to a few steps
/// later): HandheldPdr::update returns the steps it confirmed at this sample.
///
/// Frames: the phone's own axes (any right-handed frame; Android: x right, y up the screen, z out
/// of the screen); the accelerometer reads specific force (+g up at rest). Track: x east, y north
/// (magnetic), heading clockwise from north. No heap in update().

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <span>

#include "telltale/fusion/attitude_telltale.hpp"
#include "telltale/fusion/handheld/stand_bias.hpp"
#include "telltale/fusion/handheld/track_relay.hpp"
#include "telltale/fusion/handheld/walk_ratio.hpp"
#include "telltale/fusion/handheld/walk_steps.hpp"
#include "telltale/fusion/handheld/walking_yaw.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr.hpp"

namespace telltale::fusion {

struct HandheldPdrParams {
  double height_m = 1.75;
  double step_scale = 1.0;  ///< personal factor on the walk-ratio step length (1: population)
  WalkRatioParams length;
  /// The boat's filter: with no GNSS speed its start's line fit (a hull's in a seaway) never
  /// runs, and the phone starts from the growing mean. Without the accelerometer's skew as a
  /// state: that models one part's two filter chains, a few ms apart and fixed, where a phone's
  /// sensors are stamped by its OS (the IPIN files' gyro interpolated onto the accelerometer's
  /// stamps). On the eight IPIN walks the state ran to its 20 ms clamp through the handling on
  /// two walks and to -12.5 ms on a third, and route 21 walk 1 lost two steps (length ratio
  /// 0.902 -> 0.880, outside 10 %): nothing there says what the skew is. Nor the full scales:
  /// a phone's are its maker's (Android runs its MEMS parts at up to 2000 deg/s and 4-16 g) and
  /// the PDR is not told them; the IPIN phones read up to 923 deg/s and 2.9 g in their handling,
  /// which the boat instrument's 250 deg/s and 2 g took for clipped readings (the walks'
  /// closures within 0.08 points either way). Not known: nothing is taken for clipped.
  TelltaleAttitudeParams attitude = [] {
    TelltaleAttitudeParams p = without_ranges({});
    p.acc_skew_sigma_init_s = 0.0;
    return p;
  }();
  StandBiasParams bias;
  WalkStepParams steps;
  /// The magnetometer orients the track once, from its mean over the stand before the first
  /// walk (heading of the phone's forward axis: the horizontal part of y - z, the top of the
  /// screen for a phone held flat or tilted toward the face). false: the track starts north.
  bool orient_with_mag = true;
};

struct HandheldStep {
  double t_s = 0.0;
  /// Laid with the bias known at the step (TrackRelay; relay_track: with the walk's last).
  double x_m = 0.0, y_m = 0.0, heading_deg = 0.0, length_m = 0.0, step_hz = 0.0;
  double distance_m = 0.0;
  std::size_t steps = 0;
  /// As the gyro laid it, for laying it again (TrackRelay's record, track_relay.hpp; its time on
  /// the stages' clock).
  GyroLaidStep gyro;
};

/// A walk's steps (in order, every step since the start) laid again with one gyro bias for the
/// whole walk: the one the walk ended with (track_relay.hpp says why). Each step's heading moves
/// by the yaw the biases it was laid with and this one part by up to it; the first step keeps
/// its heading (the track's orientation, from the magnetometer), the lengths are kept. For a walk
/// reviewed after it ends (fusion_cli pdr, steps-eval): live, a step can only be laid with the
/// stands before it (TrackRelay, the wearable node's track).
void relay_track(std::span<HandheldStep> steps, const Eigen::Vector3d& bias_rad_s);

class HandheldPdr {
 public:
  using Params = HandheldPdrParams;
  explicit HandheldPdr(Params p = {});
  /// Feeds one sample (mag may be NaN). Returns how many steps were laid at it: steps()[0..n),
  /// each with its own time (at or before this sample's, on the caller's clock; the stages run
  /// on a LocalClock).
  int update(const ImuSample& s, const Eigen::Vector3d& mag_uT);
  [[nodiscard]] const std::array<HandheldStep, WalkStepDetector::kMaxHeld>& steps() const {
    return laid_;
  }
  [[nodiscard]] const HandheldStep& last() const { return last_; }
  [[nodiscard]] bool walking() const { return detector_.walking(); }
  [[nodiscard]] bool standing() const { return bias_.quiet(); }
  [[nodiscard]] const Eigen::Vector3d& gyro_bias_rad_s() const { return bias_.bias_rad_s(); }
  [[nodiscard]] double heading_rad() const { return heading_.heading_rad(); }
  [[nodiscard]] const Eigen::Vector3d& up() const { return att_.state().up_body; }
  /// What the IMU gate (gate_imu_sample) rejected: NaN/Inf anywhere, time not advancing.
  [[nodiscard]] const ImuGateCounts& diagnostics() const { return diag_; }

 private:
  Params params_;
  ImuGateCounts diag_;
  LocalClock clock_;
  bool have_t_ = false;
  double last_t_s_ = 0.0;
  TelltaleAttitudeFilter att_;
  StandBiasLearner bias_;
  WalkStepDetector detector_;
  WalkingHeading heading_;
  TrackRelay relay_;
  std::array<HandheldStep, WalkStepDetector::kMaxHeld> laid_{};
  HandheldStep last_;
  Eigen::Vector2d mag_offset_sum_ = Eigen::Vector2d::Zero();  ///< unit vectors of the offset
  int mag_n_ = 0;
  bool oriented_ = false;
  std::array<double, 4> intervals_{};
  int interval_n_ = 0;
};

}  // namespace telltale::fusion
