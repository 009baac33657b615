#pragma once
/// \file
/// Pedestrian dead reckoning for a phone held in front of the walker (the reading / texting pose
/// of real phone walks), in stages, each with its Params and State:
///
///   1. tilt: the up direction in the phone's frame from TelltaleAttitudeFilter (attitude_telltale);
///   2. StandBiasLearner: the gyro bias from the walker standing still (a hand, not a table);
///   3. WalkStepDetector: steps from the vertical specific force, counted only once the motion
///      is a walk (a regular cadence with the phone's tilt steady), so handling the phone,
///      standing and pausing make no steps and no distance;
///   4. step length from height and cadence by the walk ratio (walk_ratio_step_length_m);
///   5. WalkingHeading: the phone's yaw about the vertical, the bias-corrected gyro integrated
///      about the up direction. A phone held in front keeps a fixed yaw to the walking direction,
///      so turns of the phone are turns of the walk; the magnetometer (unreliable indoors) only
///      orients the track once, at the start, and never steers it;
///   6. the track: each step laid at the heading the phone had at that step.
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
#include "telltale/fusion/handheld/walk_ratio.hpp"
#include "telltale/fusion/handheld/walk_steps.hpp"
#include "telltale/fusion/handheld/walking_yaw.hpp"
#include "telltale/fusion/imu_sample.hpp"
#include "telltale/fusion/pdr.hpp"

namespace telltale::fusion {

// ---------------------------------------------------------------------------------------------
/// Gyro bias from standing. A hand holding a phone is never still (tremor: 0.05-0.25 rad/s rms,
/// acceleration 0.05-0.4 m/s^2 rms), so no single second gives the bias; but the phone's
/// orientation stays put while the walker stands, so over a stand of T seconds the mean rate is
/// the bias plus (net rotation) / T: a few degrees over a 20 s stand, under 0.005 rad/s. Each
/// stand is weighted by T^2 (its error goes as 1/T) and the current stand counts as it grows.
struct StandBiasParams {
  double window_s = 1.0;          ///< quiet test window
  /// Quiet: |f| rms about its mean and the rate rms below these over the window. A walking step
  /// moves |f| by 1-3 m/s^2 (heel strike), handling turns the phone at 2-7 rad/s; a hand
  /// holding it stays below both.
  double max_acc_sd_m_s2 = 0.4;
  double max_gyro_rms_rad_s = 0.4;
  double min_stand_s = 3.0;       ///< shorter quiet stretches are pauses of a moving hand
  /// A stand's mean rate above this is a slow turn on the spot, not a bias (phone gyros are
  /// factory- and OS-calibrated to well under 1 deg/s).
  double max_bias_rad_s = 0.03;
  /// The bias about the vertical from the magnetometer during stands. A standing walker stays
  /// on one spot, so the field there is one fixed vector even when indoor iron bends it; the
  /// phone's yaw change over the stand is then the change of the field's horizontal direction
  /// seen from the phone (tilt-compensated), and d = (gyro yaw) - (magnetic yaw) grows as
  /// bias * t whatever the hand's yaw wander does (the wander is in both and cancels). Its slope
  /// (least squares over the stand's samples) is the bias about the stand's vertical; the other
  /// two components stay the gyro learner's. Never used while walking: the walker then moves
  /// through the field's disturbances, and a direction change of the field is not a turn.
  /// Stands are combined by the inverse variance of their slopes (see StandBiasLearner::State).
  bool mag_yaw_bias = true;
  /// The magnetic yaw's noise goes as 1/|B horizontal|: below this (a field nearly along the
  /// vertical, or a dead sensor) a stand says nothing. Earth's horizontal field is 10-40 uT.
  double min_mag_horizontal_uT = 5.0;
  /// |B| is the same at one spot whatever the phone's orientation; a stand whose |B| varies by
  /// more than this (rms) had the phone moved past a magnetic source (or the walker stepped),
  /// so its field was not one fixed vector: no estimate from it.
  double max_mag_norm_sd_uT = 2.0;
};
class StandBiasLearner {
 public:
  using Params = StandBiasParams;
  struct State {
    // Window sums.
    double win_t0_s = 0.0;
    int win_n = 0;
    double win_a = 0.0, win_a2 = 0.0, win_w2 = 0.0;
    Eigen::Vector3d win_w = Eigen::Vector3d::Zero();
    // The stand in progress (consecutive quiet windows) and the stands before it.
    double stand_s = 0.0;
    Eigen::Vector3d stand_w_dt = Eigen::Vector3d::Zero();  ///< integral of the rate
    double done_weight = 0.0;                              ///< sum of T^2
    Eigen::Vector3d done_sum = Eigen::Vector3d::Zero();    ///< sum of T^2 * mean
    Eigen::Vector3d bias = Eigen::Vector3d::Zero();
    // Magnetic yaw: psi_g = integral of w . up (raw gyro), psi_m = the phone's yaw from the
    // field (unwrapped, counter-clockwise), d = psi_g - psi_m. Least-squares sums of d against t
    // (t from the first sample) over the window and over the stand, d^2 for the residual about
    // the fitted line (the slope's variance); |B| sums for its rms.
    struct YawSums {
      double n = 0.0, t = 0.0, d = 0.0, tt = 0.0, td = 0.0, dd = 0.0, b = 0.0, bb = 0.0,
             bh = 0.0;
      Eigen::Vector3d up = Eigen::Vector3d::Zero();
      void add(const YawSums& o) {
        n += o.n; t += o.t; d += o.d; tt += o.tt; td += o.td; dd += o.dd;
        b += o.b; bb += o.bb; bh += o.bh; up += o.up;
      }
    };
    double psi_g = 0.0, psi_m = 0.0, psi_m_raw = 0.0;
    bool have_psi_m = false;
    double t_origin_s = 0.0;  ///< t origin of the sums (the first sample)
    YawSums win_yaw, stand_yaw;
    bool win_yaw_ok = true;    ///< every sample of the window had a usable field
    bool stand_yaw_ok = true;  ///< and every window of the stand
    /// The stands with a magnetic slope, each weighted by the inverse variance of its slope,
    /// T^3 / (rms residual of d about its line)^2 (mag_slope_weight in the source).
    double mag_weight = 0.0;  ///< sum of the weights
    double mag_sum = 0.0;     ///< sum of weight * slope (rad/s about that stand's up)
    Eigen::Vector3d mag_up = Eigen::Vector3d::Zero();  ///< sum of weight * the stand's mean up
    double vertical_bias = 0.0;  ///< the magnetic estimate about mag_up (valid if mag_weight > 0)
    bool quiet = false;  ///< the last full window was quiet
    bool have_bias = false;
    double last_t_s = 0.0;
    bool started = false;
  };
  explicit StandBiasLearner(Params p = {}) : params_(p) {}
  /// One sample with the up direction (unit, phone frame) and the field (NaN: none).
  void update(const ImuSample& s, const Eigen::Vector3d& up, const Eigen::Vector3d& mag_uT);
  /// The bias: the gyro learner's, its component along the stands' vertical replaced by the
  /// magnetic estimate once a stand gave one.
  [[nodiscard]] const Eigen::Vector3d& bias_rad_s() const { return state_.bias; }
  /// The magnetic estimate of the bias about the vertical (rad/s) and whether there is one.
  [[nodiscard]] bool has_mag_vertical_bias() const { return state_.mag_weight > 0.0; }
  [[nodiscard]] double mag_vertical_bias_rad_s() const { return state_.vertical_bias; }
  [[nodiscard]] bool quiet() const { return state_.quiet; }
  [[nodiscard]] const State& state() const { return state_; }

