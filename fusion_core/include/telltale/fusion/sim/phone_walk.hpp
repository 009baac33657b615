#pragma once
/// \file
/// A phone walk as the IPIN 2023 logs showed them (the real logs may not be copied into the
/// project): the phone handled at random first (rotations of 2-7 rad/s, the hand's jerks), then
/// held in front of a walker standing still (hand tremor, a slow yaw wander), then walked with
/// the phone held in front (the screen tilted 50 deg toward the face, like the logs), with
/// pauses. HandheldPdr's simulator (handheld_pdr_test, `fusion_cli steps-eval --tables ipin`,
/// beside the real walks); the four carrying poses and their switches are gait_sim's.
///
/// Physics, in the world frame (ENU): the phone's orientation is sampled and the gyro is the
/// rotation between consecutive samples (plus a constant bias and white noise); the specific
/// force is gravity plus the motion's acceleration, rotated into the phone. A step is the trunk's
/// bounce seen by a hand held in front: vertically gait_sim's walker (`walking_trunk_up`: a walk
/// from standing begins with the push of its first toe-off and ends at its closing heel strike,
/// whose loading settles into the stand or pause after it; 1.6-4.0 m/s^2 at 1.75 m and 1.6-2.0
/// steps/s, the walk-ratio law lengthening the step with the cadence), forward
/// 1.2 m/s^2 at the step's rate and a lateral sway at the stride's, the phone pitching 2 deg
/// with each step, the horizontal motions building up over the first step and dying out over
/// the last; a corner turns the walker over its first 1.5 s (walking) or 2 s (standing). Every
/// phase carries the hand's 8 Hz tremor (0.3 deg) and a +-1.5 deg yaw wander over 20 s. The
/// field: Earth's (0, 20, -44) uT ENU, 0.4 uT of noise.
///
/// Deterministic on every platform (sim::Rng).

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion::sim {

enum class PhonePhase { kHandling, kStanding, kWalking, kPause };

struct PhoneSegment {
  PhonePhase phase;
  double duration_s;
  double turn_deg = 0.0;  ///< heading change over the segment (walking: a corner at its start)
};

struct PhoneWalkParams {
  double rate_hz = 50.0;
  double step_hz = 1.8;
  double step_length_m = 0.7;  ///< the walker's step (truth)
  double height_m = 1.75;      ///< the walker's (the trunk's bounce: sim::walking_trunk_up)
  Eigen::Vector3d gyro_bias_rad_s = Eigen::Vector3d::Zero();
};

struct PhoneWalkTruth {
  double distance_m = 0.0;
  double steps = 0.0;
  double x_m = 0.0, y_m = 0.0;                   ///< where the walk ends (it starts at 0, 0)
  double heading_rad = 0.0;                      ///< walking direction at the end
  std::vector<std::pair<double, double>> quiet;  ///< [t0, t1] of handling, standing, pauses
  double walk_start_s = 0.0;                     ///< the first walking segment's start
  /// The walk's end as its walker would mark it (the IPIN logs' "here" pressed at the last
  /// landmark): 0.5 s after the last walking segment, whose closing heel strike's loading is
  /// over within a quarter step of it.
  double walk_end_s = 0.0;
};

struct PhoneWalk {
  std::vector<ImuSample> samples;
  std::vector<Eigen::Vector3d> mag_uT;  ///< one per sample
  PhoneWalkTruth truth;
};

[[nodiscard]] PhoneWalk simulate_phone_walk(const std::vector<PhoneSegment>& plan,
                                            const PhoneWalkParams& params, std::uint64_t seed);

/// Phone -> world (ENU) for a walker heading `heading` (clockwise from north), the phone held in
/// front: x right, y up the screen (forward and up), z out of the screen (toward the face), the
/// screen tilted 50 deg toward the face plus `extra_pitch` (rad).
[[nodiscard]] Eigen::Matrix3d phone_held_in_front(double heading, double extra_pitch = 0.0);

/// An IPIN-like walk for `seed`: 20-40 s of handling, 20-40 s standing, then a closed rectangle
/// (sides 8-25 m) walked clockwise or counter-clockwise at 1.6-2.0 steps/s, with a 3-10 s pause
/// at two of its corners. `params` receives the cadence, the gyro bias (N(0, 0.003) rad/s per
/// axis) and the step length the walk-ratio law gives at `height_m` (the test of the pipeline,
/// not of the law).
[[nodiscard]] std::vector<PhoneSegment> ipin_like_plan(std::uint64_t seed, double height_m,
                                                       PhoneWalkParams& params);

}  // namespace telltale::fusion::sim
