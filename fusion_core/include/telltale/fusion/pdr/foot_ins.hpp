#pragma once
/// \file
/// Foot PDR stage (FootPdr, foot_pdr.hpp): each stride's displacement from the foot's own
/// inertial navigation, reset at every stance. A foot on the ground is still: its velocity is
/// zero and its accelerometer reads gravity alone. So between two stances the sensor can be
/// navigated like any strapdown INS (attitude from the gyro, the specific force turned into the
/// world frame less gravity, integrated twice), and each stance tells it the truth twice over:
/// the velocity it should have (zero) and where up is. The stride is then measured, not
/// modelled: no height, no cadence law, and the walking direction is the displacement's.
///
/// What it does per sample:
/// - attitude: the gyro's rotation over the interval (the sample's rate, bias already off), with
///   the two-sample coning term; the specific force is seen at the attitude of the instant it
///   describes, half an interval before the increment's end (both imu_sample.hpp). A swinging
///   foot turns at 5-10 rad/s, 3-6 deg per 100 Hz sample: without them the walked distance
///   depended on the rate (IPOL, 50 / 100 / 200 Hz: 20.92 / 20.67 / 20.53 m), with them
///   20.37 / 20.39 / 20.40 m;
/// - stance: |rate| < stance_gyro_rad_s and ||f| - g| < stance_acc_m_s2 held for stance_min_s
///   (a swing passes through such values only for an instant; a foot flat holds them 0.1-0.4 s);
/// - in a stance: the attitude levelled to the accelerometer (the smallest rotation that brings
///   the measured up onto the vertical: roll and pitch only, the yaw kept), velocity zero, g
///   learnt as |f|'s mean (so an accelerometer's scale error does not read as a vertical
///   acceleration);
/// - in a swing: v += (R f - g z) dt, p += v dt; at the next stance the velocity left (all of
///   it error: the foot is still) is taken as having grown evenly over the swing, and its
///   integral, v T / 2, comes off the stride.
///
/// Measured on the IPOL foot recordings (walk 10 m, turn, walk back 10 m; 44 files, docs/pdr.md):
/// distance 20.39 m mean, the walk's end 0.57 m (median) from its start.
///
/// A swing longer than max_swing_s is no stride of a walk (a foot swung under a chair, a ride):
/// dropped, the drift of that long would be metres. Over a gap in the samples (longer than
/// max_gap_s) the rotation is unknown: the swing in progress is dropped, the yaw kept.
///
/// Frames: world x, y horizontal, z up; the first sample's attitude is the smallest rotation
/// that levels it, so the world's yaw origin is arbitrary but fixed (sensor_yaw_rad() says where
/// the sensor's x axis points in it). Memory: fixed-size members, no heap.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "telltale/fusion/imu_sample.hpp"

namespace telltale::fusion {

struct FootInsParams {
  double stance_gyro_rad_s = 0.6;  ///< 34 deg/s: a foot flat turns less, a swing 200-1000 deg/s
  double stance_acc_m_s2 = 1.5;    ///< ||f| - g| below this: no acceleration but gravity's
  double stance_min_s = 0.04;      ///< held this long: a stance, not a swing passing through
  double g_tau_s = 2.0;            ///< |f|'s mean over stances (the accelerometer's own g)
  double max_swing_s = 5.0;        ///< a walking stride's swing lasts 0.4-1 s, a pivot 1-2 s
  double max_gap_s = 0.2;          ///< a fifth of a stride unseen: its rotation is lost
};

class FootIns {
 public:
  using Params = FootInsParams;
  explicit FootIns(Params p = {}) : params_(p) {}
  /// One sample, the gyro's bias off; `dt_s` since the last (0 for the first). Returns true at
  /// the sample where a stance begins after a swing: stride_m() is that swing's horizontal
  /// displacement.
  bool update(const ImuSample& s, double dt_s);
  /// The last stride's displacement (world x, y; m).
  [[nodiscard]] const Eigen::Vector2d& stride_m() const { return stride_m_; }
  /// The yaw of the world frame's x axis is the first sample's; this is the sensor's x axis's
  /// heading in it now (rad, counter-clockwise from world x), for orienting the track.
  [[nodiscard]] double sensor_yaw_rad() const;
  /// The vertical in the sensor's frame (unit).
  [[nodiscard]] Eigen::Vector3d up_body() const {
    return q_.conjugate() * Eigen::Vector3d::UnitZ();
  }
  [[nodiscard]] bool stance() const { return stance_; }
  [[nodiscard]] bool started() const { return started_; }
  /// Swings dropped: longer than max_swing_s, or broken by a gap.
  [[nodiscard]] unsigned dropped() const { return dropped_; }

 private:
  Params params_;
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();  ///< body -> world
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_ = Eigen::Vector3d::Zero();  ///< since the last stance
  Eigen::Vector2d stride_m_ = Eigen::Vector2d::Zero();
  OwnGravity g_;          ///< learnt over the stances
  double still_s_ = 0.0;  ///< how long the stance test has held
  double swing_s_ = 0.0;  ///< since the last stance ended
  bool stance_ = true;    ///< a walk starts from standing
  /// The last interval's gyro increment (rad; 0 after a gap): the coning term's other half.
  Eigen::Vector3d dtheta_prev_rad_ = Eigen::Vector3d::Zero();
  bool started_ = false;
  bool waiting_ = false;  ///< a swing was dropped: nothing measured until the next stance
  unsigned dropped_ = 0;
};

}  // namespace telltale::fusion