 private:
  void close_stand();
  void clear_window();
  void update_estimate();
  /// The stand's magnetic slope into the sums (if it qualifies).
  void close_mag_stand();
  Params params_;
  State state_;
};

struct HandheldPdrParams {
  double height_m = 1.75;
  double step_scale = 1.0;  ///< personal factor on the walk-ratio step length (1: population)
  WalkRatioParams length;
  /// The boat's filter as it is: with no GNSS speed its start's line fit (a hull's in a seaway)
  /// never runs, and the phone starts from the growing mean.
  TelltaleAttitudeParams attitude;
  StandBiasParams bias;
  WalkStepParams steps;
  /// The magnetometer orients the track once, from its mean over the stand before the first
  /// walk (heading of the phone's forward axis: the horizontal part of y - z, the top of the
  /// screen for a phone held flat or tilted toward the face). false: the track starts north.
  bool orient_with_mag = true;
};

struct HandheldStep {
  double t_s = 0.0;
  double x_m = 0.0, y_m = 0.0, heading_deg = 0.0, length_m = 0.0, step_hz = 0.0;
  double distance_m = 0.0;
  std::size_t steps = 0;
  /// At the step, for relay_track: the yaw the gyro bias in use had taken off since the start
  /// (rad) and the integral of the up direction (phone frame, s).
  double bias_yaw_rad = 0.0;
  Eigen::Vector3d up_s = Eigen::Vector3d::Zero();
};

/// A walk's steps (in order, every step since the start) laid again with one gyro bias for the
/// whole walk: the one the walk ended with. The bias is a constant of the gyro over a walk
/// (it drifts with temperature over tens of minutes), and each stand measures it; live, a step
/// can only be laid with the stands before it, so a walk whose first stand measured it badly
/// (a walker turning slowly on the spot, a magnetic estimate refused) walks its first legs with
/// that error, and the later, better stands only mend the legs after them. The estimate every
/// stand has made is the best for every step, the first ones included. Each step's heading moves
/// by the yaw the two biases part by up to it, (bias in use - bias) integrated about the up
/// direction; the first step keeps its heading (the track's orientation, from the
/// magnetometer), the lengths are kept. For a walk reviewed after it ends (fusion_cli pdr,
/// steps-eval); the live track (the wearable node) cannot know the stands ahead of it.
void relay_track(std::span<HandheldStep> steps, const Eigen::Vector3d& bias_rad_s);

class HandheldPdr {
 public:
  using Params = HandheldPdrParams;
  explicit HandheldPdr(Params p = {});
  /// Feeds one sample (mag may be NaN). Returns how many steps were laid at it: steps()[0..n),
  /// each with its own time (at or before this sample's).
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
  bool have_t_ = false;
  double last_t_s_ = 0.0;
  TelltaleAttitudeFilter att_;
  StandBiasLearner bias_;
  WalkStepDetector detector_;
  WalkingHeading heading_;
  std::array<HandheldStep, WalkStepDetector::kMaxHeld> laid_{};
  HandheldStep last_;
  Eigen::Vector2d mag_offset_sum_ = Eigen::Vector2d::Zero();  ///< unit vectors of the offset
  int mag_n_ = 0;
  bool oriented_ = false;
  std::array<double, 4> intervals_{};
  int interval_n_ = 0;
};

}  // namespace telltale::fusion
